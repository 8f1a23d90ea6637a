"""The impact-speed governor: the balance criterion as a per-tick speed limit for a controller."""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from impact_balance.balance.areas import warm_up as warm_up_maps
from impact_balance.contacts.stance import has_free_flyer
from impact_balance.criteria.cap import cap_approach
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.exceptions import GovernorError, ScenarioError
from impact_balance.governor.limit import SpeedLimit
from impact_balance.governor.posture import Posture, PostureEvaluator, PostureSettings
from impact_balance.governor.support import ContactAwareLimit, combine
from impact_balance.governor.worker import ContactAwareWorker
from impact_balance.projection.bretl import warm_up as warm_up_bretl
from impact_balance.projection.walk import warm_up
from impact_balance.robot.robot import Robot
from impact_balance.scenario import (
    BasePose,
    Scenario,
    load_scenario,
    scenario_from_dict,
    with_source,
)

__all__ = ["CRITERIA", "Governor"]

#: The governor's criteria: "com", the CoM velocity area (the paper's); "zmp", the predicted
#: ZMP stays in the ZMP support area (the paper's Experiment 1 comparison).
CRITERIA = ("com", "zmp")

#: Largest |norm - 1| of the base quaternion in q (pinocchio's order x, y, z, w).
QUATERNION_TOLERANCE = 1e-6


