"""The impact-speed governor: the balance criterion as a per-tick speed limit for a controller."""

from __future__ import annotations

import math
import os
import threading
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import ArrayLike

from impact_balance._jit import njit
from impact_balance.balance.areas import warm_up as warm_up_maps
from impact_balance.constants import MAX_POSITION, MAX_SPEED
from impact_balance.contacts.contact_model import scaled_contact
from impact_balance.contacts.stance import ContactSpec, has_free_flyer
from impact_balance.criteria.cap import cap_approach
from impact_balance.criteria.linear_exit import BOUNDARY_TOLERANCE, EXIT_STATUSES, speed_interval
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.exceptions import GovernorError, ScenarioError
from impact_balance.governor.batch import BatchEvaluator, BatchLimits
from impact_balance.governor.limit import Binding, SpeedLimit, _floating_limit
from impact_balance.governor.options import (
    CRITERIA,
    ContactAwareOptions,
    Criterion,
    held_stance_option,
    reach_option,
)
from impact_balance.governor.posture import (
    NO_HALFPLANES,
    Posture,
    PostureEvaluator,
    PostureSettings,
)
from impact_balance.governor.support import ContactAwareLimit, combine
from impact_balance.governor.tick import NOT_FINITE, velocity_exit
from impact_balance.governor.worker import ContactAwareWorker
from impact_balance.impact.held_stance import HeldStanceJumps, held_stance_jumps
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
from impact_balance.scenario.calibration import (
    CalibrationFile,
    apply_calibration,
    read_calibration,
)

if TYPE_CHECKING:
    from impact_balance.balance.reach import ComReach, ReachOptions

__all__ = ["Governor"]

#: Largest |norm - 1| of the base quaternion in q (pinocchio's order x, y, z, w), and of a
#: continuous joint's (cos, sin) pair.
QUATERNION_TOLERANCE = 1e-6
#: How far a 1-dof joint of q may lie beyond its finite position limits (rad, or m for a
#: prismatic joint): a measured state may overshoot a limit a little (a soft limit in
#: simulation, encoder noise), a posture farther out is not the robot's.
JOINT_LIMIT_TOLERANCE = 0.1

