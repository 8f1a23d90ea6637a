"""What happened in a balance trial: ``balanced``, ``contact_broken``, ``fell`` or ``aborted``.

The criterion makes two promises, and a trial can break either, or both:

- *balance*: from a CoM velocity inside the CoM velocity area the robot comes back to rest
  without a step. Breaking it is a **fall** (``fell``), at the first of:

  - ``base_dropped``: the base sinks more than ``max_drop`` (10 cm) below its start: a robot
    that kept its balance lowers its base by a few centimetres at most;
  - ``trunk_tipped``: the base turns more than ``max_trunk_tilt`` (25 degrees) from its start
    orientation: no recovery without a step comes back from there;
  - ``dcm_escaped``: the DCM left the ZMP support area and was still outside at the end (the
    robot cannot be at rest with its DCM outside its support). The area is the scenario's, so
    the check stops (is *not applicable*) once the stance changed beyond the strict bounds
    below: the support in contact is then another one;
  - ``not_at_rest``: the CoM still moves faster than ``rest_speed`` (5 cm/s) at the end: 2.5 s
    after the disturbance (``settle_time``), or, for a robot still moving then, up to
    ``extra_time`` (2.5 s) later (a controller may bring the CoM back to its start slowly: that
    is a recovery, not a fall).

- *the contacts stay*: the paper assumes the impact does not break the sustained contacts.
  A contact **event** is recorded (each kind once per contact, with its time) when a contact

  - ``lifted``: had carried ``load_force`` (20 N, or half the contact's share of the weight
    when that is less: :meth:`OutcomeCriteria.for_robot`) and then carried less than ``min_force``
    (1 N) for more than ``lost_time`` (20 ms), counted from the end of the disturbance (an
    impulsive push may unload a foot while it acts; the criterion judges the state it leaves);
  - ``slipped``: its frame moved more than ``max_slip`` (1 cm) from its start;
  - ``tilted``: its frame turned more than ``max_tilt`` (5 degrees) from its start (a sole
    only: a point contact, ``size: [0, 0]``, cannot tilt; its frame turns with the leg).

  A trial with an event after the disturbance and no fall is ``contact_broken``: the robot
  came to rest without a step, but not on the contacts it started with.

**Strict outcome.** The criterion's premise is that the sustained contacts stay where they are.
A trial **fails strictly** (``strict_fail``) when it fell, or when after the disturbance a
contact broke beyond the strict bounds (:data:`STRICT_BOUNDS`, fields of :class:`OutcomeCriteria`):

- ``strict_max_tilt``: a contact frame turned more than 10 degrees from its start (a sole
  rolled over its edge);
- ``strict_max_slip``: a contact frame moved more than 3 cm from its start (a sole or a hand
  slid);
- ``strict_max_unloaded``: a contact that had carried ``load_force`` carried less than
  ``min_force`` for more than 0.1 s (a foot lifted, a hand contact lost).

A ``contact_broken`` trial within these bounds does not fail strictly; one beyond them does.

**Point contacts** (point feet, ``size: [0, 0]``) break by slipping or lifting only, with the
same bounds as a sole (lenient: 1 cm, 20 ms unloaded; strict: 3 cm, 0.1 s unloaded); their
tilt is neither an event nor a strict failure, and is left out of ``max_tilt``.

A trial is ``aborted`` when it went wrong before the disturbance (a fall or a contact event
before the impact or the push, or an impact point that never reached the surface): it tests
nothing and is left out of brackets and scores. Otherwise it is ``balanced``.

The monitor only sees arrays (world frame, SI units), so the same logic serves MuJoCo trials and
recorded logs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Literal

import numpy as np

__all__ = [
    "EVENT_KINDS",
    "FALL_REASONS",
    "OUTCOMES",
    "STRICT_BOUNDS",
    "ContactEvent",
    "EventKind",
    "FallReason",
    "Outcome",
    "OutcomeCriteria",
    "OutcomeMonitor",
    "OutcomeName",
]

#: A trial's outcome.
OutcomeName = Literal["balanced", "contact_broken", "fell", "aborted"]
#: Why a trial ``fell``.
FallReason = Literal["base_dropped", "trunk_tipped", "dcm_escaped", "not_at_rest"]
#: How a sustained contact broke.
EventKind = Literal["lifted", "slipped", "tilted"]

#: Trial outcomes.
OUTCOMES: tuple[OutcomeName, ...] = ("balanced", "contact_broken", "fell", "aborted")
#: Reasons of ``fell``.
FALL_REASONS: tuple[FallReason, ...] = (
    "base_dropped",
    "trunk_tipped",
    "dcm_escaped",
    "not_at_rest",
)
#: Kinds of contact events.
EVENT_KINDS: tuple[EventKind, ...] = ("lifted", "slipped", "tilted")
#: The strict bounds on the sustained contacts: a sole rolled over 10 degrees (rad), a contact slid
#: over 3 cm (m), a contact unloaded for over 0.1 s (s). The defaults of :class:`OutcomeCriteria`.
STRICT_BOUNDS: dict[str, float] = {
    "strict_max_tilt": float(np.deg2rad(10.0)),
    "strict_max_slip": 0.03,
    "strict_max_unloaded": 0.1,
}


@dataclass(frozen=True)
class OutcomeCriteria:
    """Thresholds of :class:`OutcomeMonitor` (SI units, angles in radians).

    See the module docstring.
    """

    min_force: float = 1.0
    load_force: float = 20.0
    lost_time: float = 0.02
    max_tilt: float = float(np.deg2rad(5.0))
    max_slip: float = 0.01
    max_drop: float = 0.10
    max_trunk_tilt: float = float(np.deg2rad(25.0))
    settle_time: float = 2.5
    rest_speed: float = 0.05
    extra_time: float = 2.5
    strict_max_tilt: float = STRICT_BOUNDS["strict_max_tilt"]
    strict_max_slip: float = STRICT_BOUNDS["strict_max_slip"]
    strict_max_unloaded: float = STRICT_BOUNDS["strict_max_unloaded"]

    def to_dict(self) -> dict[str, Any]:
        """The thresholds by name (JSON-ready)."""
        return asdict(self)

    def for_robot(self, weight: float, contacts: int) -> OutcomeCriteria:
        """These thresholds for a robot of ``weight`` (N) on ``contacts`` sustained contacts.

        ``load_force`` is at most half a contact's share of the weight, so that a light robot's
        contact counts as loaded (a 2.5 kg Solo 12 on three feet puts 8 N on each, never 20);
        a humanoid's thresholds are unchanged (Talos: 221 N per sole at half its share).
        """
        if contacts < 1 or not weight > 0:
            return self
        share = 0.5 * float(weight) / contacts
        return self if share >= self.load_force else replace(self, load_force=share)


@dataclass(frozen=True)
class ContactEvent:
    """A sustained contact broke.

    A sustained contact broke: ``contact`` (its frame), ``kind`` (lifted, slipped, tilted), ``time``
    (s) and ``value`` (the slip in m, the tilt in rad, the unloaded time in s).
    """

    contact: str
    kind: EventKind
    time: float
    value: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"contact": self.contact, "kind": self.kind, "time": self.time, "value": self.value}


@dataclass(frozen=True)
class Outcome:
    """A trial's outcome: one of :data:`OUTCOMES`, why, when and every contact event.

    ``reason`` is a fall reason, the first contact event, or why it was aborted (None when
    balanced); ``time`` is when (s); ``detail`` a line. ``stance_changed``: when the contacts
    first went beyond the strict bounds after the disturbance, and how (``(time, "contact kind")``,
    None if never); ``max_unloaded``: the longest time a loaded contact carried (almost) nothing
    after the disturbance (s).
    """

    outcome: OutcomeName
    reason: str | None
    time: float | None
    detail: str = ""
    events: tuple[ContactEvent, ...] = ()
    stance_changed: tuple[float, str] | None = None
    max_unloaded: float = 0.0

    @property
    def fell(self) -> bool:
        """Whether the outcome is ``fell``."""
        return self.outcome == "fell"

    @property
    def strict_fail(self) -> bool:
        """Fell, or broke a contact beyond the strict bounds (False when aborted)."""
        return self.outcome != "aborted" and (self.fell or self.stance_changed is not None)

    @property
    def strict_reason(self) -> str | None:
        """Why the trial failed strictly: the fall's reason, else the contact beyond the bounds."""
        if not self.strict_fail:
            return None
        if self.fell:
            return self.reason
        assert self.stance_changed is not None
        return self.stance_changed[1]


