"""The paper's Experiment 1 in simulation: a governed approach to an unknown wall.

The impacting point is sent at a wall it does not know, its speed capped every control tick by an
impact-speed governor.

The robot stands on the scenario's contacts, its impacting point backed off ``standoff`` (15 cm)
along the surface normal ``n``; the balance controller of ``validate`` holds it (``ik`` or ``id``).
A wall, whose distance the controller is not told, stands ``wall_distance`` from the start point
along ``-n``. From ``start_time`` on, the point's reference speed rises towards ``reference`` with
a bounded acceleration (20 m/s^2), and every control tick (500 Hz) the governor
(:class:`~impact_balance.governor.Governor`, fed the simulated ``(q, v)``) gives the speed
allowed from the current posture and CoM velocity; the point is commanded at the smaller of
the two (``governor="none"``: the reference alone). When the measured normal force exceeds
15 N the reference stops pushing and withdraws 5 cm, as on HRP-4. The trial is then scored like
any balance trial (:mod:`.outcomes`), and reports the measured approach speed at contact, the
cap in force at contact, the time from the start of the approach to the contact, and the
governor's time per tick.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.exceptions import SimulationError
from impact_balance.governor import Criterion, Governor
from impact_balance.json_values import json_number
from impact_balance.sim.control.approach import approach_profile
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    run_balance_trial,
)
from impact_balance.sim.trials.impact_trial import TrialRecord
from impact_balance.sim.trials.result import BalanceTrialResult

__all__ = [
    "APPROACH_VERSION",
    "GOVERNORS",
    "MIN_WALL_DISTANCE",
    "GovernedApproach",
    "WallOptions",
    "WallTrial",
    "check_wall_distance",
    "pooled_tick_statistics",
    "run_wall_trial",
    "write_wall_video",
]

#: Version of the approach trial, for journals (with the balance trial's): 2 = the ``id``
#: controller bounds the point's speed by the cap (``WallOptions.cap_constraint``).
APPROACH_VERSION = 2

_FloatArray = npt.NDArray[np.float64]

#: Governors of the approach: the CoM criterion's, the ZMP criterion's, or none (the reference
#: alone).
GOVERNORS = ("com", "zmp", "none")

#: Closest wall, m from the point's start: a trial starts the point at least 2 cm from the
#: surface (:mod:`impact_balance.ranges`); a wall at the start point is touched before the
#: approach begins, and nothing is tested.
MIN_WALL_DISTANCE = 0.02


def check_wall_distance(
    distance: float, reference: float, acceleration: float = 20.0, field: str = "--wall-distance"
) -> float:
    """``distance`` (m) if the approach can reach its reference speed before the wall.

    The reference speed ramps up at ``acceleration`` (m/s^2) from rest, so it needs
    ``reference**2 / (2 * acceleration)`` m to reach ``reference`` (m/s); the wall must be at
    least that far, and at least :data:`MIN_WALL_DISTANCE`, from the point's start (and at most
    1 m).

    Raises:
        SimulationError: Otherwise, naming ``field`` and the least distance.
    """
    if not (np.isfinite(distance) and 0.0 < distance <= 1.0):
        raise SimulationError(field, distance, "must be in (0, 1] m")
    needed = max(MIN_WALL_DISTANCE, reference * reference / (2.0 * acceleration))
    if distance < needed:
        raise SimulationError(
            field,
            distance,
            f"the wall must be at least {needed:.3g} m from the point's start: the reference "
            f"reaches {reference:g} m/s after {reference * reference / (2.0 * acceleration):.3g} m "
            f"at {acceleration:g} m/s^2, and a trial needs {MIN_WALL_DISTANCE:g} m at least "
            "(move the wall or lower --reference)",
        )
    return float(distance)


@dataclass(frozen=True)
class WallOptions:
    """One approach to an unknown wall.

    Attributes:
        reference: The reference approach speed (m/s, along ``-n``).
        governor: "com", "zmp" or "none" (:data:`GOVERNORS`).
        wall_distance: Distance from the point's start to the wall, along ``-n`` (m).
        standoff: How far the start posture backs the point off the scenario's impact point (m).
        acceleration: Bound on the reference speed's rate (m/s^2).
        max_time: Longest approach before the trial gives up (s): a slow governor may not arrive.
        cap_constraint: With the ``id`` controller, bound the point's approach speed one control
            period ahead by the cap in its QP (a hard constraint; the paper's "track the maximum
            contact velocity with a whole-body QP"). False: the cap only lowers the reference's
            speed, and the controller's tracking lag may carry the point past a falling cap (up to
            5 %, docs/validation.md); kept for that comparison.
    """

    reference: float
    governor: str = "com"
    wall_distance: float = 0.15
    standoff: float = 0.15
    acceleration: float = 20.0
    max_time: float = 30.0
    cap_constraint: bool = True


@dataclass
class GovernedApproach:
    """The impacting point's reference when a governor caps its speed every tick.

    It duck-types :class:`~impact_balance.sim.control.approach.ImpactTask` for the balance
    controllers (an :class:`~impact_balance.sim.control.approach.ImpactReference`).

    ``speed_limit(t)`` is called by the trial loop before each control step with the governor's
    ceiling (m/s, ``inf`` without a governor); the reference's own speed follows a
    bounded-acceleration profile to ``speed``; the command is the smaller of the two.
    :meth:`speed_bound` gives a torque controller the cap as a bound on the point's speed
    (``bound_speed``; the ``id`` controller's QP enforces it).
    """

    frame: str
    offset: pin.SE3
    start: np.ndarray
    normal: np.ndarray
    speed: float
    start_time: float = 0.3
    acceleration: float = 20.0
    force_threshold: float = 15.0
    retract: float = 0.05
    withdraw_speed: float = 0.3
    bound_speed: bool = True
    contact_time: float | None = field(default=None, init=False)
    ceiling: float = field(default=np.inf, init=False)
    commanded: float = field(default=0.0, init=False)
    _point: np.ndarray | None = field(default=None, init=False)
    _last_t: float | None = field(default=None, init=False)
    _contact_point: np.ndarray | None = field(default=None, init=False)

    @property
    def start_point(self) -> np.ndarray:
        """The point's start (m, world)."""
        return self.start

    def reference_speed(self, t: float) -> float:
        """The reference's own speed at ``t`` (m/s): a bounded-acceleration ramp to ``speed``."""
        return approach_profile(t - self.start_time, self.speed, self.acceleration, np.inf)[1]

    def reference(
        self, t: float, normal_force: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World position, velocity and acceleration of the point's reference at ``t``.

        See the class docstring.
        """
        n = np.asarray(self.normal, dtype=float)
        if self._point is None:
            self._point = np.asarray(self.start, dtype=float).copy()
        if self.contact_time is None and normal_force > self.force_threshold:
            self.contact_time = float(t)
            self._contact_point = self._point.copy()
        if self.contact_time is not None and self._contact_point is not None:
            s, ds, dds = approach_profile(
                t - self.contact_time, self.withdraw_speed, self.acceleration, self.retract
            )
            return self._contact_point + s * n, ds * n, dds * n
        dt = 0.0 if self._last_t is None else max(0.0, t - self._last_t)
        self._last_t = float(t)
        previous = self.commanded
        self.commanded = min(self.reference_speed(t), max(0.0, self.ceiling))
        self._point = self._point - self.commanded * dt * n
        acceleration = 0.0 if dt <= 0.0 else (self.commanded - previous) / dt
        return self._point.copy(), -self.commanded * n, -acceleration * n

    def target(self, t: float, normal_force: float = 0.0) -> np.ndarray:
        """The reference position alone (m, world) at ``t``."""
        return self.reference(t, normal_force)[0]

    def speed_bound(self) -> float:
        """The largest approach speed (m/s, along ``-normal``) a controller should allow now.

        The governor's cap until the contact; ``inf`` after it, without a governor, or when
        ``bound_speed`` is off.
        """
        if not self.bound_speed or self.contact_time is not None:
            return np.inf
        return float(self.ceiling)


@dataclass
class WallTrial:
    """What one approach measured (SI units; see the module docstring).

    ``series`` (per control tick from the start of the approach to the end of the trial): ``time``
    (s), ``reference`` (the reference's own speed), ``cap`` (the governor's ceiling, None when
    unbounded or without a governor), ``commanded`` (the speed commanded), ``measured`` (the
    point's approach speed, ``-n . v``), all m/s. ``frames``: MuJoCo ``qpos``, CoM and impact force
    per tick, for the video (when asked). ``ticks``: the governor's time of every tick (s), for
    statistics pooled over several trials (:func:`pooled_tick_statistics`).
    """

    options: WallOptions
    result: BalanceTrialResult
    speed_at_contact: float | None
    cap_at_contact: float | None
    time_to_contact: float | None
    tick_us: dict[str, Any]
    series: dict[str, Any]
    wall: np.ndarray | None = None
    frames: dict[str, Any] | None = None
    ticks: list[float] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: one approach of ``approach --json``."""
        s = self.result.summary()
        o = self.options
        return {
            "governor": o.governor,
            "reference": o.reference,
            "wall_distance": o.wall_distance,
            "cap_constraint": o.cap_constraint,
            "speed_at_contact": self.speed_at_contact,
            "cap_at_contact": self.cap_at_contact,
            "time_to_contact": self.time_to_contact,
            "outcome": s["outcome"],
            "strict_fail": s["strict_fail"],
            "reason": s["reason"],
            "strict_reason": s["strict_reason"],
            "detail": s["detail"],
            "events": s["events"],
            "tick_us": self.tick_us,
            "ticks_us": [round(1e6 * t, 3) for t in self.ticks],  # for statistics over trials
            "trial": s,
        }


def run_wall_trial(
    setup: BalanceSetup,
    options: WallOptions,
    trial_options: BalanceTrialOptions | None = None,
    governor: Governor | None = None,
    frames: bool = False,
) -> WallTrial:
    """Run one approach (see the module docstring).

    Args:
        setup: The scenario prepared for balance trials.
        options: The approach's options.
        trial_options: The balance trial's options (default: the setup's controller's).
        governor: A :class:`~impact_balance.governor.Governor` of the setup's scenario and
            ``options.governor``'s criterion (built here when None and the options ask for one).
        frames: Keep what a video needs.

    Returns:
        What the approach measured.

    Raises:
        SimulationError: Options out of range (a wall closer than the approach needs:
            :func:`check_wall_distance`), or a scenario without an impact.
    """
    _check(options)
    analysis = setup.analysis
    if analysis.impact is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    trial_options = trial_options or BalanceTrialOptions(controller=setup.controller)
    if governor is None and options.governor != "none":
        criterion: Criterion = "zmp" if options.governor == "zmp" else "com"
        governor = Governor(setup.scenario, criterion=criterion)
    im = analysis.impact.model
    n = np.asarray(im.normal, dtype=float)
    start = im.point + options.standoff * n
    task = GovernedApproach(
        im.spec.frame,
        im.spec.offset,
        start,
        n,
        options.reference,
        start_time=trial_options.settle,
        acceleration=options.acceleration,
        bound_speed=options.cap_constraint,
    )
    wall = start - options.wall_distance * n
    recorder = _ApproachRecorder(setup.sim, task, governor, frames)
    result = run_balance_trial(
        setup,
        impact_task=task,
        surface_point=wall,
        standoff=options.standoff,
        options=trial_options,
        before_control=recorder,
        max_approach_time=options.max_time,
    )
    impact = result.impact
    cap_at_contact = None
    caps = recorder.caps
    if impact is not None and caps:
        k = max(0, int(np.searchsorted([c[0] for c in caps], impact.contact_time)) - 1)
        cap_at_contact = json_number(caps[k][2])
    return WallTrial(
        options,
        result,
        None if impact is None else json_number(impact.approach_speed),
        cap_at_contact,
        None if impact is None else float(impact.contact_time - task.start_time),
        _tick_statistics(recorder.ticks),
        recorder.rows,
        wall,
        {k: np.array(x) for k, x in recorder.kept.items()} if frames else None,
        list(recorder.ticks),
    )


def _check(options: WallOptions) -> None:
    """Refuse a governor, reference speed or wall distance out of range."""
    if options.governor not in GOVERNORS:
        raise SimulationError(
            "--governor", options.governor, f"must be one of {', '.join(GOVERNORS)}"
        )
    if not (np.isfinite(options.reference) and 0.0 < options.reference <= 5.0):
        raise SimulationError("--reference", options.reference, "must be in (0, 5] m/s")
    if not (np.isfinite(options.acceleration) and options.acceleration > 0.0):
        raise SimulationError("acceleration", options.acceleration, "must be > 0 m/s^2")
    check_wall_distance(options.wall_distance, options.reference, options.acceleration)


class _ApproachRecorder:
    """Before every control step: the governor's cap given to the task, and the series recorded."""

    def __init__(
        self, sim: SimModel, task: GovernedApproach, governor: Governor | None, frames: bool
    ):
        self.sim, self.task, self.governor, self.frames = sim, task, governor, frames
        self.n = np.asarray(task.normal, dtype=float)
        self.ticks: list[float] = []
        self.caps: list[tuple[float, float, float]] = []
        self.rows: dict[str, list[float | None]] = {
            "time": [],
            "reference": [],
            "cap": [],
            "commanded": [],
            "measured": [],
        }
        self.kept: dict[str, list[Any]] = {"time": [], "qpos": [], "com": [], "impact": []}

    def __call__(self, t: float, q: _FloatArray, v: _FloatArray) -> None:
        sim, task, governor, rows = self.sim, self.task, self.governor, self.rows
        if self.frames:
            assert sim.impact_geom is not None
            self.kept["time"].append(t)
            self.kept["qpos"].append(sim.data.qpos.copy())
            self.kept["com"].append(sim.com())
            self.kept["impact"].append(sim.contact_force(sim.impact_geom))
        if t < task.start_time:
            return
        if task.contact_time is None and governor is not None:
            t0 = time.perf_counter()
            limit = governor.limit(q, v)
            self.ticks.append(time.perf_counter() - t0)
            task.ceiling = limit.ceiling
        if task.contact_time is None:
            self.caps.append((t, task.reference_speed(t), task.ceiling))
        rows["time"].append(t)
        rows["reference"].append(task.reference_speed(t) if task.contact_time is None else 0.0)
        rows["cap"].append(
            json_number(task.ceiling)
            if governor is not None and task.contact_time is None
            else None
        )
        rows["commanded"].append(task.commanded if task.contact_time is None else 0.0)
        rows["measured"].append(float(-self.n @ sim.impact_point_velocity(self.n)))


def _tick_statistics(ticks: list[float]) -> dict[str, float | int | None]:
    """Median and 99th percentile (us) of the governor's ticks, and their count."""
    us = np.asarray(ticks) * 1e6
    if not us.size:
        return {"median": None, "p99": None, "count": 0}
    return {
        "median": float(np.median(us)),
        "p99": float(np.percentile(us, 99)),
        "count": int(us.size),
    }


def pooled_tick_statistics(
    trials: Iterable[WallTrial | Mapping[str, Any]],
) -> dict[str, float | int | None]:
    """Median and 99th percentile (us) of the governor's ticks of all ``trials`` pooled, and count.

    Each trial is a :class:`WallTrial` or its JSON (:meth:`WallTrial.to_dict`, its ``ticks_us``).
    A percentile of one trial's few ticks (70 to 140) is one of its largest ticks; pooled over the
    trials it is a percentile.
    """
    ticks: list[float] = []
    for trial in trials:
        if isinstance(trial, Mapping):
            ticks += [1e-6 * float(us) for us in trial["ticks_us"]]
        else:
            ticks += trial.ticks
    return _tick_statistics(ticks)


def write_wall_video(
    setup: BalanceSetup, trial: WallTrial, path: str | Path, title: str | None = None
) -> Path:
    """The approach as an MP4 (:func:`~.video.write_video`), the wall where it stood.

    Args:
        setup: The setup the trial ran on.
        trial: A trial run with ``frames=True``.
        path: The ``.mp4`` file.
        title: The video's title (default: the scenario's name).

    Returns:
        The path written.

    Raises:
        SimulationError: The trial kept no frames, or the video cannot be made here.
    """
    from impact_balance.sim.trials.video import write_video

    if not trial.frames or not len(trial.frames["time"]) or trial.wall is None:
        raise SimulationError("--video", str(path)[:80], "the trial kept no frames")
    sim, f = setup.sim, trial.frames
    k = len(f["time"])
    record = TrialRecord(
        time=f["time"],
        qpos=f["qpos"],
        qvel=np.zeros((k, sim.model.nv)),
        com=f["com"],
        com_velocity=np.zeros((k, 3)),
        forces={"impact": f["impact"]},
        impact_velocity=np.zeros((k, 3)),
        approach_start=float(f["time"][0]),
        wall_time=0.0,
    )
    impact = setup.analysis.impact
    if impact is None or sim.surface_geom is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    home = sim.model.geom_pos[sim.surface_geom].copy()
    sim.model.geom_pos[sim.surface_geom] = home + (trial.wall - impact.model.point)
    try:
        return write_video(sim, record, path, title=title)
    finally:
        sim.model.geom_pos[sim.surface_geom] = home