_MAX_SPEED_SQUARED = MAX_SPEED * MAX_SPEED
#: A bound within reach this close to the criterion's own (m/s) does not bind (the search's
#: tolerance: where the reach exceeds the area, its answer is the area's own up to rounding).
_REACH_TOLERANCE = 1e-9
_FLOAT = np.dtype(np.float64)  # numpy's own float64 dtype: a float array's dtype is this object
_STRIDE = (8,)  # a contiguous float64 vector's
#: The half-planes and rates :func:`velocity_exit` takes where there is no area to exit.
_NO_AREA = (np.zeros((0, 2)), np.zeros(0), np.zeros((0, 0)))


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
    has its own pinocchio Data (made once) and allocates no model per tick.

    Thread safety. One lock per instance serialises :meth:`limit`, :meth:`limit_com` and
    :meth:`cap` (they share the Data and the cached posture): several threads may call one
    governor, each call sees a consistent state, and the answers are those of serial calls.
    Calls do not run in parallel: give each thread its own governor for that.
    :meth:`cap` without a ``limit`` caps with the last answer of any thread; pass the
    :class:`SpeedLimit` you got (or call :meth:`SpeedLimit.cap`) to cap with your own.

    Margins. The scenario's ``zmp_margin`` (m) shrinks the ZMP support area; its
    ``velocity_margin`` (m/s) keeps every post-impact CoM velocity that far inside the CoM
    velocity area ("com" criterion, both impact models; the "zmp" criterion has none): a margin
    for the impact model's error, as ``zmp_margin`` is one for the controller's. Both are read
    as :func:`~impact_balance.analyze` reads them, so ``analyze`` of the same scenario answers
    the same maximum at the scenario's posture and CoM velocity (see :meth:`scenario_at`).
    Its ``angular_momentum_damping_time`` (s) likewise makes the "com" criterion count the
    centroidal angular momentum the impulse leaves, as ``analyze``'s default answer does
    (:mod:`impact_balance.impact.angular_momentum`; the contact-aware bound does not count it).
    Its ``friction_scale`` makes both criteria see every contact's friction times it, as
    ``analyze`` does (the areas a controller that uses that share of the cones can realise).

    Args:
        scenario: A :class:`~impact_balance.scenario.Scenario`, a scenario file or a bundled
            name; it must have an ``impact``.
        criterion: "com" (default) or "zmp" (:data:`~impact_balance.governor.options.Criterion`).
        posture_tolerance: See "Reuse" above (>= 0, in the units of q's entries).
        contact_aware: Also bound the speed by the contact-aware impact model's CoM velocity
            jump (:mod:`.support`: the robot standing on its supports; the answer is then the
            criterion for the union of both models' post-impact CoM velocities, the smaller
            maximum). "com" criterion, composite inertia only. None or False: off; True: on
            with the default :class:`~impact_balance.governor.options.ContactAwareOptions`
            (rates recomputed every 5 posture evaluations, in the tick); or the options.
        velocity_margin: Overrides the scenario's ``velocity_margin`` (m/s; through
            :meth:`~impact_balance.scenario.Scenario.replace`, so checked by the schema).
            None (default): the scenario's.
        calibration: A calibration file (``impact-balance calibrate --out``) or its read
            :class:`~impact_balance.scenario.calibration.CalibrationFile`: its ``zmp_margin``
            (m) replaces the scenario's. Its robot must be the scenario's. None (default): the
            scenario's margin. The calibration read is :attr:`calibration`.
        com_reach: Also cap within the CoM's reach at constant height (docs/com-reach.md):
            each answer is at most the largest approach speed whose post-impact CoM velocities
            (and their effective twins with the angular momentum term) stay within the reach
            (:func:`~impact_balance.impact.within_reach.max_contact_velocity_within_reach`, in
            the posture's CoM velocity area with the ZMP margin), binding "com_reach" where
            that is smaller. The reach is that of the scenario's posture, computed once here
            (the contacts do not change while the governor runs; the reach is not recomputed
            as the posture moves). True: the default search (a few seconds); a
            :class:`~impact_balance.balance.reach.ReachOptions`: that search; a
            :class:`~impact_balance.balance.reach.ComReach`: used as is. A posture evaluation
            computes the bound for its CoM velocity; a tick that reuses the posture reuses that
            bound. "com" criterion only. None or False (default): off. The reach is
            :attr:`com_reach`.
        impact_model: "floating" (default: the paper's impact model) or "held-stance"
            (docs/governor.md): the held-stance jumps
            (:func:`~impact_balance.impact.held_stance.held_stance_jumps`, the contact-aware
            model at the restitution bounds) of the scenario's posture, computed once here
            (like the reach, not recomputed as the posture moves), replace the floating
            model's post-impact jumps: each answer is the largest approach speed keeping
            ``c0 + s j`` in the posture's CoM velocity area with the velocity margin for both
            jumps j, binding "held_stance" (the angular momentum term is not counted). Where
            a fixed point was not reached, the answers are the floating model's (binding
            "floating"), the fallback of ``analyze --impact-model held-stance``. "com"
            criterion only, not with ``contact_aware`` or ``com_reach``. The jumps are
            :attr:`held_stance`.

    Raises:
        ScenarioError: another robot's or a bad calibration, no impact, an unknown frame, an
            impact model that cannot be built at the scenario's posture (the scenario is
            evaluated once, as a check).
        GovernorError: an unknown criterion, a bad tolerance, a bad ``velocity_margin``
            (or one with the "zmp" criterion), contact-aware options or a reach with the "zmp"
            criterion, a ``com_reach`` of another type, an unknown ``impact_model`` or
            "held-stance" with the "zmp" criterion, ``contact_aware`` or ``com_reach``.
    """

    def __init__(
        self,
        scenario: Scenario | str | os.PathLike[str],
        criterion: Criterion = "com",
        *,
        posture_tolerance: float = 0.0,
        contact_aware: ContactAwareOptions | bool | None = None,
        velocity_margin: float | None = None,
        calibration: CalibrationFile | str | os.PathLike[str] | None = None,
        com_reach: ComReach | ReachOptions | bool | None = None,
        impact_model: str = "floating",
    ) -> None:
        if criterion not in CRITERIA:
            raise GovernorError("criterion", criterion, f"must be one of {', '.join(CRITERIA)}")
        held_stance_option(impact_model, criterion, contact_aware, com_reach)
        self.criterion: Criterion = criterion
        self.posture_tolerance = _tolerance(posture_tolerance)
        aware = _contact_aware(contact_aware, criterion)
        scenario = _governed(scenario, criterion, velocity_margin)
        #: The calibration whose ZMP margin is in use, or None.
        self.calibration: CalibrationFile | None = None
        if calibration is not None:
            self.calibration, scenario = _calibrated(scenario, calibration)
        self.scenario = scenario
        #: The velocity margin in use, m/s (the scenario's; 0 with the "zmp" criterion).
        self.velocity_margin = scenario.velocity_margin if criterion == "com" else 0.0
        self.robot: Robot = scenario.load_robot()
        model = self.robot.model
        self.nq, self.nv = model.nq, model.nv
        self._q_shape, self._v_shape = (self.nq,), (self.nv,)
        self._free_flyer = has_free_flyer(model)
        self._joints = _JointBounds(self.robot)
        assert scenario.impact is not None  # _governed refuses a scenario without one
        # The stance analyze() builds: its contacts are resolved there (a contact given by its
        # world normal is turned into an offset fixed in its frame at the scenario's posture).
        stance = scenario.build_stance(self.robot)
        #: The scenario's own configuration (lifted onto the ground as ``analyze`` does): a
        #: posture to start from.
        self.configuration: np.ndarray = stance.q.copy()
        #: The sustained contacts, resolved (frame, size, friction, offset in the frame).
        self.contacts: tuple[ContactSpec, ...] = tuple(c.spec for c in stance.contacts)
        #: The CoM's reach of the scenario's posture the answers are capped within, or None.
        self.com_reach: ComReach | None = reach_option(com_reach, criterion, stance)
        self._reach_bound: tuple[bytes, float] | None = None  # (posture key, bound m/s)
        #: The held-stance jumps of the scenario's posture (``impact_model="held-stance"``),
        #: or None.
        self.held_stance: HeldStanceJumps | None = None
        if impact_model == "held-stance":
            self.held_stance = held_stance_jumps(stance, scenario.impact.spec())
        settings = PostureSettings(
            # The criterion's contacts: friction times the scenario's friction_scale.
            tuple(scaled_contact(c, scenario.friction_scale) for c in self.contacts),
            scenario.impact.spec(),
            float(scenario.plane_height),
            float(scenario.gravity),
            bool(scenario.torque_limits),
            float(scenario.zmp_margin),
            criterion,
            self.velocity_margin,
            scenario.angular_momentum_damping_time if criterion == "com" else None,
        )
        self._evaluator = PostureEvaluator(self.robot, settings)
        self._batch = BatchEvaluator(
            self.robot, self._evaluator, self._checked_row, self._first_faulty_row
        )
        self._lock = threading.Lock()
        self._support: ContactAwareLimit | None = None
        if aware is not None:
            self._support = ContactAwareLimit(settings.impact, aware.every, aware.starts)
        self._worker: ContactAwareWorker | None = None
        self._last: SpeedLimit | None = None
        self._posture: Posture | None = self._first_posture()
        self._support_posture: bytes | None = None
        self._aware = aware
        self._clock = _RatesClock()  # the rates' age
        if self._support is not None and aware is not None and aware.asynchronous:
            # The worker's first answer (the scenario's posture, which loads its compiled code)
            # gives the first rates; then it keeps them fresh.
            self._worker = ContactAwareWorker(scenario, aware.starts)
            self._support.adopt(self._worker.warm_up(self._posture.q))
            self._support_posture = self._posture.key

    def _first_posture(self) -> Posture:
        """Load the compiled code and evaluate the scenario's posture.

        The posture is a check of the scenario's frames, normal and friction; the first tick
        then pays for neither.
        """
        warm_up()  # the projection kernel's one-time load
        warm_up_bretl()  # the fallback's (HiGHS), so that a tick that falls back is not slow
        warm_up_maps()  # and the fallback's compiled map
        self._state(self.configuration, np.zeros(self.nv))  # and the state check's
        try:
            posture = self._evaluator.evaluate(self.configuration)
            self._evaluator.evaluate(self.configuration, steps=True)  # what the kernel leaves
        except ScenarioError as exc:
            raise with_source(exc, self.scenario.source) from None
        criterion = posture.com_criterion
        if criterion is not None:  # the criterion's compiled code, here too
            criterion.limit(np.zeros(3))
            criterion.limits(np.zeros(3), np.zeros((1, 2)))
        # and the tick's (velocity_exit), for the area's read-only half-planes and for none
        J, G, h, rates = posture.exit_arrays
        still, c = np.zeros(self.nv), np.empty(3)
        velocity_exit(J, still, G, h, rates, BOUNDARY_TOLERANCE, 1.0, c)
        velocity_exit(J, still, _NO_AREA[0], _NO_AREA[1], _NO_AREA[2], BOUNDARY_TOLERANCE, 1.0, c)
        return posture

    def close(self) -> None:
        """Stop the contact-aware worker process, if any (``contact_aware_async``).

        The governor then recomputes the rates in the tick, as without it. Idempotent.
        """
        with self._lock:
            if self._worker is not None:
                self._worker.close()
                self._worker = None

    def __enter__(self) -> Governor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- per tick ---------------------------------------------------------------------------
    def limit(self, q: ArrayLike, v: ArrayLike) -> SpeedLimit:
        """The speed limit at configuration ``q`` and generalized velocity ``v``.

        Args:
            q: The configuration (nq), pinocchio's order and conventions (class docstring).
            v: The generalized velocity (nv), pinocchio's order and conventions.

        Returns:
            The speed limit (m/s), its limiting vertex and edge, the safe interval.

        Raises:
            GovernorError: ``q`` or ``v`` not real numbers, of the wrong size, not finite, a
                base quaternion that is not unit (within :data:`QUATERNION_TOLERANCE`), a joint
                beyond its limits by more than :data:`JOINT_LIMIT_TOLERANCE`; with
                ``contact_aware_async``, rates older than the options allow with
                ``on_stale="raise"``, and :class:`~.worker.WorkerError` for a worker that
                failed on an earlier posture or ended.
            ScenarioError, ImpactModelError, SolverError: a posture the pipeline cannot
                evaluate (see :meth:`~impact_balance.governor.posture.PostureEvaluator.evaluate`).
        """
        with self._lock:
            posture = self._posture
            # The very q of the cached posture (checked when it was evaluated): no check again.
            if (
                posture is not None
                and type(q) is np.ndarray
                and q.dtype is _FLOAT
                and q.shape == self._q_shape
                and q.tobytes() == posture.key
            ):
                answer = self._tick(posture, _velocity(v, self._v_shape), True)
                if self.held_stance is not None:
                    return self._held(posture, answer)
                return answer if self.com_reach is None else self._within_reach(posture, answer)
        configuration, velocity = self._state(q, v)
        with self._lock:
            posture, reused = self._posture_at(configuration, checked=True)
            answer = self._tick(posture, velocity, reused)
            if self.held_stance is not None:
                return self._held(posture, answer)
            return answer if self.com_reach is None else self._within_reach(posture, answer)

    def _state(
        self, q: ArrayLike, v: ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``q`` and ``v`` as contiguous float vectors, checked as :meth:`limit` says.

        Contiguous float64 arrays of the right sizes are checked in one compiled pass
        (:func:`_state_fault`); anything else, or a state it finds at fault, by the checks that
        name the field and value (in the order q, v, the joints).
        """
        configuration, velocity = _as_is(q, self._q_shape), _as_is(v, self._v_shape)
        joints = self._joints
        if (
            configuration is None
            or velocity is None
            or _state_fault(
                configuration,
                velocity,
                joints.idx,
                joints.lower,
                joints.upper,
                joints.pair_indices,
                self._free_flyer,
                MAX_POSITION,
                QUATERNION_TOLERANCE,
            )
        ):
            configuration = self._configuration(q)
            velocity = _vector(v, self.nv, "v")
            joints.check(configuration)
        return configuration, velocity

    def _tick(self, posture: Posture, v: npt.NDArray[np.float64], reused: bool) -> SpeedLimit:
        """The answer at ``posture`` for the generalized velocity ``v`` (under the lock).

        ``v``: (nv,) contiguous floats, checked here (not finite, or a CoM speed above
        ``MAX_SPEED``: :class:`GovernorError`). The "com" criterion without the contact-aware
        bound is one compiled call (:func:`~impact_balance.governor.tick.velocity_exit`) and the
        answer; the others go through :meth:`_answer`.
        """
        J, G, h, rates = posture.exit_arrays
        fast = G is not NO_HALFPLANES and self._support is None
        if not fast:
            G, h, rates = _NO_AREA
        com_velocity = np.empty(3)
        code, speed, j, k, lo, hi = velocity_exit(
            J, v, G, h, rates, BOUNDARY_TOLERANCE, _MAX_SPEED_SQUARED, com_velocity
        )
        if code < 0:
            _refuse_velocity(code, v, self.nv, com_velocity)
        if not fast:  # the general answer
            return self._answer(posture, com_velocity, reused)
        point, normal = posture.impact_point_normal
        vertex, edge = (j, k) if code == 0 else (None, None)
        interval = None if math.isnan(lo) else (lo, hi)
        if code != 0:  # "already_falling" (0) or "unbounded" (inf)
            speed = 0.0 if code == 1 else math.inf
        self._last = answer = _floating_limit(
            self.criterion,
            speed,
            EXIT_STATUSES[code],
            vertex,
            edge,
            interval,
            com_velocity,
            normal,
            point,
            reused,
        )
        return answer

    def limits(self, q_batch: ArrayLike, v_batch: ArrayLike, *, threads: int = 1) -> BatchLimits:
        """The speed limits of N postures: row i is ``limit(q_batch[i], v_batch[i])``.

        Equal to N calls of :meth:`limit` (to rounding: 1e-12 m/s in the tests), each posture
        evaluated (the ``posture_tolerance`` and the last answer are neither used nor
        changed). The areas and the criterion of all postures run in one compiled call
        (:mod:`impact_balance.governor.batch`); ``threads`` > 1 hands chunks of rows to the
        calling thread and threads kept by the governor for its next batches. The answers do
        not depend on ``threads``, to the last digit.

        Args:
            q_batch: (N, nq) configurations, as :meth:`limit`'s ``q``.
            v_batch: (N, nv) generalized velocities, as :meth:`limit`'s ``v``.
            threads: Threads to share the rows (1 to 64; each makes its own pinocchio Data).

        Returns:
            The N answers as arrays (a row as a :class:`SpeedLimit`: ``answers[i]``).

        Raises:
            GovernorError: Not (N, nq) and (N, nv) real finite numbers, a row that
                :meth:`limit` refuses (the field names the row: ``q_batch[3]``), ``threads``
                out of range, or a ``contact_aware`` governor (the batch answers the floating
                criterion only).
            ScenarioError, ImpactModelError, SolverError: A posture the pipeline cannot
                evaluate, as :meth:`limit`.
        """
        if self._support is not None:
            raise GovernorError(
                "contact_aware",
                True,
                "limits() answers the floating criterion only; call limit() per posture",
            )
        if self.com_reach is not None:
            raise GovernorError(
                "com_reach", True, "limits() answers without the reach; call limit() per posture"
            )
        if self.held_stance is not None:
            raise GovernorError(
                "impact_model",
                "held-stance",
                "limits() answers the floating model only; call limit() per posture",
            )
        try:
            return self._batch.limits(q_batch, v_batch, threads)
        except ScenarioError as exc:
            raise with_source(exc, self.scenario.source) from None

    def limit_com(self, q: ArrayLike, com_velocity: ArrayLike) -> SpeedLimit:
        """:meth:`limit` with the CoM velocity given, for a controller with its own estimate.

        Args:
            q: The configuration (nq), pinocchio's order and conventions.
            com_velocity: The CoM velocity (world, m/s; 2 or 3 numbers, only x and y matter).

        Returns:
            The speed limit, as :meth:`limit`'s.

        Raises:
            GovernorError: A bad ``q`` (as :meth:`limit`) or ``com_velocity``.
        """
        configuration = self._configuration(q)
        c = np.asarray(com_velocity, dtype=float).ravel() if _is_real(com_velocity) else None
        if c is None or c.size not in (2, 3) or not np.isfinite(c).all():
            raise GovernorError(
                "com_velocity", com_velocity, "must be 2 or 3 finite real numbers (world, m/s)"
            )
        if math.hypot(*c) > MAX_SPEED:
            raise GovernorError(
                "com_velocity", com_velocity, f"the speed must be at most {MAX_SPEED:g} m/s"
            )
        c = np.append(c, 0.0) if c.size == 2 else c.copy()
        with self._lock:
            posture, reused = self._posture_at(configuration)
            answer = self._answer(posture, c, reused)
            if self.held_stance is not None:
                return self._held(posture, answer)
            return answer if self.com_reach is None else self._within_reach(posture, answer)

    def cap(
        self, reference_velocity: ArrayLike | None = None, limit: SpeedLimit | None = None
    ) -> npt.NDArray[np.float64]:
        """The reference velocity with its approach speed brought into the safe interval.

        See :func:`~impact_balance.criteria.cap.cap_approach`.

        Args:
            reference_velocity: The reference end-effector velocity (world, m/s); None: the
                scenario's ``impact.reference_velocity``.
            limit: The answer whose safe interval caps it (default: this governor's last).

        Returns:
            The capped velocity (world, m/s).

        Raises:
            GovernorError: no limit yet (call :meth:`limit` first), no reference, or a bad one.
        """
        if reference_velocity is None:
            assert self.scenario.impact is not None  # the constructor refuses a scenario without
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
        elif not isinstance(limit, SpeedLimit):
            raise GovernorError(
                "limit", limit, "must be a SpeedLimit (a governor's answer) or None"
            )
        return cap_approach(reference_velocity, limit.normal, limit.safe_interval)

    def scenario_at(self, q: ArrayLike, com_velocity: ArrayLike) -> Scenario:
        """The scenario :func:`~impact_balance.analyze` answers the same for (its margins included).

        This governor's, at configuration ``q`` (every joint by name, an explicit ``base``
        pose) with ``com_velocity`` (world, m/s; e.g. a :class:`SpeedLimit`'s). To replay or
        save a tick.

        Raises:
            ScenarioError: a joint outside its position limits (scenarios refuse those).
        """
        configuration = self._configuration(q)
        self._joints.check(configuration)
        c = np.asarray(com_velocity, dtype=float).ravel()
        robot, joints = self.robot, {}
        for name in robot.joint_names:
            slot = robot.joint_slot(name)
            if slot.nq == 1:
                joints[name] = float(configuration[slot.idx_q])
            elif slot.nq == 2 and slot.nv == 1:  # continuous: (cos, sin)
                cos, sin = configuration[slot.idx_q], configuration[slot.idx_q + 1]
                joints[name] = math.atan2(float(sin), float(cos))
        update: dict[str, Any] = {"joints": joints, "com_velocity": (float(c[0]), float(c[1]))}
        if self._free_flyer:
            rotation = pin.Quaternion(configuration[3:7]).normalized().matrix()
            x, y, z = (float(a) for a in configuration[:3])
            roll, pitch, yaw = (float(a) for a in pin.rpy.matrixToRpy(rotation))
            update["base"] = BasePose(position=(x, y, z), rpy=(roll, pitch, yaw))
        raw = self.scenario.model_dump(exclude_none=True)
        raw.update(update)
        raw["contacts"] = [
            _fixed_in_frame(c, s) for c, s in zip(raw["contacts"], self.contacts, strict=True)
        ]
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
        """The last posture evaluated (the scenario's until the first call).

        Its stance, areas and impact model, for display.
        """
        with self._lock:
            assert self._posture is not None
            return self._posture

    # -- internals ---------------------------------------------------------------------------
    def _configuration(self, q: ArrayLike) -> npt.NDArray[np.float64]:
        """``q`` as a checked configuration vector (see :meth:`limit`)."""
        configuration, squared = _squared_vector(q, self.nq, "q")
        if self._free_flyer:
            if squared > MAX_POSITION * MAX_POSITION:  # rarely
                _base_within_bounds(configuration)
            x, y, z, w = configuration[3:7].tolist()  # four Python floats: no array product
            if abs(x * x + y * y + z * z + w * w - 1.0) > 2.0 * QUATERNION_TOLERANCE:
                raise GovernorError(
                    "q",
                    [x, y, z, w],
                    "the base quaternion (x, y, z, w) must be unit (within "
                    f"{QUATERNION_TOLERANCE:g}); normalise it",
                )
        return configuration

    def _first_faulty_row(self, qs: npt.NDArray[np.float64]) -> int:
        """The first row that :meth:`_checked_row` refuses, -1 if none (one compiled pass).

        ``qs``: (N, nq) C-contiguous floats; :func:`_rows_fault`.
        """
        joints = self._joints
        return int(
            _rows_fault(
                qs, joints.idx, joints.lower, joints.upper, joints.pair_indices,
                self._free_flyer, MAX_POSITION, QUATERNION_TOLERANCE,
            )
        )  # fmt: skip

    def _checked_row(self, q: npt.NDArray[np.float64], field: str) -> npt.NDArray[np.float64]:
        """Row ``q`` of a batch checked as :meth:`limit` checks ``q`` (errors name ``field``)."""
        try:
            configuration = self._configuration(q)
            self._joints.check(configuration)
        except GovernorError as exc:
            raise GovernorError(field + exc.field[1:], exc.value, exc.reason) from None
        return configuration

    def _posture_at(
        self, q: npt.NDArray[np.float64], checked: bool = False
    ) -> tuple[Posture, bool]:
        """The posture of ``q``, reused when it is the cached one (under the lock).

        ``checked``: the joints of ``q`` were checked already.
        """
        cached = self._posture
        if cached is not None:
            if self.posture_tolerance == 0.0:
                if cached.key == q.tobytes():  # the very q checked when it was evaluated
                    return cached, True
            elif float(np.abs(q - cached.q).max()) <= self.posture_tolerance:
                if not checked:
                    self._joints.check(q)
                return cached, True
        if not checked:
            self._joints.check(q)
        try:
            posture = self._evaluator.evaluate(q)
        except ScenarioError as exc:
            raise with_source(exc, self.scenario.source) from None
        self._posture = posture
        return posture, False

    def _refresh_support(self, support: ContactAwareLimit, posture: Posture) -> None:
        """Keep the contact-aware rates up to date for ``posture`` (under the lock).

        In the tick, the limit recomputes its rates when due (on a new posture); with a
        worker, every tick checks it (a finished answer is collected, a dead worker raised)
        and hands it the current posture when it is idle (never waiting).

        Raises:
            WorkerError: The worker has ended, or failed on the posture it was given.
        """
        clock = self._clock
        new = self._support_posture != posture.key
        if new:
            clock.evaluated()
            self._support_posture = posture.key
        worker = self._worker
        if worker is None:
            if new:
                support.new_posture(lambda: posture.stance)
                if support.age == 0:
                    clock.computed()
            return
        done = worker.poll()
        if done is not None:
            support.adopt(done, clock.adopted())
        elif new:
            support.aged()
        if worker.idle and worker.submitted != posture.key:
            worker.submit(posture.key, posture.q)
            clock.submitted()

    def _stale(self, postures: int, seconds: float) -> bool:
        """Whether the asynchronous rates are older than the options allow.

        Raises:
            GovernorError: They are, and ``on_stale`` is "raise".
        """
        aware = self._aware
        if self._worker is None or aware is None:
            return False
        if postures <= aware.max_age and seconds <= aware.max_age_seconds:
            return False
        if aware.on_stale == "raise":
            raise GovernorError(
                "contact_aware_async",
                f"{postures} postures, {seconds:.3g} s",
                f"the contact-aware rates are older than max_age ({aware.max_age} postures) "
                f"or max_age_seconds ({aware.max_age_seconds:g} s): the worker is stalled",
            )
        return True

    def _answer(
        self, posture: Posture, com_velocity: npt.NDArray[np.float64], reused: bool
    ) -> SpeedLimit:
        """The answer for ``posture`` and the CoM velocity (world, m/s); kept as the last."""
        binding: Binding = "floating"
        criterion = posture.com_criterion
        support = self._support
        limit: ContactVelocityLimit
        ages: tuple[int, float] | None = None
        stale = False
        if criterion is not None and support is None:
            limit = criterion.limit(com_velocity)
            interval = criterion.interval(com_velocity, limit)
        elif criterion is not None and support is not None:
            if self._worker is not None or self._support_posture != posture.key:
                self._refresh_support(support, posture)  # the rates may be due
            ages = self._clock.age()
            stale = self._stale(*ages)
            limit, aware = support.answers(criterion, com_velocity)
            interval = criterion.interval(com_velocity, limit)
            if not stale:
                interval = combine(interval, aware.interval)
                if aware.limit.max_contact_velocity < limit.max_contact_velocity:
                    limit, binding = aware.limit, "contact_aware"
            elif self._aware is not None and self._aware.on_stale == "zero":
                return self._keep(
                    _zero_answer(self.criterion, limit, com_velocity, posture, reused, ages)
                )
        else:
            assert posture.zmp_limit is not None  # the "zmp" criterion's posture has it
            limit = posture.zmp_limit
            interval = _zmp_interval(limit)
        model = posture.impact
        return self._keep(
            SpeedLimit(
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
                None if ages is None else ages[0],
                None if ages is None else ages[1],
                stale,
            )
        )

    def _within_reach(self, posture: Posture, answer: SpeedLimit) -> SpeedLimit:
        """``answer`` capped within the CoM's reach (under the lock); kept as the last.

        The bound is computed when the posture is new (or has none yet) for the answer's CoM
        velocity, and reused while the posture is (see ``com_reach`` in the class docstring).
        """
        reach, criterion = self.com_reach, posture.com_criterion
        speed = answer.max_contact_velocity
        if reach is None or criterion is None or not speed > 0.0:
            return answer
        cached = self._reach_bound
        if cached is None or cached[0] != posture.key or not answer.posture_reused:
            from impact_balance.balance.lipm import lipm_omega
            from impact_balance.impact.within_reach import max_contact_velocity_within_reach

            settings = self._evaluator.settings
            omega = lipm_omega(float(posture.com[2]), settings.plane_height, settings.gravity)
            within = max_contact_velocity_within_reach(
                criterion.area,
                omega,
                reach,
                posture.impact,
                answer.com_velocity[:2],
                criterion.angular_momentum,
                speed,
            )
            # Not binding at this velocity (within the search's 1e-9 m/s): no bound kept.
            cached = (posture.key, within if within < speed - _REACH_TOLERANCE else math.inf)
            self._reach_bound = cached
        bound = cached[1]
        if not bound < speed:
            return answer
        interval = answer.safe_interval
        if interval is not None:
            interval = (interval[0], bound) if interval[0] <= bound else None
        return self._keep(
            replace(answer, max_contact_velocity=bound, safe_interval=interval, binding="com_reach")
        )

    def _held(self, posture: Posture, answer: SpeedLimit) -> SpeedLimit:
        """``answer`` with the held-stance jumps in place of the floating model's (under the lock).

        Kept as the last. Unchanged where a fixed point was not reached (the fallback).
        """
        held, criterion = self.held_stance, posture.com_criterion
        if held is None or criterion is None or not all(held.converged):
            return answer
        _, limit = criterion.limits(answer.com_velocity, held.jumps)
        interval: tuple[float, float] | None
        if criterion.G is None:
            interval = None
        elif limit.from_inside:
            interval = limit.interval_from_inside()
        else:
            interval = speed_interval(
                criterion.margins(answer.com_velocity), held.jumps @ criterion.G.T
            )
        return self._keep(
            replace(
                answer,
                max_contact_velocity=limit.max_contact_velocity,
                status=limit.status,
                limiting_vertex=limit.limiting_vertex,
                limiting_edge=limit.limiting_edge,
                safe_interval=interval,
                binding="held_stance",
            )
        )

    def _keep(self, answer: SpeedLimit) -> SpeedLimit:
        """``answer``, kept as the last (under the lock)."""
        self._last = answer
        return answer


