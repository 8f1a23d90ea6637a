"""The paper's Experiment 1 in simulation: the impacting point sent at a wall it does not know,
its speed capped every control tick by an impact-speed governor.

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
from dataclasses import dataclass, field

import numpy as np

from impact_balance.exceptions import SimulationError
from impact_balance.json_values import json_number
from impact_balance.sim.control.approach import _profile
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    run_balance_trial,
)
from impact_balance.sim.trials.impact_trial import TrialRecord, _point_velocity
from impact_balance.sim.trials.result import BalanceTrialResult

__all__ = [
    "APPROACH_VERSION",
    "GOVERNORS",
    "GovernedApproach",
    "WallOptions",
    "WallTrial",
    "run_wall_trial",
    "write_wall_video",
]

#: Version of the approach trial, for journals (with the balance trial's): 2 = the ``id``
#: controller bounds the point's speed by the cap (``WallOptions.cap_constraint``).
APPROACH_VERSION = 2

#: Governors of the approach: the CoM criterion's, the ZMP criterion's, or none (the reference alone).
GOVERNORS = ("com", "zmp", "none")


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
    """The impacting point's reference when a governor caps its speed every tick (duck-types
    :class:`~.approach.ImpactTask` for the balance controllers: ``reference``, ``target``, ``start_point``).

    ``speed_limit(t)`` is called by the trial loop before each control step with the governor's
    ceiling (m/s, ``inf`` without a governor); the reference's own speed follows a
    bounded-acceleration profile to ``speed``; the command is the smaller of the two.
    :meth:`speed_bound` gives a torque controller the cap as a bound on the point's speed
    (``bound_speed``; the ``id`` controller's QP enforces it).
    """

    frame: str
    offset: object
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
        return self.start

    def reference_speed(self, t: float) -> float:
        """The reference's own speed at ``t`` (m/s): a bounded-acceleration ramp to ``speed``."""
        return _profile(t - self.start_time, self.speed, self.acceleration, np.inf)[1]

    def reference(
        self, t: float, normal_force: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World position, velocity and acceleration of the point's reference at ``t`` (see the class docstring)."""
        n = np.asarray(self.normal, dtype=float)
        if self._point is None:
            self._point = np.asarray(self.start, dtype=float).copy()
        if self.contact_time is None and normal_force > self.force_threshold:
            self.contact_time = float(t)
            self._contact_point = self._point.copy()
        if self.contact_time is not None:
            s, ds, dds = _profile(
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
        return self.reference(t, normal_force)[0]

    def speed_bound(self) -> float:
        """The largest approach speed (m/s, along ``-normal``) a controller should allow the point
        now: the governor's cap until the contact, ``inf`` after it, without a governor or when
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
    per tick, for the video (when asked).
    """

    options: WallOptions
    result: BalanceTrialResult
    speed_at_contact: float | None
    cap_at_contact: float | None
    time_to_contact: float | None
    tick_us: dict
    series: dict
    wall: np.ndarray | None = None
    frames: dict | None = None

    def to_dict(self) -> dict:
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
            "reason": s["reason"],
            "detail": s["detail"],
            "events": s["events"],
            "tick_us": self.tick_us,
            "trial": s,
        }


def run_wall_trial(
    setup: BalanceSetup,
    options: WallOptions,
    trial_options: BalanceTrialOptions | None = None,
    governor=None,
    frames: bool = False,
) -> WallTrial:
    """Run one approach (see the module docstring). ``governor``: a
    :class:`~impact_balance.governor.Governor` of the setup's scenario and ``options.governor``'s criterion
    (built here when None and the options ask for one); ``frames``: keep what a video needs.
    """
    if options.governor not in GOVERNORS:
        raise SimulationError(
            "--governor", options.governor, f"must be one of {', '.join(GOVERNORS)}"
        )
    if not (np.isfinite(options.reference) and 0.0 < options.reference <= 5.0):
        raise SimulationError("--reference", options.reference, "must be in (0, 5] m/s")
    if not (np.isfinite(options.wall_distance) and 0.0 < options.wall_distance <= 1.0):
        raise SimulationError("--wall-distance", options.wall_distance, "must be in (0, 1] m")
    analysis = setup.analysis
    if analysis.impact is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    trial_options = trial_options or BalanceTrialOptions(controller=setup.controller)
    if governor is None and options.governor != "none":
        from impact_balance.governor import Governor

        governor = Governor(setup.scenario, criterion=options.governor)
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
    ticks: list[float] = []
    caps: list[tuple[float, float, float]] = []
    rows: dict[str, list] = {
        "time": [],
        "reference": [],
        "cap": [],
        "commanded": [],
        "measured": [],
    }
    kept: dict[str, list] = {"time": [], "qpos": [], "com": [], "impact": []}
    sim = setup.sim

    def before_control(t: float, q: np.ndarray, v: np.ndarray) -> None:
        if frames:
            kept["time"].append(t)
            kept["qpos"].append(sim.data.qpos.copy())
            kept["com"].append(sim.com())
            kept["impact"].append(sim.contact_force(sim.impact_geom))
        if t < task.start_time:
            return
        if task.contact_time is None and governor is not None:
            t0 = time.perf_counter()
            limit = governor.limit(q, v)
            ticks.append(time.perf_counter() - t0)
            task.ceiling = limit.ceiling
        if task.contact_time is None:
            caps.append((t, task.reference_speed(t), task.ceiling))
        rows["time"].append(t)
        rows["reference"].append(task.reference_speed(t) if task.contact_time is None else 0.0)
        rows["cap"].append(
            json_number(task.ceiling)
            if governor is not None and task.contact_time is None
            else None
        )
        rows["commanded"].append(task.commanded if task.contact_time is None else 0.0)
        rows["measured"].append(float(-n @ _point_velocity(sim, n)))

    result = run_balance_trial(
        setup,
        impact_task=task,
        surface_point=wall,
        standoff=options.standoff,
        options=trial_options,
        before_control=before_control,
        max_approach_time=options.max_time,
    )
    impact = result.impact
    cap_at_contact = None
    if impact is not None and caps:
        k = max(0, int(np.searchsorted([c[0] for c in caps], impact.contact_time)) - 1)
        cap_at_contact = json_number(caps[k][2])
    us = np.asarray(ticks) * 1e6
    tick_us = (
        {"median": float(np.median(us)), "p99": float(np.percentile(us, 99)), "count": int(us.size)}
        if us.size
        else {"median": None, "p99": None, "count": 0}
    )
    return WallTrial(
        options,
        result,
        None if impact is None else json_number(impact.approach_speed),
        cap_at_contact,
        None if impact is None else float(impact.contact_time - task.start_time),
        tick_us,
        rows,
        wall,
        {k: np.array(x) for k, x in kept.items()} if frames else None,
    )


def write_wall_video(setup: BalanceSetup, trial: WallTrial, path, title: str | None = None):
    """The approach as an MP4 (:func:`~.video.write_video`), the wall where it stood (``frames=True`` trials)."""
    from impact_balance.sim.trials.video import write_video

    if not trial.frames or not len(trial.frames["time"]):
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
    home = sim.model.geom_pos[sim.surface_geom].copy()
    sim.model.geom_pos[sim.surface_geom] = home + (trial.wall - setup.analysis.impact.model.point)
    try:
        return write_video(sim, record, path, title=title)
    finally:
        sim.model.geom_pos[sim.surface_geom] = home
