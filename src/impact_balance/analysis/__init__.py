"""The whole pipeline as one call.

- :mod:`.analyze`: :func:`~impact_balance.analysis.analyze.analyze`, scenario to answer;
- :mod:`.result`: what it answers (:class:`~impact_balance.analysis.result.Analysis`,
  :class:`~impact_balance.analysis.result.ImpactAnswer`, warnings as
  :class:`~impact_balance.analysis.result.Diagnostic`);
- :mod:`.diagnostics`: the warning rules;
- :mod:`.report`: the plain-text report.
"""

__all__: list[str] = []
