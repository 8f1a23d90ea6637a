"""Sustained contacts.

The stance (:mod:`.stance`), contact wrench cones (:mod:`.cwc`) and the linear constraints on
the stacked contact wrenches (:mod:`.wrench_polytope`).
"""

__all__: list[str] = []
