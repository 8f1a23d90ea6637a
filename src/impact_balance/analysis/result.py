"""What an analysis answers: :class:`Analysis` (areas and impact) and :class:`ImpactAnswer`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from impact_balance.balance.areas import BalanceAreas
from impact_balance.balance.infeasibility import CannotBalanceReason
from impact_balance.contacts.stance import Stance
from impact_balance.criteria.qp import QPResult
from impact_balance.criteria.velocity_limit import ContactVelocityLimit, LimitStatus
from impact_balance.impact.angular_momentum import AngularMomentumTerm
from impact_balance.impact.model import ImpactModel
from impact_balance.json_values import json_number
from impact_balance.scenario import Scenario

__all__ = ["Analysis", "Diagnostic", "ImpactAnswer"]


@dataclass(frozen=True)
class Diagnostic:
    """One warning.

    Attributes:
        code: Stable identifier (see the module docstring of
            :mod:`impact_balance.analysis.diagnostics`).
        field: The scenario field it is about (``contacts[1].frame``, ``impact.normal``, ...).
        message: One sentence, in the user's terms.
    """

    code: str
    field: str
    message: str

    def __str__(self) -> str:
        return f"{self.field}: {self.message} [{self.code}]"

    def to_dict(self) -> dict[str, str]:
        """The JSON object of one entry of ``warnings``."""
        return {"code": self.code, "field": self.field, "message": self.message}


@dataclass(frozen=True)
class ImpactAnswer:
    """What the impact analysis concludes.

    Attributes:
        model: Impact model (impulse rates, W, cone).
        com: The CoM velocity criterion's answer: the maximum contact velocity (m/s) and
            its status.
        zmp: The ZMP criterion's answer.
        contact_velocity: Reference velocity with its approach speed moved into the safe
            interval (capped at the maximum when the CoM velocity is inside the area; see
            :func:`~impact_balance.criteria.cap.safe_contact_velocity`), m/s, world; None
            without a reference velocity or when no approach speed is safe.
        qp: The paper's QP solution when requested.
        safe_interval: The approach speeds (lo, hi) m/s whose post-impact CoM velocities all
            stay in the area (hi may be inf), or None when there are none; see
            :func:`~impact_balance.criteria.com.safe_interval` (of the extended criterion
            when ``angular_momentum`` is set, as ``contact_velocity`` is).
        angular_momentum: The term of the angular momentum the impulse leaves (scenario key
            ``angular_momentum_damping_time``), or None (the paper's criterion).
        extended: The CoM velocity criterion that counts that angular momentum (None without
            ``angular_momentum``); ``com`` stays the paper's.
    """

    model: ImpactModel
    com: ContactVelocityLimit
    zmp: ContactVelocityLimit
    contact_velocity: npt.NDArray[np.float64] | None
    qp: QPResult | None = None
    safe_interval: tuple[float, float] | None = None
    angular_momentum: AngularMomentumTerm | None = None
    extended: ContactVelocityLimit | None = None

    @property
    def default(self) -> ContactVelocityLimit:
        """The project's default answer: :attr:`extended` when set, else the paper's :attr:`com`."""
        return self.com if self.extended is None else self.extended

    @property
    def max_contact_velocity(self) -> float:
        """The CoM velocity criterion's maximum contact velocity, m/s (inf: unbounded)."""
        return self.com.max_contact_velocity

    @property
    def status(self) -> LimitStatus:
        """The CoM velocity criterion's status."""
        return self.com.status

    @property
    def zmp_max_contact_velocity(self) -> float:
        """The ZMP criterion's maximum contact velocity, m/s (inf: unbounded)."""
        return self.zmp.max_contact_velocity

    @property
    def zmp_status(self) -> LimitStatus:
        """The ZMP criterion's status."""
        return self.zmp.status

    def evaluation_speed(self) -> float:
        """Approach speed at which sets are reported, m/s.

        Returns:
            The maximum contact velocity, or the reference's approach speed (at least 0)
            when the maximum is unbounded (0 without a reference).
        """
        if self.com.is_finite:
            return self.com.max_contact_velocity
        ref = self.model.spec.reference_velocity
        return max(0.0, self.model.approach_speed(ref)) if ref is not None else 0.0


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`analyze`. ``to_dict()`` is the JSON of ``impact-balance analyze --json``.

    ``timings`` (s): ``total`` is the analysis itself (stance, constraints, areas, impact,
    and ``diagnosis`` when it cannot balance), without loading; ``scenario_loading`` (when
    given a name or a path), ``robot_loading`` (the robot model, cached after its first
    use) and ``kernel_loading`` (numba loading or compiling the compiled kernels: the first
    analysis of a process only) are apart, and ``kernel_compiling`` is the part of
    ``kernel_loading`` spent compiling (the first run after an installation only). The
    stage times (``stance``, ``constraints``, ``areas``, ``impact``) leave the kernels'
    loading out too.
    """

    scenario: Scenario
    stance: Stance
    areas: BalanceAreas
    impact: ImpactAnswer | None
    timings: dict[str, float] = field(default_factory=dict)
    #: Valid input that is probably a mistake, or an answer with a caveat (see diagnostics).
    warnings: tuple[Diagnostic, ...] = ()

    @property
    def com_velocity(self) -> np.ndarray:
        """The pre-impact CoM velocity (3,), world, m/s."""
        return np.asarray(self.scenario.com_velocity, dtype=float)

    @property
    def com_velocity_inside(self) -> bool:
        """Whether the pre-impact CoM velocity can be brought to rest on these contacts."""
        return bool(
            self.areas.can_balance
            and self.areas.com_velocity_area.contains(self.com_velocity, 1e-10)
        )

    @property
    def cannot_balance_reason(self) -> CannotBalanceReason | None:
        """Why the robot cannot balance (None when it can).

        See :mod:`impact_balance.balance.infeasibility`.
        """
        return self.areas.reason

    @property
    def verdict(self) -> str:
        """One line: "balanced", "falling: ..." or "cannot balance: ..."."""
        if not self.areas.can_balance:
            return "cannot balance: the contacts cannot hold the robot at rest (empty areas)"
        if not self.com_velocity_inside:
            return "falling: the CoM velocity is outside the CoM velocity area"
        return "balanced"

    def to_dict(self) -> dict[str, Any]:
        """The JSON document of ``impact-balance analyze --json`` (strict JSON: no NaN, inf)."""
        a = self.areas
        out: dict[str, Any] = {
            "scenario": self.scenario.name,
            "robot": self.stance.robot.name,
            "verdict": self.verdict,
            "can_balance": a.can_balance,
            "cannot_balance_reason": None if a.reason is None else a.reason.to_dict(),
            "mass": self.stance.mass,
            "com": self.stance.com.tolist(),
            "omega": a.omega,
            "plane_height": a.plane_height,
            "zmp_margin": a.zmp_margin,
            "velocity_margin": self.scenario.velocity_margin,
            **(
                {}
                if self.scenario.angular_momentum_damping_time is None
                else {"angular_momentum_damping_time": self.scenario.angular_momentum_damping_time}
            ),
            **(
                {}
                if self.scenario.friction_scale == 1.0
                else {"friction_scale": self.scenario.friction_scale}
            ),
            "gravity": a.gravity,
            "com_velocity": self.com_velocity.tolist(),
            "com_velocity_inside": self.com_velocity_inside,
            "com_velocity_area": a.com_velocity_area.to_dict(),
            "zmp_area": a.zmp_area.to_dict(),
            "contacts": [
                {
                    "frame": c.spec.frame,
                    "position": c.position.tolist(),
                    "normal": c.normal.tolist(),
                    "friction": c.spec.friction,
                    "size": list(c.spec.size),
                }
                for c in self.stance.contacts
            ],
            "timings_ms": {k: 1e3 * v for k, v in self.timings.items()},
            "warnings": [w.to_dict() for w in self.warnings],
        }
        if self.impact is not None:
            im = self.impact
            s = im.evaluation_speed()
            out["impact"] = {
                "frame": im.model.spec.frame,
                "point": im.model.point.tolist(),
                "normal": im.model.normal.tolist(),
                "friction": im.model.spec.friction,
                "restitution": list(im.model.spec.restitution),
                "cone_edges": im.model.spec.cone_edges,
                "max_contact_velocity": json_number(im.max_contact_velocity),
                "status": im.status,
                "reference_velocity": None
                if im.model.spec.reference_velocity is None
                else list(im.model.spec.reference_velocity),
                "contact_velocity": None
                if im.contact_velocity is None
                else im.contact_velocity.tolist(),
                "evaluated_at_approach_speed": s,
                "impulse_vertices": im.model.impulse_vertices(s).tolist(),
                "post_impact_com_velocities": im.model.post_impact_com_velocities(
                    self.com_velocity, s
                ).tolist(),
                "safe_interval": None
                if im.safe_interval is None
                else [json_number(x) for x in im.safe_interval],
                "zmp_max_contact_velocity": json_number(im.zmp_max_contact_velocity),
                "zmp_status": im.zmp_status,
                "W": im.model.W.tolist(),
            }
            if im.angular_momentum is not None and im.extended is not None:
                out["impact"]["angular_momentum"] = {
                    "damping_time": im.angular_momentum.damping_time,
                    "gain": im.angular_momentum.gain,
                    "max_contact_velocity": json_number(im.extended.max_contact_velocity),
                    "status": im.extended.status,
                }
                out["impact"]["default_max_contact_velocity"] = json_number(
                    im.extended.max_contact_velocity
                )
            if im.qp is not None:
                out["impact"]["qp"] = {
                    "status": im.qp.status,
                    "approach_speed": json_number(im.qp.approach_speed),
                    "contact_velocity": None
                    if im.qp.contact_velocity is None
                    else im.qp.contact_velocity.tolist(),
                }
        return out
