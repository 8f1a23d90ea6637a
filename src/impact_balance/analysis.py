"""The whole pipeline: scenario -> stance -> constraints -> areas -> impact -> answer."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .areas import BalanceAreas, areas_from_polytope, with_reason
from .constraints import wrench_polytope
from .criteria import VelocityLimit, max_contact_velocity, safe_contact_velocity, safe_interval, zmp_max_contact_velocity
from .diagnostics import Diagnostic, diagnose
from .impact import ImpactModel, impact_model
from .projection.walk import warm_up
from .qp import QPOptions, QPResult, solve_contact_velocity_qp, static_torques
from .infeasibility import CannotBalanceReason
from .exceptions import NonFiniteResultError, ScenarioError, SolverError
from .scenario import Scenario, load_scenario, with_source
from .stance import Stance

__all__ = ["ImpactAnswer", "Analysis", "analyze"]


def _num(x: float) -> float | None:
    """JSON-safe float (inf -> None)."""
    return float(x) if np.isfinite(x) else None


@dataclass(frozen=True)
class ImpactAnswer:
    """What the impact analysis concludes.

    Attributes:
        model: Impact model (impulse rates, W, cone).
        com_limit: Maximum approach speed by the CoM velocity criterion (m/s).
        zmp_limit: Maximum approach speed by the ZMP criterion (m/s).
        contact_velocity: Reference velocity with its approach speed moved into the safe
            interval (capped at the maximum when the CoM velocity is inside the area; see
            :func:`~impact_balance.criteria.safe_contact_velocity`), m/s, world; None without a
            reference velocity or when no approach speed is safe.
        qp: The paper's QP solution when requested.
        safe_interval: The approach speeds (lo, hi) m/s whose post-impact CoM velocities all
            stay in the area (hi may be inf), or None when there are none; see
            :func:`~impact_balance.criteria.safe_interval`.
    """

    model: ImpactModel
    com_limit: VelocityLimit
    zmp_limit: VelocityLimit
    contact_velocity: np.ndarray | None
    qp: QPResult | None = None
    safe_interval: tuple[float, float] | None = None

    @property
    def max_contact_velocity(self) -> float:
        return self.com_limit.max_approach_speed

    @property
    def zmp_max_contact_velocity(self) -> float:
        return self.zmp_limit.max_approach_speed

    def evaluation_speed(self) -> float:
        """Approach speed at which sets are reported: the maximum, or the reference's if unbounded."""
        if self.com_limit.is_finite:
            return self.com_limit.max_approach_speed
        ref = self.model.spec.reference_velocity
        return max(0.0, self.model.approach_speed(ref)) if ref is not None else 0.0


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`analyze`. ``to_dict()`` is the JSON of ``impact-balance analyze --json``.

    ``timings`` (s): ``total`` is the analysis itself (stance, constraints, areas, impact,
    and ``diagnosis`` when it cannot balance), without loading; ``scenario_loading`` (when
    given a name or a path), ``robot_loading`` (the robot model, cached after its first
    use) and ``kernel_loading`` (the compiled projection kernel, first call of the process
    only) are apart.
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
        return np.asarray(self.scenario.com_velocity, dtype=float)

    @property
    def com_velocity_inside(self) -> bool:
        """Whether the pre-impact CoM velocity can be brought to rest on these contacts."""
        return bool(self.areas.can_balance and self.areas.com_velocity_area.contains(self.com_velocity, 1e-10))

    @property
    def cannot_balance_reason(self) -> CannotBalanceReason | None:
        """Why the robot cannot balance (None when it can); see :mod:`impact_balance.infeasibility`."""
        return self.areas.reason

    @property
    def verdict(self) -> str:
        if not self.areas.can_balance:
            return "cannot balance: the contacts cannot hold the robot at rest (empty areas)"
        if not self.com_velocity_inside:
            return "falling: the CoM velocity is outside the CoM velocity area"
        return "balanced"

    def to_dict(self) -> dict[str, Any]:
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
            "gravity": a.gravity,
            "com_velocity": self.com_velocity.tolist(),
            "com_velocity_inside": self.com_velocity_inside,
            "com_velocity_area": a.com_velocity_area.to_dict(),
            "zmp_area": a.zmp_area.to_dict(),
            "contacts": [
                {"frame": c.spec.frame, "position": c.position.tolist(), "normal": c.normal.tolist(),
                 "friction": c.spec.friction, "size": list(c.spec.size)}
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
                "max_contact_velocity": _num(im.max_contact_velocity),
                "status": im.com_limit.status,
                "reference_velocity": None if im.model.spec.reference_velocity is None else list(im.model.spec.reference_velocity),
                "contact_velocity": None if im.contact_velocity is None else im.contact_velocity.tolist(),
                "evaluated_at_approach_speed": s,
                "impulse_vertices": im.model.impulse_vertices(s).tolist(),
                "post_impact_com_velocities": im.model.post_impact_com_velocities(self.com_velocity, s).tolist(),
                "safe_interval": None if im.safe_interval is None else [_num(x) for x in im.safe_interval],
                "zmp_max_contact_velocity": _num(im.zmp_max_contact_velocity),
                "zmp_status": im.zmp_limit.status,
                "W": im.model.W.tolist(),
            }
            if im.qp is not None:
                out["impact"]["qp"] = {
                    "status": im.qp.status,
                    "approach_speed": _num(im.qp.approach_speed),
                    "contact_velocity": None if im.qp.contact_velocity is None else im.qp.contact_velocity.tolist(),
                }
        return out