class _RatesClock:
    """The contact-aware rates' age, in postures and in seconds.

    Postures: evaluations since the one the rates are for. Seconds: since the first posture
    evaluated after that one (0 while the rates are the current posture's: rates of a posture
    the robot still holds are exact however old).
    """

    def __init__(self) -> None:
        self.evaluations = 0
        self._rates: tuple[int, float | None] = (0, None)  # (index, first later time)
        self._submitted: tuple[int, float | None] = (0, None)

    def evaluated(self) -> None:
        """A new posture was evaluated."""
        self.evaluations += 1
        now = time.monotonic()
        if self._rates[1] is None:
            self._rates = (self._rates[0], now)
        if self._submitted[1] is None:
            self._submitted = (self._submitted[0], now)

    def computed(self) -> None:
        """The rates were computed for the current posture (in the tick)."""
        self._rates = self._submitted = (self.evaluations, None)

    def submitted(self) -> None:
        """The current posture was handed to the worker."""
        self._submitted = (self.evaluations, None)

    def adopted(self) -> int:
        """The worker's answer (for the posture last submitted) is in use; its age in postures."""
        self._rates = self._submitted
        return self.evaluations - self._rates[0]

    def age(self) -> tuple[int, float]:
        """The rates' age: (postures, seconds)."""
        postures = self.evaluations - self._rates[0]
        later = self._rates[1]
        return postures, 0.0 if postures == 0 or later is None else time.monotonic() - later


