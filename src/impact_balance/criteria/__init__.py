"""Balance criteria: how fast may the contact be hit.

- :mod:`.velocity_limit`: the answer of a criterion (:class:`ContactVelocityLimit`);
- :mod:`.criterion`: the family (:class:`Criterion`, the names "com" and "zmp");
- :mod:`.linear_exit`: the first exit of points moving linearly out of an area, the core of
  both criteria;
- :mod:`.com`: the paper's CoM velocity criterion; :mod:`.zmp`: the ZMP criterion;
- :mod:`.cap`: the approach-speed clamps of a reference velocity;
- :mod:`.qp`: the paper's QP in joint velocities;
- :mod:`.posture_kernel`: one posture's areas, impact model and CoM criterion rates in one
  compiled call (what :func:`~impact_balance.analyze` and a governor run).
"""

__all__: list[str] = []