def analyze(scenario: Scenario | str, solve_qp: bool | None = None) -> Analysis:
    """Run the whole pipeline on a scenario (object, file path or bundled name).

    ``solve_qp`` overrides the scenario's ``impact.qp.solve``.
    """
    timings: dict[str, float] = {}
    if not isinstance(scenario, Scenario):
        t = time.perf_counter()
        scenario = load_scenario(scenario)
        timings["scenario_loading"] = time.perf_counter() - t
    t = time.perf_counter()
    try:
        robot = scenario.load_robot()  # cached after the first use of a robot
    except ScenarioError as exc:
        raise with_source(exc, scenario.source) from None
    robot.workspace()  # its scratch pinocchio Data (~2-7 ms, first use per thread): loading too
    timings["robot_loading"] = time.perf_counter() - t
    kernel = warm_up()  # the compiled projection kernel's one-time load, timed apart
    if kernel:
        timings["kernel_loading"] = kernel
    t0 = time.perf_counter()
    stance = scenario.build_stance(robot)
    t1 = time.perf_counter()
    polytope = wrench_polytope(stance, scenario.torque_limits, scenario.gravity)
    t2 = time.perf_counter()
    try:
        areas = areas_from_polytope(polytope, scenario.plane_height, scenario.zmp_margin)
    except SolverError as exc:
        raise exc.within("contacts (projection of the contact wrench polytope)") from None
    t3 = time.perf_counter()
    timings.update(stance=t1 - t0, constraints=t2 - t1, areas=t3 - t2)
    if not areas.can_balance:  # explain why (LPs; only for a stance that cannot balance)
        areas = with_reason(areas, stance, scenario.torque_limits, scenario.gravity)
        timings["diagnosis"] = time.perf_counter() - t3
        t3 = time.perf_counter()
    _check_finite(_area_checks(stance, areas))
    answer = None
    if scenario.impact is not None:
        cfg = scenario.impact
        try:
            model = impact_model(stance, cfg.spec())
        except ScenarioError as exc:
            raise with_source(exc, scenario.source) from None
        _check_finite(_impact_checks(model))
        com_limit = max_contact_velocity(areas.com_velocity_area, model, scenario.com_velocity)
        zmp_limit = zmp_max_contact_velocity(
            areas.zmp_area, model, stance.com, scenario.plane_height, scenario.gravity, cfg.duration
        )
        interval = safe_interval(areas.com_velocity_area, model, scenario.com_velocity, com_limit)
        contact_velocity = None
        if cfg.reference_velocity is not None:
            contact_velocity = safe_contact_velocity(cfg.reference_velocity, model.normal, interval)
        qp = None
        if (cfg.qp.solve if solve_qp is None else solve_qp) and cfg.reference_velocity is not None:
            tau0 = static_torques(stance, polytope) if cfg.qp.impulsive_torque_limits else None
            options = QPOptions(
                cfg.qp.joint_velocity_limits, cfg.qp.impulsive_torque_limits, cfg.qp.peak_factor, cfg.duration, cfg.qp.solver
            )
            try:
                qp = solve_contact_velocity_qp(
                    model, areas.com_velocity_area, scenario.com_velocity, cfg.reference_velocity, stance.robot, tau0,
                    options,
                )
            except SolverError as exc:
                raise exc.within("impact.qp") from None
        answer = ImpactAnswer(model, com_limit, zmp_limit, contact_velocity, qp, interval)
        timings["impact"] = time.perf_counter() - t3
    timings["total"] = time.perf_counter() - t0
    return Analysis(scenario, stance, areas, answer, timings, diagnose(scenario, stance, answer))


def _area_checks(stance: Stance, areas: BalanceAreas) -> list[tuple[str, Any, tuple[str, ...]]]:
    """(result field, value, scenario fields that can make it overflow) of the areas step."""
    return [
        ("com", stance.com, ("base.position",)),
        ("omega", areas.omega, ("plane_height", "gravity")),
        # The squared sizes: their overflow is that of the areas and of the edge normals.
        ("zmp_area", _squared_size(areas.zmp_area), ("plane_height", "base.position")),
        ("com_velocity_area", _squared_size(areas.com_velocity_area), ("plane_height", "gravity")),
    ]


def _squared_size(polygon) -> float:
    """Sum of the squared vertex coordinates (inf when they overflow, NaN with a NaN)."""
    v = polygon.vertices.ravel()
    with np.errstate(over="ignore", invalid="ignore"):
        return float(v @ v)


def _impact_checks(model: ImpactModel) -> list[tuple[str, Any, tuple[str, ...]]]:
    """Like :func:`_area_checks`, for the impact model."""
    return [
        ("impact.point", model.point, ("impact.offset", "base.position")),
        ("impact.W", model.W, ("impact.offset",)),
        ("impact.impulse_vertices", model.impulse_rates, ("impact.offset", "impact.friction")),
    ]


def _check_finite(checks: list[tuple[str, Any, tuple[str, ...]]]) -> None:
    """Raise :class:`NonFiniteResultError` naming the first non-finite result (never NaN out).

    One sum over everything first (a NaN or an infinity anywhere makes it non-finite), so the
    common case costs a few microseconds; the field is looked for only on failure.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(sum(float(np.sum(value)) for _, value, _ in checks)):
            return
        for name, value, inputs in checks:
            if not np.isfinite(value).all():
                raise NonFiniteResultError(name, inputs)
        # every part finite: only their sum overflowed