def _tolerance(posture_tolerance: float) -> float:
    """``posture_tolerance`` as a float; :class:`GovernorError` unless finite and >= 0."""
    try:
        tolerance = float(posture_tolerance)
    except (TypeError, ValueError):
        tolerance = math.nan
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise GovernorError("posture_tolerance", posture_tolerance, "must be a finite number >= 0")
    return tolerance


def _contact_aware(
    option: ContactAwareOptions | bool | None, criterion: Criterion
) -> ContactAwareOptions | None:
    """The contact-aware options of ``option`` (None: off).

    :class:`GovernorError` when it is not one of None, a bool or :class:`ContactAwareOptions`,
    or with the "zmp" criterion.
    """
    if option is None or option is False:
        return None
    aware = ContactAwareOptions() if option is True else option
    if not isinstance(aware, ContactAwareOptions):
        raise GovernorError(
            "contact_aware", option, "must be True, False, None or a ContactAwareOptions"
        )
    if criterion != "com":
        raise GovernorError("contact_aware", criterion, "bounds the CoM criterion only")
    return aware


def _governed(
    scenario: Scenario | str | os.PathLike[str], criterion: Criterion, margin: float | None
) -> Scenario:
    """The scenario a governor answers for.

    Loaded, with an impact, its ``velocity_margin`` replaced by ``margin`` when given
    (:class:`GovernorError` naming ``velocity_margin`` when the schema refuses it, or when it is
    not 0 with the "zmp" criterion).
    """
    if not isinstance(scenario, Scenario):
        if not isinstance(scenario, (str, os.PathLike)):
            raise GovernorError(
                "scenario",
                scenario,
                "must be a Scenario, a scenario file or a bundled scenario name",
            )
        scenario = load_scenario(scenario if isinstance(scenario, str) else Path(scenario))
    if scenario.impact is None:
        raise with_source(
            ScenarioError("impact", None, "the governor needs an impact (frame, normal...)"),
            scenario.source,
        )
    if margin is None:
        return scenario
    try:
        scenario = scenario.replace(velocity_margin=margin)
    except ScenarioError as exc:
        raise GovernorError("velocity_margin", margin, exc.reason) from None
    if scenario.velocity_margin and criterion != "com":
        raise GovernorError("velocity_margin", margin, "applies to the com criterion only")
    return scenario


