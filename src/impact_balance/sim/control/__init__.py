"""Controllers of the simulated robot.

- :mod:`.controller`: the family's base, what a trial needs from a balance controller;
- :mod:`.kinematic` (``ik``): DCM feedback + pink IK to joint position servos;
- :mod:`.torque` (``id``): DCM feedback + an inverse-dynamics QP to torque motors;
- :mod:`.registry`: the controllers by name; :mod:`.gains`: their gains;
- :mod:`.approach`: the impacting point's reference; :mod:`.zmp`: the desired ZMP;
- :mod:`.actuation`: how the joints are driven (servos of the support limbs, torque motors).
"""

__all__: list[str] = []
