"""Physical constants and the physical ranges of input (SI units)."""

import math

__all__ = [
    "DEFAULT_ANGULAR_MOMENTUM_DAMPING_TIME",
    "GRAVITY",
    "GRAVITY_RANGE",
    "MAX_ANGLE",
    "MAX_ANGULAR_MOMENTUM_DAMPING_TIME",
    "MAX_DESCRIPTION",
    "MAX_DURATION",
    "MAX_FRICTION",
    "MAX_NAME",
    "MAX_PEAK_FACTOR",
    "MAX_POSITION",
    "MAX_SIZE",
    "MAX_SPEED",
    "MAX_VELOCITY_MARGIN",
]

#: Standard gravity, m/s^2, acting along world -z.
GRAVITY: float = 9.81

# -- physical ranges of input --------------------------------------------------------------
# Every number must be finite (NaN and infinities are refused by the schema itself), and lie
# in a range a physical robot can have. The ranges are wide on purpose: they refuse what is
# surely a mistake (a mistyped exponent, a value in mm for m), not an unusual robot.
#: Largest friction coefficient (contacts and impact); real surfaces are below 2.
MAX_FRICTION = 1e6
#: Largest contact side, m.
MAX_SIZE = 10.0
#: Largest coordinate of a position (base, offsets) and |plane_height|, m.
MAX_POSITION = 1e4
#: Largest |roll|, |pitch|, |yaw|, rad (two turns).
MAX_ANGLE = 4 * math.pi
#: Largest speed (reference velocity, CoM velocity), m/s.
MAX_SPEED = 100.0
#: Largest velocity margin (``velocity_margin``, ``--velocity-margin``), m/s: a margin far
#: beyond any CoM velocity area a robot has.
MAX_VELOCITY_MARGIN = 10.0
#: Accepted gravity, m/s^2 (the Moon's 1.62 to Jupiter's 24.8, with margin).
GRAVITY_RANGE = (0.1, 100.0)
#: Longest impact duration, s (impacts last milliseconds).
MAX_DURATION = 1.0
#: Largest ratio of peak to mean impulsive force.
MAX_PEAK_FACTOR = 1e3
#: Longest scenario name (it names figure files), characters.
MAX_NAME = 100
#: Longest description, characters.
MAX_DESCRIPTION = 2000
#: Longest angular momentum damping time (``angular_momentum_damping_time``), s: a day.
MAX_ANGULAR_MOMENTUM_DAMPING_TIME = 86400.0
#: The angular momentum damping time a scenario has when it sets none, s; None is the paper's
#: criterion (the angular momentum the impulse leaves is ignored). The one place to change the
#: project's default (see docs/angular-momentum.md).
DEFAULT_ANGULAR_MOMENTUM_DAMPING_TIME: float | None = None
