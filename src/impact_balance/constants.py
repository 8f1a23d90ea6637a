"""Physical constants (SI units)."""

__all__ = ["GRAVITY"]

#: Standard gravity, m/s^2, acting along world -z.
GRAVITY: float = 9.81