def _calibrated(
    scenario: Scenario, calibration: CalibrationFile | str | os.PathLike[str]
) -> tuple[CalibrationFile, Scenario]:
    """The calibration (read when a path) and ``scenario`` with its ZMP margin."""
    if isinstance(calibration, CalibrationFile):
        read, name = calibration, "calibration"
    else:
        name = os.fspath(calibration)
        read = read_calibration(calibration, "calibration")
    return read, apply_calibration(scenario, read, name, "calibration")


def _fixed_in_frame(contact: dict[str, Any], spec: ContactSpec) -> dict[str, Any]:
    """A scenario's contact (its mapping) with its orientation as the governor holds it.

    A contact given by its world normal is resolved once, at the scenario's stance, into an
    offset fixed in its frame (:meth:`~impact_balance.scenario.Scenario.build_stance`); at
    another posture the normal form would be resolved anew. It is written as that offset's
    ``rpy``; a contact given in its frame is returned as it is.
    """
    if contact.get("normal") is None:
        return contact
    fixed = {k: v for k, v in contact.items() if k not in ("normal", "angle")}
    rpy = pin.rpy.matrixToRpy(spec.offset.rotation)
    fixed["offset"] = {
        "position": [float(x) for x in spec.offset.translation],
        "rpy": [float(x) for x in rpy],
    }
    return fixed