class Governor:
    """The maximum impact speed for the measured state, every control tick.

    Built once from a scenario (the robot, its sustained contacts, the impacting frame and
    offset, the expected surface normal, the impact's friction, restitution and inertia
    model, the ZMP margin, the LIPM plane, gravity, torque limits); the scenario's posture
    (``configuration``, ``joints``, ``base``) and ``com_velocity`` are NOT used: every call
    gives the state. Then, each tick::

        limit = governor.limit(q, v)           # SpeedLimit: maximum, limiting vertex, safe interval
        u = governor.cap(u_ref)                # the reference end-effector velocity, capped

    ``q`` (nq) and ``v`` (nv) are in pinocchio's order for the robot's model: ``q`` = base
    position (m, world), base quaternion (x, y, z, w), joint positions; ``v`` = base linear
    and angular velocity in the BASE frame (pinocchio's convention for a free flyer; rotate a
    world-frame estimate by the base orientation's transpose first), joint velocities. The
    contacts and the impact point are robot frames: their world poses come from ``q``, so the
    governor follows the robot. The CoM velocity is the model's, ``J_com(q) v``.

    Reuse. The per-posture work (kinematics, the contact wrench polytope and its projection,
    the impact model) is redone only when ``q`` changes by more than ``posture_tolerance``
    (max-abs over the entries of q, in their units; default 0: any change, compared
    exactly); otherwise only the CoM velocity is new and a tick costs a few microseconds.
    With a tolerance, the answer is that of the posture last computed. The robot model,
    the contact specifications and the impact's friction cone are built once; the governor
    has its own pinocchio Data (made once, ~2 ms) and allocates no model per tick.

    Thread safety. One lock per instance serialises :meth:`limit`, :meth:`limit_com` and
    :meth:`cap` (they share the Data and the cached posture): several threads may call one
    governor, each call sees a consistent state, and the answers are those of serial calls.
    Calls do not run in parallel: give each thread its own governor for that.
    :meth:`cap` without a ``limit`` caps with the last answer of any thread; pass the
    :class:`SpeedLimit` you got (or call :meth:`SpeedLimit.cap`) to cap with your own.

    Args:
        scenario: A :class:`~impact_balance.scenario.Scenario`, a scenario file or a bundled
            name; it must have an ``impact``.
        criterion: "com" (default) or "zmp" (see :data:`CRITERIA`).
        posture_tolerance: See "Reuse" above (>= 0).
        contact_aware: Also bound the speed by the contact-aware impact model's CoM velocity
            jump (:mod:`.support`: the robot standing on its supports; the answer is then the
            criterion for the union of both models' post-impact CoM velocities, the smaller
            maximum). "com" criterion, composite inertia only. Its jump rates are recomputed
            every ``contact_aware_every`` posture evaluations (default 5), not every posture;
            with ``contact_aware_async``, by a worker process off the tick instead (:mod:`.worker`:
            the tick never waits for them; rates one recomputation old; :meth:`close` stops it).
            ``contact_aware_starts``: "union" (default: the criterion holds for every solution
            of the frictional impact LCP reached from the kept solutions and the cold start),
            "warm" (the option as frozen in commit 5e477e6: one fixed point, warm-started from
            the previous answer) or "cold" (one, from gauges 0); see :mod:`.support`.
        contact_aware_async: With ``contact_aware``, recompute its rates in a worker process
            (:mod:`.worker`, POSIX) instead of in the tick: each posture tick polls for a
            finished answer (~1 us) and hands the worker the current posture when it is idle;
            it never waits. Call :meth:`close` (or use ``with``) to stop the worker.
        velocity_margin: Every post-impact CoM velocity must lie this far (m/s) inside the
            CoM velocity area ("com" criterion, both models): a margin for the impact model's
            error, as ``zmp_margin`` is one for the controller's. Default 0, the paper's
            criterion (and ``analyze()``'s answer, which has no such margin). See
            docs/governor.md, "A margin for the impact model's error".

    Raises:
        ScenarioError: no impact, an unknown frame, an impact model that cannot be built at
            the scenario's posture (the scenario is evaluated once, as a check).
        GovernorError: an unknown criterion or a bad tolerance.
    """

    def __init__(
        self,
        scenario: Scenario | str | os.PathLike,
        criterion: str = "com",
        posture_tolerance: float = 0.0,
        contact_aware: bool = False,
        contact_aware_every: int = 5,
        contact_aware_starts: str = "union",
        velocity_margin: float = 0.0,
        contact_aware_async: bool = False,
    ):
        if criterion not in CRITERIA:
            raise GovernorError("criterion", criterion, f"must be one of {', '.join(CRITERIA)}")
        try:
            velocity_margin = float(velocity_margin)
        except (TypeError, ValueError):
            velocity_margin = math.nan
        if not (math.isfinite(velocity_margin) and 0.0 <= velocity_margin <= 10.0):
            raise GovernorError(
                "velocity_margin", velocity_margin, "must be a number in [0, 10] m/s"
            )
        if velocity_margin and criterion != "com":
            raise GovernorError(
                "velocity_margin", velocity_margin, "applies to the com criterion only"
            )
        try:
            tolerance = float(posture_tolerance)
        except (TypeError, ValueError):
            tolerance = math.nan
        if not (math.isfinite(tolerance) and tolerance >= 0.0):
            raise GovernorError(
                "posture_tolerance", posture_tolerance, "must be a finite number >= 0"
            )
        if not isinstance(scenario, Scenario):
            scenario = load_scenario(scenario)
        if scenario.impact is None:
            raise with_source(
                ScenarioError("impact", None, "the governor needs an impact (frame, normal...)"),
                scenario.source,
            )
        self.scenario = scenario
        self.criterion = criterion
        self.posture_tolerance = tolerance
        self.robot: Robot = scenario.load_robot()
        model = self.robot.model
        self.nq, self.nv = model.nq, model.nv
        self._free_flyer = has_free_flyer(model)
        settings = PostureSettings(
            tuple(c.spec() for c in scenario.contacts),
            scenario.impact.spec(),
            float(scenario.plane_height),
            float(scenario.gravity),
            bool(scenario.torque_limits),
            float(scenario.zmp_margin),
            criterion,
            velocity_margin,
        )
        self.velocity_margin = velocity_margin
        #: The scenario's own configuration (lifted onto the ground as ``analyze`` does): a
        #: posture to start from.
        self.configuration: np.ndarray = scenario.build_stance(self.robot).q.copy()
        self._evaluator = PostureEvaluator(self.robot, settings)
        self._lock = threading.Lock()
        self._support: ContactAwareLimit | None = None
        if contact_aware:
            if criterion != "com":
                raise GovernorError("contact_aware", criterion, "bounds the CoM criterion only")
            self._support = ContactAwareLimit(
                settings.impact, contact_aware_every, contact_aware_starts
            )
        elif contact_aware_async:
            raise GovernorError(
                "contact_aware_async", contact_aware_async, "needs contact_aware=True"
            )
        self._worker: ContactAwareWorker | None = None
        self._posture: Posture | None = None
        self._last: SpeedLimit | None = None
        warm_up()  # the projection kernel's one-time load, not in the first tick
        warm_up_bretl()  # the fallback's (HiGHS), so that a tick that falls back pays 5 ms, not 71
        warm_up_maps()  # and the fallback's compiled map (12 ms on its first call)
        try:  # a check of the frames, the normal and the friction, at the scenario's posture
            self._posture = self._evaluator.evaluate(self.configuration)
        except ScenarioError as exc:
            raise with_source(exc, scenario.source) from None
        if (
            self._posture.com_criterion is not None
        ):  # load the criterion's compiled code (1-3 ms) here too
            self._posture.com_criterion.limit(np.zeros(3))
            self._posture.com_criterion.limits(np.zeros(3), np.zeros((1, 2)))
        self._support_posture: bytes | None = None
        if self._support is not None and contact_aware_async:
            # The worker's first answer (the scenario's posture, which loads its compiled code)
            # gives the first rates; then it keeps them fresh.
            self._worker = ContactAwareWorker(scenario, contact_aware_starts)
            self._support.adopt(self._worker.warm_up(self._posture.q))

    def close(self) -> None:
        """Stop the contact-aware worker process, if any (``contact_aware_async``); the
        governor then recomputes the rates in the tick, as without it. Idempotent.
        """
        with self._lock:
            if self._worker is not None:
                self._worker.close()
                self._worker = None

    def __enter__(self) -> Governor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- per tick ---------------------------------------------------------------------------
    def limit(self, q: Sequence[float], v: Sequence[float]) -> SpeedLimit:
        """The speed limit at configuration ``q`` (nq) and generalized velocity ``v`` (nv),
        pinocchio's order and conventions (see the class docstring).

        Raises:
            GovernorError: ``q`` or ``v`` of the wrong size, not finite, or a base
                quaternion that is not unit (within 1e-6); with ``contact_aware_async``, a
                worker that failed on an earlier posture or ended.
            ScenarioError, ImpactModelError, SolverError: a posture the pipeline cannot
                evaluate (see :meth:`~impact_balance.governor.posture.PostureEvaluator.evaluate`).
        """
        q = self._configuration(q)
        v = _vector(v, self.nv, "v")
        with self._lock:
            posture, reused = self._posture_at(q)
            return self._answer(posture, posture.com_jacobian @ v, reused)

    def limit_com(self, q: Sequence[float], com_velocity: Sequence[float]) -> SpeedLimit:
        """:meth:`limit` with the CoM velocity given (world, m/s; 2 or 3 numbers, only x and y
        matter), for a controller with its own CoM velocity estimate.
        """
        q = self._configuration(q)
        c = np.asarray(com_velocity, dtype=float).ravel() if _is_numeric(com_velocity) else None
        if c is None or c.size not in (2, 3) or not math.isfinite(float(c @ c)):
            raise GovernorError(
                "com_velocity", com_velocity, "must be 2 or 3 finite numbers (world, m/s)"
            )
        c = np.append(c, 0.0) if c.size == 2 else c.copy()
        with self._lock:
            posture, reused = self._posture_at(q)
            return self._answer(posture, c, reused)

    def cap(
        self, reference_velocity: Sequence[float] | None = None, limit: SpeedLimit | None = None
    ) -> np.ndarray:
        """The reference end-effector velocity (world, m/s) with its approach speed brought
        into the safe interval of ``limit`` (default: this governor's last answer); see
        :func:`~impact_balance.criteria.cap.cap_approach`. Without ``reference_velocity``,
        the scenario's ``impact.reference_velocity``.

        Raises:
            GovernorError: no limit yet (call :meth:`limit` first), no reference, or a bad one.
        """
        if reference_velocity is None:
            reference_velocity = self.scenario.impact.reference_velocity
            if reference_velocity is None:
                raise GovernorError(
                    "reference_velocity",
                    None,
                    "give one (the scenario has no impact.reference_velocity)",
                )
        if limit is None:
            with self._lock:
                limit = self._last
            if limit is None:
                raise GovernorError("limit", None, "no speed limit yet: call limit(q, v) first")
        return cap_approach(reference_velocity, limit.normal, limit.safe_interval)

    def scenario_at(self, q: Sequence[float], com_velocity: Sequence[float]) -> Scenario:
        """The scenario :func:`~impact_balance.analyze` answers the same for (without a
        ``velocity_margin``, which scenarios do not have): this governor's,
        at configuration ``q`` (every joint by name, an explicit ``base`` pose) with
        ``com_velocity`` (world, m/s; e.g. a :class:`SpeedLimit`'s). To replay or save a tick.

        Raises:
            ScenarioError: a joint outside its position limits (scenarios refuse those).
        """
        q = self._configuration(q)
        c = np.asarray(com_velocity, dtype=float).ravel()
        robot, joints = self.robot, {}
        for name in robot.joint_names:
            slot = robot.joint_slot(name)
            if slot.nq == 1:
                joints[name] = float(q[slot.idx_q])
            elif slot.nq == 2 and slot.nv == 1:  # continuous: (cos, sin)
                joints[name] = math.atan2(float(q[slot.idx_q + 1]), float(q[slot.idx_q]))
        update: dict = {"joints": joints, "com_velocity": (float(c[0]), float(c[1]))}
        if self._free_flyer:
            rotation = pin.Quaternion(q[3:7]).normalized().matrix()
            rpy = pin.rpy.matrixToRpy(rotation)
            update["base"] = BasePose(position=tuple(map(float, q[:3])), rpy=tuple(map(float, rpy)))
        raw = self.scenario.model_dump(exclude_none=True)
        raw.update(update)
        raw["base"] = update.get("base", BasePose()).model_dump(exclude_none=True)
        return scenario_from_dict(raw, self.scenario.source)

    # -- reading ----------------------------------------------------------------------------
    @property
    def last(self) -> SpeedLimit | None:
        """The last answer (of any thread), None before the first call."""
        with self._lock:
            return self._last

    @property
    def posture(self) -> Posture:
        """The last posture evaluated (the scenario's until the first call): its stance,
        areas and impact model, for display.
        """
        with self._lock:
            assert self._posture is not None
            return self._posture

    # -- internals ---------------------------------------------------------------------------
    def _configuration(self, q: Sequence[float]) -> np.ndarray:
        q = _vector(q, self.nq, "q")
        if self._free_flyer:
            norm = float(q[3:7] @ q[3:7])
            if abs(norm - 1.0) > 2.0 * QUATERNION_TOLERANCE:
                raise GovernorError(
                    "q",
                    q[3:7].tolist(),
                    "the base quaternion (x, y, z, w) must be unit; normalise it",
                )
        return q

    def _posture_at(self, q: np.ndarray) -> tuple[Posture, bool]:
        """The posture of ``q``, reused when it is the cached one (under the lock)."""
        cached = self._posture
        if cached is not None:
            if self.posture_tolerance == 0.0:
                if cached.key == q.tobytes():
                    return cached, True
            elif float(np.abs(q - cached.q).max()) <= self.posture_tolerance:
                return cached, True
        try:
            posture = self._evaluator.evaluate(q)
        except ScenarioError as exc:
            raise with_source(exc, self.scenario.source) from None
        self._posture = posture
        return posture, False

    def _answer(self, posture: Posture, com_velocity: np.ndarray, reused: bool) -> SpeedLimit:
        binding = "floating"
        criterion = posture.com_criterion
        if criterion is not None and self._support is None:
            limit = criterion.limit(com_velocity)
            interval = criterion.interval(com_velocity, limit)
        elif criterion is not None:
            if (
                self._support_posture != posture.key
            ):  # a posture evaluated since: the rates may be due
                if self._worker is None:
                    self._support.new_posture(lambda: posture.stance)
                else:  # collect a finished answer, hand the worker this posture; never wait
                    done = self._worker.poll()
                    if done is None:
                        self._support.aged()
                    else:
                        self._support.adopt(done)
                    if self._worker.idle:
                        self._worker.submit(posture.key, posture.q)
                self._support_posture = posture.key
            limit, aware = self._support.answers(criterion, com_velocity)
            interval = combine(criterion.interval(com_velocity, limit), aware.interval)
            if aware.limit.max_contact_velocity < limit.max_contact_velocity:
                limit, binding = aware.limit, "contact_aware"
        else:
            limit = posture.zmp_limit
            interval = _zmp_interval(limit)
        model = posture.impact
        answer = SpeedLimit(
            self.criterion,
            limit.max_contact_velocity,
            limit.status,
            limit.limiting_vertex,
            limit.limiting_edge,
            interval,
            com_velocity,
            model.normal,
            model.point,
            reused,
            binding,
        )
        self._last = answer
        return answer


def _zmp_interval(limit: ContactVelocityLimit) -> tuple[float, float] | None:
    """The ZMP criterion's safe speeds: from 0 to its maximum, or none when it is already
    violated (the CoM's vertical outside the ZMP area) or the area is empty.
    """
    return limit.interval_from_inside()


def _is_numeric(x) -> bool:
    try:
        np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        return False
    return True


def _vector(x: Sequence[float], size: int, field: str) -> np.ndarray:
    """``x`` as a contiguous float vector of ``size`` finite entries (a copy when converted)."""
    try:
        a = np.ascontiguousarray(x, dtype=float)
    except (TypeError, ValueError):
        raise GovernorError(field, x, f"must be {size} numbers") from None
    if a.shape != (size,):
        raise GovernorError(
            field, f"shape {a.shape}", f"must have {size} entries (the model's n{field})"
        )
    if not math.isfinite(float(a @ a)):
        bad = np.flatnonzero(~np.isfinite(a))
        which = f"entry {int(bad[0])}" if bad.size else "the entries are too large"
        raise GovernorError(field, x, f"must be finite ({which})")
    return a
