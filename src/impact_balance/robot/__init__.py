"""Robot models.

- :mod:`.robot`: loading a robot (URDF, SRDF), its joints and limits, and its per-thread
  pinocchio data (:class:`~impact_balance.robot.robot.ThreadData`);
- :mod:`.meshes`: the mesh files of a robot's URDF;
- :mod:`.ik`: whole-body inverse kinematics for building stances.
"""

__all__: list[str] = []