def _base_within_bounds(q: npt.NDArray[np.float64]) -> None:
    """Raise :class:`GovernorError` naming a base coordinate of ``q`` beyond ``MAX_POSITION``."""
    far = np.flatnonzero(np.abs(q[:3]) > MAX_POSITION)
    if far.size:
        raise GovernorError(
            f"q[{int(far[0])}]",
            float(q[far[0]]),
            f"the base position must be within {MAX_POSITION:g} m per coordinate",
        )


def _zero_answer(
    criterion: Criterion,
    floating: ContactVelocityLimit,
    com_velocity: npt.NDArray[np.float64],
    posture: Posture,
    reused: bool,
    ages: tuple[int, float],
) -> SpeedLimit:
    """The answer of stale rates with ``on_stale="zero"``: no approach speed is vouched for.

    The floating criterion's status is kept (it says whether the robot is already falling); the
    maximum is 0 and there is no safe interval, so the cap removes the approach component.
    """
    return SpeedLimit(
        criterion,
        0.0,
        floating.status,
        None,
        None,
        None,
        com_velocity,
        posture.impact.normal,
        posture.impact.point,
        reused,
        "contact_aware",
        ages[0],
        ages[1],
        True,
    )


def _zmp_interval(limit: ContactVelocityLimit) -> tuple[float, float] | None:
    """The ZMP criterion's safe speeds.

    From 0 to its maximum, or none when it is already violated (the CoM's vertical outside the
    ZMP area) or the area is empty.
    """
    return limit.interval_from_inside()


