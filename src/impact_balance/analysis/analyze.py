"""The whole pipeline: scenario -> stance -> constraints -> areas -> impact -> answer."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from impact_balance._jit import HAVE_NUMBA, KernelClock, njit
from impact_balance.analysis.diagnostics import diagnose
from impact_balance.analysis.result import Analysis, ImpactAnswer
from impact_balance.balance.areas import (
    BalanceAreas,
    areas_from_polytope,
    posture_areas,
    with_reason,
)
from impact_balance.balance.lipm import lipm_omega
from impact_balance.contacts.contact_model import scaled_stance
from impact_balance.contacts.cwc import local_faces
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.contacts.wrench_polytope import (
    WrenchPolytope,
    assemble_polytope,
    friction_scaling,
    wrench_polytope,
)
from impact_balance.criteria.cap import safe_contact_velocity
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.posture_answer import posture_answer
from impact_balance.criteria.posture_kernel import constants, posture_kernel
from impact_balance.criteria.qp import (
    QPOptions,
    QPResult,
    solve_contact_velocity_qp,
    static_torques,
)
from impact_balance.criteria.zmp import zmp_max_contact_velocity
from impact_balance.exceptions import (
    ImpactModelError,
    NonFiniteResultError,
    ScenarioError,
    SolverError,
)
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.angular_momentum import AngularMomentumTerm, angular_momentum_gain
from impact_balance.impact.model import ImpactModel, impact_cone, impact_model
from impact_balance.projection.walk import MAX_PIVOTS, NO_HINT, warm_up
from impact_balance.scenario import Scenario, load_scenario, with_source

__all__ = [
    "Analysis",
    "ImpactAnswer",
    "analyze",
    "angular_momentum_term",
    "contact_model_areas",
    "impact_answer",
    "stance_areas",
    "stance_posture",
]


def analyze(scenario: Scenario | str, solve_qp: bool | None = None) -> Analysis:
    """Run the whole pipeline on a scenario (object, file path or bundled name).

    The scenario's ``zmp_margin`` (m) shrinks the ZMP support area, and the CoM velocity
    area with it; its ``velocity_margin`` (m/s) keeps every post-impact CoM velocity that far
    inside the CoM velocity area (the CoM criterion, its safe interval and the QP; the ZMP
    criterion has no velocity margin); its ``friction_scale`` multiplies every contact's
    friction in the areas (:func:`~impact_balance.contacts.contact_model.scaled_stance`; the
    returned stance keeps the scenario's frictions). A
    :class:`~impact_balance.governor.Governor` of the same scenario answers the same maximum
    contact velocity at the scenario's posture and CoM velocity. After the stance, the areas,
    the impact model and the CoM criterion's rates are the governor's one compiled call
    (:func:`~impact_balance.criteria.posture_kernel.posture_kernel`) where it answers, the
    steps one by one elsewhere: the same numbers.

    Args:
        scenario: A :class:`~impact_balance.scenario.Scenario`, a scenario file or the name
            of a bundled scenario.
        solve_qp: Overrides the scenario's ``impact.qp.solve`` when given.

    Returns:
        The stance, the areas, the impact answer (None without an impact), the timings (s)
        and the diagnostics.

    Raises:
        ScenarioError: A bad scenario, or one the robot model refuses (unknown frame...).
        SolverError: A projection or the QP failed (naming the step).
        NonFiniteResultError: A result overflowed (naming it and the inputs that can cause it).
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
    robot.thread_data()  # its scratch pinocchio Data (~2-7 ms, first use per thread): loading too
    timings["robot_loading"] = time.perf_counter() - t
    clock = KernelClock()  # numba's loading and compiling are timed apart from the analysis
    with clock.running():
        warm_up()  # the compiled projection kernel's one-time load
        t0 = clock.now()
        stance = scenario.build_stance(robot)
        t1 = clock.now()
        qp = scenario.impact is not None and (
            scenario.impact.qp.solve if solve_qp is None else solve_qp
        )
        # The criterion's contacts: the scenario's, their friction times its friction_scale.
        criterion_stance = scaled_stance(stance, scenario.friction_scale)
        polytope, areas, model, criterion, t2 = _posture(
            scenario, criterion_stance, clock.now, polytope=qp
        )
        t3 = clock.now()
        timings.update(stance=t1 - t0, constraints=t2 - t1, areas=t3 - t2)
        if not areas.can_balance:  # explain why (LPs; only for a stance that cannot balance)
            areas = with_reason(areas, criterion_stance, scenario.torque_limits, scenario.gravity)
            timings["diagnosis"] = clock.now() - t3
            t3 = clock.now()
        if model is None or not _posture_finite(stance, areas, model):
            checks = _area_checks(stance, areas)
            if model is not None:  # the compiled posture's: checked with the areas (after them)
                checks += _impact_checks(model)
            _check_finite(checks)  # names the first non-finite result
        answer = None
        if scenario.impact is not None:
            answer = _answer(scenario, stance, areas, model, criterion, polytope if qp else None)
            timings["impact"] = clock.now() - t3
        timings["total"] = clock.now() - t0
    if clock.loading:
        timings["kernel_loading"] = clock.loading
    if clock.compiling:
        timings["kernel_compiling"] = clock.compiling
    return Analysis(scenario, stance, areas, answer, timings, diagnose(scenario, stance, answer))


def stance_posture(
    scenario: Scenario, stance: Stance
) -> tuple[BalanceAreas, ImpactModel | None, ComCriterion | None]:
    """The balance areas at a stance, and the impact model and CoM criterion where it can.

    :func:`analyze`'s path from the stance: the compiled posture
    (:func:`~impact_balance.criteria.posture_kernel.posture_kernel`, its objects by
    :func:`~impact_balance.criteria.posture_answer.posture_answer`) where it answers, the areas
    step by step (:func:`stance_areas`) where it does not; the same numbers either way. The
    sweep evaluator's, at each stance of a sweep.

    Args:
        scenario: Its ``torque_limits``, ``gravity``, ``plane_height`` (m), ``zmp_margin`` (m),
            ``velocity_margin`` (m/s), ``friction_scale`` and ``impact`` are used.
        stance: The robot at a configuration with its contacts (world frame).

    Returns:
        ``(areas, model, criterion)``: the ZMP support and CoM velocity areas; the impact model
        of the scenario's impact and the paper's CoM criterion with the scenario's velocity
        margin (both None where the compiled posture does not answer: the caller then makes
        them, :func:`~impact_balance.impact.model.impact_model` and :func:`impact_answer`, and
        they raise what they raise).

    Raises:
        SolverError: The projection failed (named as the projection of the contacts' polytope).
    """
    criterion_stance = scaled_stance(stance, scenario.friction_scale)
    _, areas, model, criterion, _ = _posture(
        scenario, criterion_stance, time.perf_counter, polytope=False
    )
    return areas, model, criterion


def stance_areas(scenario: Scenario, stance: Stance) -> tuple[WrenchPolytope, BalanceAreas]:
    """The scenario's contact wrench polytope and balance areas at a stance.

    The first half of the pipeline (stance -> constraints -> areas) step by step, with the
    scenario's torque limits, gravity, ZMP plane and ZMP margin: :func:`analyze`'s (and
    :func:`stance_posture`'s) where the compiled posture does not answer (the same numbers as
    it where it does).

    Args:
        scenario: Its ``torque_limits``, ``gravity``, ``plane_height`` (m), ``zmp_margin``
            (m) and ``friction_scale`` are used.
        stance: The robot at a configuration with its contacts (world frame).

    Returns:
        The polytope of the stacked contact wrenches and the ZMP support and CoM velocity areas.

    Raises:
        SolverError: The projection failed (named as the projection of the contacts' polytope).
    """
    polytope, areas, _ = _stance_areas(scenario, scaled_stance(stance, scenario.friction_scale))
    assert polytope is not None  # asked for
    return polytope, areas


def contact_model_areas(
    scenario: Scenario, stance: Stance, friction_scale: float, cop_margin: float = 0.0
) -> BalanceAreas:
    """The balance areas of a contact model narrower than the scenario's contacts.

    :func:`stance_areas`' pipeline (the scenario's torque limits, gravity, plane and ZMP
    margin) on :func:`~impact_balance.contacts.contact_model.scaled_stance`: every contact's
    friction times ``friction_scale`` and its rectangle inset by ``cop_margin``, whatever the
    scenario's own ``friction_scale``. The areas a controller whose contact wrench cones are
    those can realise (the ``id`` controller's ZMP clamp).

    Args:
        scenario: As for :func:`stance_areas` (its ``friction_scale`` is not used).
        stance: The robot at a configuration with the scenario's contacts (world frame).
        friction_scale: In (0, 1].
        cop_margin: The rectangles' inset on every side, m (>= 0).

    Returns:
        The ZMP support and CoM velocity areas (world frame).

    Raises:
        ScenarioError: A friction scale outside (0, 1] or a negative ``cop_margin``.
        SolverError: The projection failed.
    """
    narrower = scaled_stance(stance, friction_scale, cop_margin)
    return _stance_areas(scenario, narrower, polytope=False)[1]


def _answer(
    scenario: Scenario,
    stance: Stance,
    areas: BalanceAreas,
    model: ImpactModel | None,
    criterion: ComCriterion | None,
    polytope: WrenchPolytope | None,
) -> ImpactAnswer:
    """:func:`analyze`'s impact step: the model (unless given), its checks, the answer, the QP.

    ``model`` and ``criterion`` are the compiled posture's (None: the steps make them, and the
    model's finiteness is checked here; a given one the caller checked); the QP is solved
    when ``polytope`` is given.
    """
    cfg = scenario.impact
    assert cfg is not None  # called for a scenario with an impact
    if model is None:
        try:
            model = impact_model(stance, cfg.spec())
        except ScenarioError as exc:
            raise with_source(exc, scenario.source) from None
        _check_finite(_impact_checks(model))  # a given model was checked with the areas
    answer = impact_answer(scenario, stance, areas, model, criterion)
    if polytope is not None:
        answer = dataclasses.replace(answer, qp=_qp(scenario, stance, polytope, areas, model))
    return answer


def _posture(
    scenario: Scenario,
    stance: Stance,
    now: Callable[[], float],
    polytope: bool,
) -> tuple[WrenchPolytope | None, BalanceAreas, ImpactModel | None, ComCriterion | None, float]:
    """:func:`stance_posture`, the polytope (with ``polytope``, else None) and a time.

    The time (s, by the clock ``now``) is when the projection began (the compiled call's or the
    steps').
    """
    posture = _compiled_posture(scenario, stance, now, polytope)
    if posture is None:
        assembled, areas, t = _stance_areas(scenario, stance, now, polytope)
        return assembled, areas, None, None, t
    return posture


def _compiled_posture(
    scenario: Scenario,
    stance: Stance,
    now: Callable[[], float],
    polytope: bool,
) -> tuple[WrenchPolytope | None, BalanceAreas, ImpactModel, ComCriterion, float] | None:
    """The areas, impact model and CoM criterion by the compiled posture, or None.

    :func:`~impact_balance.criteria.posture_kernel.posture_kernel` on the stance's arrays (the
    numbers of :func:`_stance_areas`, :func:`~impact_balance.impact.model.impact_model` and
    :class:`~impact_balance.criteria.com.ComCriterion`), for a scenario with an impact of the
    composite inertia and contacts whose frictions are at most 1. None where the kernel does
    not answer, or a step would raise: the caller then takes the steps, which answer or raise
    as they always do. Also returns the polytope (with ``polytope``, for the QP; else None) and
    the time (s, by the clock ``now``) the compiled call began.
    """
    cfg = scenario.impact
    if cfg is None or cfg.inertia != "composite" or not stance.contacts:
        return None
    if max(float(c.spec.friction) for c in stance.contacts) > 1.0:
        return None  # friction-normalised variables: the steps
    try:
        spec = cfg.spec()
        placement, J6 = stance.local_point(spec.frame, spec.offset, field="impact.frame")
        w = lipm_omega(
            float(stance.com[2]), scenario.plane_height, scenario.gravity, field="plane_height"
        )
        normal, cone = impact_cone(spec)
    except (ScenarioError, ImpactModelError):
        return None  # the steps raise it, in their order
    arrays = _stance_arrays(stance, scenario.torque_limits, scenario.gravity)
    faces, rotations, positions, arms, mass, com, gravity, J, idx, limit, g = arrays
    assembled = assemble_polytope(*arrays, None) if polytope else None
    point_local = placement.translation  # (a view into the placement: read once)
    arm = point_local - stance.com_local  # as impact_model
    lo, hi = spec.restitution
    kernel_constants = constants(float(scenario.zmp_margin), (float(lo), float(hi)))
    t = now()
    out = posture_kernel(
        faces, rotations, positions, arms, J, np.ascontiguousarray(idx, dtype=np.int64), limit,
        g, mass * gravity, scenario.plane_height - float(com[2]), float(com[0]), float(com[1]),
        w, NO_HINT, MAX_PIVOTS, kernel_constants, arm, mass, stance.com_inertia, normal, cone,
    )  # fmt: skip
    answer = posture_answer(
        out, spec, point_local + stance.origin, normal, cone, J6[:3].copy(),
        mass=mass, omega=w, com=com, plane_height=scenario.plane_height, gravity=gravity,
        zmp_margin=scenario.zmp_margin, velocity_margin=scenario.velocity_margin,
    )  # fmt: skip
    if answer is None:
        return None
    areas, model, criterion = answer.projected.areas(), answer.impact, answer.criterion
    return assembled, areas, model, criterion, t


def _stance_areas(
    scenario: Scenario,
    stance: Stance,
    now: Callable[[], float] = time.perf_counter,
    polytope: bool = True,
) -> tuple[WrenchPolytope | None, BalanceAreas, float]:
    """:func:`stance_areas`, and the time (s, by the clock ``now``) between its two steps.

    The areas are a governor's (:func:`~impact_balance.balance.areas.posture_areas`, from the
    stance's arrays), the same numbers as the polytope's. Without ``polytope`` (only the QP
    reads it), the polytope is None unless the projection needs it (a stance without contacts).
    """
    if not stance.contacts:  # nothing to assemble from: the polytope of no contact
        whole = wrench_polytope(stance, scenario.torque_limits, scenario.gravity)
        t = now()
        return whole, _projected_polytope(whole, scenario), t
    arrays = _stance_arrays(stance, scenario.torque_limits, scenario.gravity)
    frictions = [float(c.spec.friction) for c in stance.contacts]
    assembled = None
    if polytope:  # wrench_polytope's numbers, from the same arrays as the areas
        assembled = assemble_polytope(*arrays, friction_scaling(frictions, list(arrays[1])))
    t = now()
    try:
        projected = posture_areas(*arrays, frictions, scenario.plane_height, scenario.zmp_margin)
        areas = projected if isinstance(projected, BalanceAreas) else projected.areas()
    except SolverError as exc:
        raise exc.within("contacts (projection of the contact wrench polytope)") from None
    return assembled, areas, t


def _qp(
    scenario: Scenario,
    stance: Stance,
    polytope: WrenchPolytope,
    areas: BalanceAreas,
    model: ImpactModel,
) -> QPResult | None:
    """The paper's QP in joint velocities for the scenario's impact (None without a reference).

    Raises:
        SolverError: The QP failed (its field is ``impact.qp``).
    """
    cfg = scenario.impact
    assert cfg is not None  # called for a scenario with an impact
    if cfg.reference_velocity is None:
        return None
    tau0 = static_torques(stance, polytope) if cfg.qp.impulsive_torque_limits else None
    options = QPOptions(
        cfg.qp.joint_velocity_limits,
        cfg.qp.impulsive_torque_limits,
        cfg.qp.peak_factor,
        cfg.duration,
        cfg.qp.solver,
    )
    try:
        return solve_contact_velocity_qp(
            model,
            areas.com_velocity_area.inset(scenario.velocity_margin),
            scenario.com_velocity,
            cfg.reference_velocity,
            stance.robot,
            tau0,
            options,
        )
    except SolverError as exc:
        raise exc.within("impact.qp") from None


#: :func:`_stance_arrays`' answer.
_Arrays = tuple[
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    float,
    np.ndarray,
    float,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
]


def _projected_polytope(polytope: WrenchPolytope, scenario: Scenario) -> BalanceAreas:
    """The areas of ``polytope`` with the scenario's plane and ZMP margin."""
    try:
        return areas_from_polytope(polytope, scenario.plane_height, scenario.zmp_margin)
    except SolverError as exc:
        raise exc.within("contacts (projection of the contact wrench polytope)") from None


def _stance_arrays(stance: Stance, torque_limits: bool, gravity: float) -> _Arrays:
    """:func:`~impact_balance.balance.areas.posture_areas`' arrays of a stance.

    Up to the frictions, the numbers that
    :func:`~impact_balance.contacts.wrench_polytope.wrench_polytope` assembles: faces,
    rotations, world positions, lever arms about the CoM (stance frame), mass, CoM, ``gravity``
    (m/s^2), then the Jacobians, torque-limited joints, limits and g(q) (empty without torque
    limits).
    """
    contacts = stance.contacts
    m = len(contacts)
    faces = _faces(tuple(c.spec for c in contacts))
    rotations = np.array([c.rotation for c in contacts], dtype=float).reshape(m, 3, 3)
    positions = np.array([c.position for c in contacts], dtype=float).reshape(m, 3)
    local = np.array([c.local_position for c in contacts], dtype=float).reshape(-1, 3)
    idx, limit = stance.robot.effort_limits
    if torque_limits and idx.size:
        J, g = np.concatenate([c.jacobian for c in contacts]), stance.gravity_torques
    else:
        J, g = np.zeros((0, 0)), np.zeros(0)
        idx, limit = np.zeros(0, dtype=np.int64), np.zeros(0)
    arms = local - stance.com_local
    return faces, rotations, positions, arms, stance.mass, stance.com, gravity, J, idx, limit, g


#: :func:`_faces`' last answer: the contacts' specs (the objects) and their stacked faces.
_LAST_FACES: tuple[tuple[ContactSpec, ...], np.ndarray] = ((), np.zeros((0, 16, 6)))


def _faces(specs: tuple[ContactSpec, ...]) -> np.ndarray:
    """The contacts' CWC faces in their frames, stacked (m, 16, 6): callers only read them.

    The last specs' array is kept (specs are immutable; a scenario's contacts give the same
    spec objects at every posture): one tuple, swapped whole, so threads never mix two answers.
    """
    global _LAST_FACES
    last, faces = _LAST_FACES
    if len(last) == len(specs) and all(a is b for a, b in zip(last, specs, strict=True)):
        return faces
    faces = np.array(
        [
            local_faces(float(c.friction), 0.5 * float(c.size[0]), 0.5 * float(c.size[1]))
            for c in specs
        ]
    ).reshape(len(specs), 16, 6)
    _LAST_FACES = (specs, faces)
    return faces


def impact_answer(
    scenario: Scenario,
    stance: Stance,
    areas: BalanceAreas,
    model: ImpactModel,
    criterion: ComCriterion | None = None,
) -> ImpactAnswer:
    """What the criteria answer for an impact: the second half of the pipeline, composed once.

    The CoM velocity criterion with the scenario's ``velocity_margin`` (m/s), its safe interval
    of approach speeds, the ZMP criterion (impulse duration ``impact.duration``), and the
    reference velocity brought into the safe interval. :func:`analyze` and the sweep evaluator
    both use it; the paper's QP is :func:`analyze`'s alone.

    Args:
        scenario: The scenario (its ``impact`` must be set); ``com_velocity`` (m/s, world xy),
            ``plane_height`` (m) and ``gravity`` (m/s^2) are used.
        stance: The stance the areas were computed at.
        areas: Its ZMP support area and CoM velocity area.
        model: The impact model at that stance.
        criterion: The paper's CoM criterion of ``areas`` and ``model`` with the scenario's
            velocity margin, when the caller has made it (the compiled posture's rates); None:
            made here.

    Returns:
        The answer, without the QP (``qp`` is None).

    Raises:
        ScenarioError: The scenario has no impact.
    """
    cfg = scenario.impact
    if cfg is None:
        raise ScenarioError("impact", None, "the scenario has no impact to answer for")
    if criterion is None:
        criterion = ComCriterion(areas.com_velocity_area, model, scenario.velocity_margin)
    com = criterion.limit(scenario.com_velocity)
    zmp = zmp_max_contact_velocity(
        areas.zmp_area, model, stance.com, scenario.plane_height, scenario.gravity, cfg.duration
    )
    term = angular_momentum_term(scenario, stance, areas, model)
    extended = None
    default_limit = com
    if term is not None:
        criterion = ComCriterion(areas.com_velocity_area, model, scenario.velocity_margin, term)
        extended = default_limit = criterion.limit(scenario.com_velocity)
    interval = criterion.interval(scenario.com_velocity, default_limit)
    contact_velocity = None
    if cfg.reference_velocity is not None:
        contact_velocity = safe_contact_velocity(cfg.reference_velocity, model.normal, interval)
    return ImpactAnswer(model, com, zmp, contact_velocity, None, interval, term, extended)


def angular_momentum_term(
    scenario: Scenario, stance: Stance, areas: BalanceAreas, model: ImpactModel
) -> AngularMomentumTerm | None:
    """The scenario's angular momentum term at a stance, or None (the paper's criterion).

    Args:
        scenario: Its ``angular_momentum_damping_time`` (s, None: off) and ``gravity`` are used.
        stance: Its CoM (world, m) is the moment's centre.
        areas: Their ``omega`` (1/s) is the LIPM's.
        model: The impact model (its point, world, m).

    Returns:
        The term, or None when the scenario leaves the option off.
    """
    tau = scenario.angular_momentum_damping_time
    if tau is None:
        return None
    gain = angular_momentum_gain(areas.omega, scenario.gravity, tau)
    return AngularMomentumTerm(np.asarray(model.point - stance.com, dtype=float), gain, float(tau))


def _area_checks(stance: Stance, areas: BalanceAreas) -> list[tuple[str, Any, tuple[str, ...]]]:
    """(result field, value, scenario fields that can make it overflow) of the areas step.

    A polygon's value is its squared size (:func:`_check_finite` computes it): its overflow is
    that of the area and of its edge normals.
    """
    return [
        ("com", stance.com, ("base.position",)),
        ("omega", areas.omega, ("plane_height", "gravity")),
        ("zmp_area", areas.zmp_area, ("plane_height", "base.position")),
        ("com_velocity_area", areas.com_velocity_area, ("plane_height", "gravity")),
    ]


def _squared_size(polygon: Polygon) -> float:
    """Sum of the squared vertex coordinates (inf when they overflow, NaN with a NaN).

    Call it with numpy's overflow and invalid warnings off.
    """
    v = polygon.vertices.ravel()
    return float(v @ v)


def _impact_checks(model: ImpactModel) -> list[tuple[str, Any, tuple[str, ...]]]:
    """Like :func:`_area_checks`, for the impact model."""
    return [
        ("impact.point", model.point, ("impact.offset", "base.position")),
        ("impact.W", model.W, ("impact.offset",)),
        ("impact.impulse_vertices", model.impulse_rates, ("impact.offset", "impact.friction")),
    ]


def _posture_finite(stance: Stance, areas: BalanceAreas, model: ImpactModel) -> bool:
    """Whether :func:`_check_finite` of the areas' and the model's checks passes, in one call.

    :func:`_finite_kernel` on the values of :func:`_area_checks` and :func:`_impact_checks`:
    False exactly where :func:`_check_finite` raises (its caller then calls it, to name the
    field).
    """
    # interpreted (without numba), numpy's dot warns of the overflow it reports
    quiet = contextlib.nullcontext() if HAVE_NUMBA else np.errstate(over="ignore", invalid="ignore")
    with quiet:
        return bool(
            _finite_kernel(
                stance.com, float(areas.omega), areas.zmp_area.vertices,
                areas.com_velocity_area.vertices, model.point, model.W, model.impulse_rates,
            )
        )  # fmt: skip


@njit(cache=True)
def _finite_kernel(
    com: np.ndarray,
    omega: float,
    zmp: np.ndarray,
    velocity: np.ndarray,
    point: np.ndarray,
    W: np.ndarray,
    impulse_rates: np.ndarray,
) -> bool:
    """Whether every number is finite, and each polygon's squared size.

    The squared size of ``zmp`` and ``velocity`` (vertices) is ``v @ v`` of the raveled
    vertices, BLAS's dot, as :func:`_squared_size`.
    """
    return (
        math.isfinite(omega)
        and _all_finite(com)
        and _all_finite(point)
        and _all_finite(W.ravel())
        and _all_finite(impulse_rates.ravel())
        and _finite_size(zmp.ravel())
        and _finite_size(velocity.ravel())
    )


@njit(cache=True)
def _all_finite(values: np.ndarray) -> bool:
    """Whether every number of ``values`` (1-d) is finite."""
    for x in values:
        if not math.isfinite(x):
            return False
    return True


@njit(cache=True)
def _finite_size(vertices: np.ndarray) -> bool:
    """Whether the squared size ``v @ v`` of the raveled ``vertices`` is finite (BLAS's dot)."""
    return vertices.size == 0 or math.isfinite(np.dot(vertices, vertices))


def _check_finite(checks: list[tuple[str, Any, tuple[str, ...]]]) -> None:
    """Raise :class:`NonFiniteResultError` naming the first non-finite result (never NaN out).

    The values are floats, arrays and polygons (their :func:`_squared_size`). One sum over
    everything first (a NaN or an infinity anywhere makes it non-finite), so the common case
    costs a few microseconds; the field is looked for only on failure.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        values = [
            _squared_size(value) if isinstance(value, Polygon) else value for _, value, _ in checks
        ]
        total = 0.0
        for value in values:  # the array method: numpy's np.sum wrapper costs ~2 us each
            total += value if isinstance(value, float) else float(np.asarray(value).sum())
        if math.isfinite(total):
            return
        for (name, _, inputs), value in zip(checks, values, strict=True):
            if not np.isfinite(value).all():
                raise NonFiniteResultError(name, inputs)
        # every part finite: only their sum overflowed
