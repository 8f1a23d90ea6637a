"""What differs between the project's versions that a benchmark side times, found by feature
detection (the new import path first, then the old one): a ``--baseline`` tree may be older
than the benchmark (e.g. commit 2fe275e, before the package was reorganised into folders)."""

from __future__ import annotations

from typing import Any

__all__ = ["force_box_and_tolerance", "governed_maximum", "wrench_polytope"]


def force_box_and_tolerance() -> tuple[float, float]:
    """``(FORCE_BOX, FORCE_TOLERANCE)`` of the area projection (units of m g)."""
    try:
        from impact_balance.balance.areas import FORCE_BOX, FORCE_TOLERANCE
    except ImportError:  # before the reorganisation: impact_balance.areas
        from impact_balance.areas import (  # type: ignore[no-redef]
            FORCE_BOX,
            FORCE_TOLERANCE,
        )
    return float(FORCE_BOX), float(FORCE_TOLERANCE)


def wrench_polytope(stance: Any, torque_limits: bool, gravity: float) -> Any:
    """The stance's wrench polytope (``impact_balance.wrench_polytope`` in every version)."""
    import impact_balance as ib

    return ib.wrench_polytope(stance, torque_limits, gravity)


def governed_maximum(limit: Any) -> float:
    """A governor answer's maximum contact velocity (``max_approach_speed`` before the rename)."""
    value = getattr(limit, "max_contact_velocity", None)
    if value is None:
        value = limit.max_approach_speed
    return float(value)