def _as_is(x: object, shape: tuple[int]) -> npt.NDArray[np.float64] | None:
    """``x`` when it is a contiguous float64 array of ``shape`` (numpy's own dtype), else None."""
    if type(x) is np.ndarray and x.dtype is _FLOAT and x.shape == shape and x.strides == _STRIDE:
        return x
    return None


def _velocity(v: ArrayLike, shape: tuple[int]) -> npt.NDArray[np.float64]:
    """``v`` as a contiguous float vector of ``shape`` (checked as :func:`_vector` checks it).

    A contiguous float64 array of that shape as it is: its finiteness is checked by the
    compiled call that reads it (:meth:`Governor._tick`).
    """
    velocity = _as_is(v, shape)
    return _vector(v, shape[0], "v") if velocity is None else velocity


def _refuse_velocity(
    code: int, v: npt.NDArray[np.float64], nv: int, com_velocity: npt.NDArray[np.float64]
) -> NoReturn:
    """Raise :class:`GovernorError` for :func:`velocity_exit`'s refusal ``code`` of ``v``."""
    if code == NOT_FINITE:
        _vector(v, nv, "v")  # raises, naming the entry
    raise GovernorError(
        "v",
        f"CoM velocity {math.hypot(*com_velocity):.3g} m/s",
        f"gives a CoM speed above {MAX_SPEED:g} m/s (the scenario's bound)",
    )


def _is_real(x: object) -> bool:
    """Whether ``x`` is an array of real numbers (integers or floats; no complex, no text)."""
    try:
        return np.asarray(x).dtype.kind in "iuf"
    except (TypeError, ValueError):
        return False


def _vector(x: ArrayLike, size: int, field: str) -> npt.NDArray[np.float64]:
    """``x`` as a contiguous float vector of ``size`` finite entries (a copy when converted).

    Real numbers only: a complex, boolean, text or object entry is refused (numpy would drop
    an imaginary part with a warning, or parse text).
    """
    return _squared_vector(x, size, field)[0]


def _squared_vector(x: ArrayLike, size: int, field: str) -> tuple[npt.NDArray[np.float64], float]:
    """:func:`_vector`'s answer and its squared norm (the one product its check takes)."""
    try:
        raw = np.asarray(x)
        if raw.dtype.kind not in "iuf":
            raise TypeError(raw.dtype)
        a = np.ascontiguousarray(raw, dtype=float)
    except (TypeError, ValueError):
        raise GovernorError(field, x, f"must be {size} real numbers") from None
    if a.shape != (size,):
        raise GovernorError(
            field, f"shape {a.shape}", f"must have {size} entries (the model's n{field})"
        )
    squared = float(np.vdot(a, a))  # one product per tick (vdot: no overflow warning)
    if not math.isfinite(squared):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise GovernorError(field, x, f"must be finite (entry {int(bad[0])})")
        k = int(np.argmax(np.abs(a)))
        raise GovernorError(
            f"{field}[{k}]", float(a[k]), "is finite but beyond any physical value (m, rad, m/s)"
        )
    return a, squared