@dataclass
class OutcomeMonitor:
    """Watches the contacts, the base and the DCM during a trial; see the module docstring.

    Args:
        names: Contact names (frames), for the events.
        positions: Start positions of the contact frames (k x 3, m, world).
        rotations: Start rotations of the contact frames (k x 3 x 3, world).
        base_height: Start height of the base (m).
        base_rotation: Start rotation of the base (3 x 3, world).
        criteria: Thresholds.
        points: Which contacts are points (no tilt rule), in ``names`` order; empty: none.
    """

    names: Sequence[str]
    positions: np.ndarray
    rotations: np.ndarray
    base_height: float
    base_rotation: np.ndarray
    criteria: OutcomeCriteria = field(default_factory=OutcomeCriteria)
    points: Sequence[bool] = ()
    disturbance: float | None = field(default=None, init=False)
    max_tilt: float = field(default=0.0, init=False)
    max_slip: float = field(default=0.0, init=False)
    max_trunk_tilt: float = field(default=0.0, init=False)
    max_drop: float = field(default=0.0, init=False)
    max_unloaded: float = field(default=0.0, init=False)
    stance_changed: tuple[float, str] | None = field(default=None, init=False)
    events: list[ContactEvent] = field(default_factory=list, init=False)
    _fall: tuple[str, float, str] | None = field(default=None, init=False)
    _dcm_out_since: float | None = field(default=None, init=False)
    _abort: tuple[str, float, str] | None = field(default=None, init=False)
    _low_since: np.ndarray = field(init=False)
    _loaded: np.ndarray = field(init=False)
    _seen: set[tuple[int, EventKind]] = field(default_factory=set, init=False)
    _tilts: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=float).reshape(-1, 3)
        self.rotations = np.asarray(self.rotations, dtype=float).reshape(-1, 3, 3)
        self.base_rotation = np.asarray(self.base_rotation, dtype=float).reshape(3, 3)
        self._low_since = np.full(len(self.names), np.nan)
        self._loaded = np.zeros(len(self.names), dtype=bool)
        if len(self.points) not in (0, len(self.names)):
            raise ValueError(
                f"points has {len(self.points)} entries for {len(self.names)} contacts"
            )
        self._tilts = np.ones(len(self.names), dtype=bool)
        if len(self.points):
            self._tilts = ~np.asarray(self.points, dtype=bool)

    # -- during the trial ---------------------------------------------------------------
    @property
    def fell(self) -> bool:
        """A fall was seen (base or trunk): the trial can stop."""
        return self._fall is not None

    def start_disturbance(self, t: float) -> None:
        """The disturbance (first contact of the impact, start of the push) begins at ``t`` (s).

        A fall or a contact event before it aborts the trial.
        """
        if self.disturbance is not None:
            return
        self.disturbance = float(t)
        if self._fall is not None:
            self._abort = (
                "before_disturbance",
                self._fall[1],
                f"{self._fall[2]} before the disturbance",
            )
        elif self.events:
            e = self.events[0]
            self._abort = (
                "before_disturbance",
                e.time,
                f"{e.contact} {e.kind} before the disturbance",
            )

    def abort(self, reason: str, t: float, detail: str) -> None:
        """Mark the trial aborted (e.g. the impact point never reached the surface)."""
        if self._abort is None:
            self._abort = (reason, float(t), detail)

    def _event(self, i: int, kind: EventKind, t: float, value: float) -> None:
        if (i, kind) not in self._seen:
            self._seen.add((i, kind))
            self.events.append(ContactEvent(self.names[i], kind, float(t), float(value)))

    def update(
        self,
        t: float,
        positions: np.ndarray,
        rotations: np.ndarray,
        normal_forces: np.ndarray | None,
        base_height: float,
        base_rotation: np.ndarray,
        dcm_margin: float | None = None,
        impulsive: bool = False,
    ) -> bool:
        """One sample of the trial.

        One sample: contact frame poses, their normal forces (N, None if unknown), the base height
        (m) and rotation, the DCM's margin in the ZMP support area (m, >= 0 inside; None if
        unknown); ``impulsive``: a push acts now (unloading does not count). Returns :attr:`fell`.
        """
        c = self.criteria
        positions = np.asarray(positions, dtype=float).reshape(-1, 3)
        rotations = np.asarray(rotations, dtype=float).reshape(-1, 3, 3)
        for i in range(len(self.names)):
            slip = float(np.linalg.norm(positions[i] - self.positions[i]))
            tilt = _angle(self.rotations[i], rotations[i]) if self._tilts[i] else 0.0
            self.max_slip = max(self.max_slip, slip)
            self.max_tilt = max(self.max_tilt, tilt)
            if tilt > c.max_tilt:
                self._event(i, "tilted", t, tilt)
            if slip > c.max_slip:
                self._event(i, "slipped", t, slip)
            if normal_forces is not None:
                self._loaded[i] |= normal_forces[i] >= c.load_force
                if impulsive or not self._loaded[i] or normal_forces[i] >= c.min_force:
                    self._low_since[i] = np.nan
                elif np.isnan(self._low_since[i]):
                    self._low_since[i] = t
                elif t - self._low_since[i] > c.lost_time:
                    self._event(i, "lifted", self._low_since[i], t - self._low_since[i])
            self._strict(i, t, tilt, slip)
        drop = self.base_height - float(base_height)
        trunk = _angle(self.base_rotation, np.asarray(base_rotation, dtype=float).reshape(3, 3))
        self.max_drop = max(self.max_drop, drop)
        self.max_trunk_tilt = max(self.max_trunk_tilt, trunk)
        if self._fall is None:
            if drop > c.max_drop:
                self._fall = ("base_dropped", float(t), f"base {100 * drop:.0f} cm below its start")
            elif trunk > c.max_trunk_tilt:
                self._fall = ("trunk_tipped", float(t), f"trunk turned {np.rad2deg(trunk):.0f} deg")
        if self.stance_changed is not None:  # another support: the scenario's area does not apply
            self._dcm_out_since = None
        elif dcm_margin is not None and np.isfinite(dcm_margin):
            if dcm_margin < 0.0:
                if self._dcm_out_since is None:
                    self._dcm_out_since = float(t)
            else:
                self._dcm_out_since = None
        return self.fell

    def _strict(self, i: int, t: float, tilt: float, slip: float) -> None:
        """After the disturbance: the longest unloading, the contacts beyond the strict bounds."""
        if self.disturbance is None or t < self.disturbance:
            return
        c = self.criteria
        unloaded = 0.0 if np.isnan(self._low_since[i]) else t - float(self._low_since[i])
        self.max_unloaded = max(self.max_unloaded, unloaded)
        if self.stance_changed is not None:
            return
        name = self.names[i]
        if tilt > c.strict_max_tilt:
            self.stance_changed = (float(t), f"{name} tilted {np.rad2deg(tilt):.1f} deg")
        elif slip > c.strict_max_slip:
            self.stance_changed = (float(t), f"{name} slipped {100 * slip:.1f} cm")
        elif unloaded > c.strict_max_unloaded:
            self.stance_changed = (float(t), f"{name} lifted {unloaded:.2f} s")

    # -- at the end ---------------------------------------------------------------------
    def finish(self, t: float, com_velocity: np.ndarray) -> Outcome:
        """The outcome at the end of the trial (time ``t``, CoM velocity in m/s, world)."""
        outcome = self._verdict(t, com_velocity)
        return replace(outcome, stance_changed=self.stance_changed, max_unloaded=self.max_unloaded)

    def _verdict(self, t: float, com_velocity: np.ndarray) -> Outcome:
        """The lenient outcome (see :meth:`finish`)."""
        events = tuple(self.events)
        if self._abort is not None:
            reason, when, detail = self._abort
            return Outcome("aborted", reason, when, detail, events)
        if self.disturbance is None:
            return Outcome(
                "aborted", "no_disturbance", float(t), "the disturbance never began", events
            )
        if self._fall is not None:
            reason, when, detail = self._fall
            return Outcome("fell", reason, when, detail, events)
        if self._dcm_out_since is not None:
            return Outcome(
                "fell",
                "dcm_escaped",
                self._dcm_out_since,
                "the DCM left the ZMP support area and did not come back",
                events,
            )
        speed = float(np.linalg.norm(np.asarray(com_velocity, dtype=float)))
        if speed > self.criteria.rest_speed:
            return Outcome(
                "fell", "not_at_rest", float(t), f"CoM speed {speed:.3f} m/s at the end", events
            )
        after = [e for e in events if e.time >= self.disturbance]
        if after:
            first = min(after, key=lambda e: e.time)
            return Outcome(
                "contact_broken",
                f"{first.kind}",
                first.time,
                f"{first.contact} {first.kind}",
                events,
            )
        return Outcome("balanced", None, None, "", events)


def _angle(r0: np.ndarray, r1: np.ndarray) -> float:
    """Rotation angle between two orientations (rad)."""
    cos = (np.trace(r0.T @ r1) - 1.0) / 2.0
    return float(np.arccos(np.clip(cos, -1.0, 1.0)))
