"""The desired ZMP of the balance controller: DCM feedback, clamped to the ZMP support area.

Linear inverted pendulum on the plane ``z = h``: ``c_dd = omega^2 (c - p)`` (horizontal, world),
``omega = sqrt(g / (c_z - h))``. Its divergent component of motion (DCM, the instantaneous capture
point) ``xi = c + c_d / omega`` obeys ``xi_d = omega (xi - p)``. Choosing

    p = xi + (k / omega) (xi - xi_ref)

makes the DCM error decay as ``exp(-k t)``. The ZMP ``p`` must lie in the ZMP support area; the
clamped ZMP is the point of the area (shrunk by a margin) nearest the desired one, found by a
two-variable QP (qpsolvers). With the clamp, the robot comes to rest exactly when the DCM is in
the area, that is when the CoM velocity is in the CoM velocity area: the zero-step balance the
criterion assumes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import qpsolvers

from impact_balance.geometry.polygon import Polygon

__all__ = ["DcmFeedback", "clamp_to_polygon", "dcm"]

_FloatArray = npt.NDArray[np.float64]


def dcm(com_xy: np.ndarray, com_velocity_xy: np.ndarray, omega: float) -> np.ndarray:
    """Divergent component of motion ``c + c_d / omega`` (m, world, horizontal)."""
    return (
        np.asarray(com_xy, dtype=float)[:2] + np.asarray(com_velocity_xy, dtype=float)[:2] / omega
    )


def clamp_to_polygon(
    polygon: Polygon, point: np.ndarray, margin: float = 0.0, solver: str = "daqp"
) -> np.ndarray:
    """The point of ``polygon`` shrunk by ``margin`` (m) nearest to ``point``.

    A point already inside is returned unchanged. When the shrunk polygon is empty (margin larger
    than the polygon), the margin is dropped. An empty polygon returns the point unchanged: there is
    nothing to clamp to (the caller's fall detector will see the fall).
    """
    p: _FloatArray = np.asarray(point, dtype=float)[:2]
    if polygon.is_empty:
        return np.array(p)
    G, h = (np.array(a) for a in polygon.halfplanes)  # the polygon's arrays are read-only
    for m in (margin, 0.0):
        if np.all(G @ p <= h - m):
            return np.array(p)
        x = qpsolvers.solve_qp(np.eye(2), -p, G, h - m, solver=solver)
        if x is not None:
            return np.asarray(x, dtype=float)
    # Degenerate polygon that the QP solver rejects: nearest vertex.
    v: _FloatArray = polygon.vertices
    return np.array(v[int(np.argmin(np.linalg.norm(v - p, axis=1)))])


@dataclass
class DcmFeedback:
    """DCM feedback with the ZMP clamped to the support area.

    Attributes:
        zmp_area: ZMP support area (m, world, on the plane ``z = plane_height``).
        omega: LIPM natural frequency (1/s).
        dcm_reference: DCM (and CoM) position to come to rest at (m, world).
        gain: DCM error decay rate ``k`` (1/s).
        margin: The desired ZMP is kept this far inside the area (m).
    """

    zmp_area: Polygon
    omega: float
    dcm_reference: np.ndarray
    gain: float = 3.0
    margin: float = 0.01

    def desired_zmp(
        self, com_xy: np.ndarray, com_velocity_xy: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """``(clamped ZMP, DCM, clamped?)`` for a CoM state (m, m/s, world)."""
        xi = dcm(com_xy, com_velocity_xy, self.omega)
        wanted = xi + (self.gain / self.omega) * (xi - self.dcm_reference)
        p = clamp_to_polygon(self.zmp_area, wanted, self.margin)
        return p, xi, bool(np.linalg.norm(p - wanted) > 1e-9)