class _JointBounds:
    """The joint part of a configuration check: limits plus :data:`JOINT_LIMIT_TOLERANCE`.

    The rule of a scenario's ``joints`` (:meth:`~impact_balance.robot.robot.Robot.joint_assignment`:
    a 1-dof joint with finite limits ``lower < upper`` lies within them), with a tolerance for a
    measured state; a continuous joint's (cos, sin) is a unit pair (within
    :data:`QUATERNION_TOLERANCE`).
    """

    def __init__(self, robot: Robot) -> None:
        names, idx, lower, upper, pairs = [], [], [], [], []
        for name in robot.joint_names:
            slot = robot.joint_slot(name)
            if slot.nq == 1:
                lo, hi = slot.lower, slot.upper
                if math.isfinite(lo) and math.isfinite(hi) and lo < hi:
                    names.append(name)
                    idx.append(slot.idx_q)
                    lower.append(lo - JOINT_LIMIT_TOLERANCE)
                    upper.append(hi + JOINT_LIMIT_TOLERANCE)
            elif slot.nq == 2 and slot.nv == 1:
                pairs.append((name, slot.idx_q))
        self.names = names
        self.idx = np.asarray(idx, dtype=np.int64)
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.pairs = pairs
        #: The continuous joints' first indices in q (their (cos, sin) pairs).
        self.pair_indices = np.asarray([i for _, i in pairs], dtype=np.int64)

    def check(self, q: npt.NDArray[np.float64]) -> None:
        """Raise :class:`GovernorError` naming the first joint of ``q`` out of bounds."""
        k = _first_outside(q, self.idx, self.lower, self.upper)
        if k >= 0:
            values = q[self.idx]
            lo = self.lower[k] + JOINT_LIMIT_TOLERANCE
            hi = self.upper[k] - JOINT_LIMIT_TOLERANCE
            raise GovernorError(
                f"q[{int(self.idx[k])}]",
                float(values[k]),
                f"joint {self.names[k]!r} is outside its limits [{lo:.4g}, {hi:.4g}] "
                f"(tolerance {JOINT_LIMIT_TOLERANCE:g})",
            )
        for name, i in self.pairs:
            norm = float(q[i] * q[i] + q[i + 1] * q[i + 1])
            if abs(norm - 1.0) > 2.0 * QUATERNION_TOLERANCE:
                raise GovernorError(
                    f"q[{i}:{i + 2}]",
                    [float(q[i]), float(q[i + 1])],
                    f"continuous joint {name!r}: (cos, sin) must be a unit pair",
                )


@njit(cache=True)
def _state_fault(
    q: npt.NDArray[np.float64],
    v: npt.NDArray[np.float64],
    idx: npt.NDArray[np.int64],
    lower: npt.NDArray[np.float64],
    upper: npt.NDArray[np.float64],
    pairs: npt.NDArray[np.int64],
    free_flyer: bool,
    max_position: float,
    quaternion_tolerance: float,
) -> int:
    """0 when ``q`` and ``v`` pass :meth:`Governor.limit`'s checks, else the first that fails.

    One compiled pass over them (a tick's checks): q finite, its base within ``max_position``
    (m) and its quaternion unit (free flyer), v finite, the joints within ``lower``/``upper``
    (:func:`_first_outside`), the continuous joints' (cos, sin) pairs at ``pairs`` unit. The
    checks that name the field and value then raise (:meth:`Governor._state`).
    """
    squared = 0.0
    for i in range(q.size):
        squared += q[i] * q[i]
    if not math.isfinite(squared):
        return 1
    if free_flyer:
        if squared > max_position * max_position:
            for i in range(3):
                if abs(q[i]) > max_position:
                    return 2
        x, y, z, w = q[3], q[4], q[5], q[6]
        if abs(x * x + y * y + z * z + w * w - 1.0) > 2.0 * quaternion_tolerance:
            return 3
    squared = 0.0
    for i in range(v.size):
        squared += v[i] * v[i]
    if not math.isfinite(squared):
        return 4
    if _first_outside(q, idx, lower, upper) >= 0:
        return 5
    for i in pairs:
        if abs(q[i] * q[i] + q[i + 1] * q[i + 1] - 1.0) > 2.0 * quaternion_tolerance:
            return 6
    return 0


@njit(cache=True)
def _rows_fault(
    qs: npt.NDArray[np.float64],
    idx: npt.NDArray[np.int64],
    lower: npt.NDArray[np.float64],
    upper: npt.NDArray[np.float64],
    pairs: npt.NDArray[np.int64],
    free_flyer: bool,
    max_position: float,
    quaternion_tolerance: float,
) -> int:
    """The first row of ``qs`` (N, nq) at which :func:`_state_fault` finds a fault, else -1.

    The configuration checks of :func:`_state_fault` (no velocity), row by row in one call.
    """
    no_velocity = np.zeros(0)
    for i in range(qs.shape[0]):
        if _state_fault(
            qs[i], no_velocity, idx, lower, upper, pairs, free_flyer, max_position,
            quaternion_tolerance,
        ):  # fmt: skip
            return i
    return -1


@njit(cache=True)
def _first_outside(
    q: npt.NDArray[np.float64],
    idx: npt.NDArray[np.int64],
    lower: npt.NDArray[np.float64],
    upper: npt.NDArray[np.float64],
) -> int:
    """The first k with ``q[idx[k]]`` below ``lower[k]`` or above ``upper[k]``, else -1.

    One compiled pass (a tick's joint check; numpy's took five array operations).
    """
    for k in range(idx.size):
        value = q[idx[k]]
        if value < lower[k] or value > upper[k]:
            return k
    return -1
