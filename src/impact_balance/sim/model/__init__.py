"""The MuJoCo model of a scenario.

- :mod:`.urdf`: the robot's URDF as a MuJoCo spec;
- :mod:`.inertia`: inertials repaired for MuJoCo;
- :mod:`.environment`: collision geometry of the contacts, the impact and the environment;
- :mod:`.joints`: the joint models (``rigid``, ``servo``);
- :mod:`.build`: the build, :func:`~impact_balance.sim.model.build.build_model`.
"""

__all__: list[str] = []
