"""Scoring a held-out set from its run outputs: ``studies/score_held_out.py``'s parts.

- :mod:`.export`: the run's JSON outputs to the records (``pushes.csv``, ``impacts.csv``,
  ``approaches.csv``, ``com_reach.csv``);
- :mod:`.premise`: the capture's premise B per rigid impact search (``premise.json``);
- :mod:`.records`: reading the records back;
- :mod:`.markdown`: rates with their Wilson intervals, and markdown tables;
- :mod:`.push_scores`, :mod:`.impact_scores`: the scores' tables;
- :mod:`.rule4`: the records against the protocol's prediction tables.

Not part of the ``impact_balance`` package (and not in its wheel): a referee's tool.
"""

__all__: list[str] = []
