"""Trials in MuJoCo.

- :mod:`.impact_trial`: an impact trial (the limb driven into the surface, the rest held) and
  :mod:`.measure`, its measurement against the impact model;
- :mod:`.balance_trial`: a balance trial (a controller holds the stance through an impact or a
  push), with :mod:`.setup` (what it runs on), :mod:`.impact_tracker`, :mod:`.rigid_impact`,
  :mod:`.outcomes`, :mod:`.result`, :mod:`.log` and :mod:`.video`.
"""

__all__: list[str] = []
