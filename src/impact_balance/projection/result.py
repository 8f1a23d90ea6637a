"""What a projection returns."""

from __future__ import annotations

from dataclasses import dataclass

from impact_balance.geometry.polygon import Polygon

__all__ = ["ProjectionResult"]


@dataclass(frozen=True)
class ProjectionResult:
    """The projected polygon and how it was obtained.

    Attributes:
        polygon: The projection.
        method: "walk" (parametric simplex walk) or "bretl" (one HiGHS LP per ray).
        n_lp: LPs solved (Bretl; the walk counts one LP for its first vertex).
        pivots: Simplex pivots (walk; 0 for Bretl, whose pivots happen inside HiGHS).
    """

    polygon: Polygon
    method: str
    n_lp: int = 0
    pivots: int = 0
