"""Calibrating the ZMP margin on training pushes: the smallest one that meets a false-safe target.

The training trials are ``push-test --json`` outputs of **one** robot and **one** controller,
with the same outcome thresholds and criterion settings. For each push the CoM criterion's
before-trial prediction is kept as its raw margin ``r`` in the CoM velocity area *without* ZMP
margin (m/s, ``predicted_com_velocity_margin``; older files: ``com_velocity_margin + omega
zmp_margin``). At a ZMP margin ``M`` (m) the push is called safe when ``r >= omega M``
(:meth:`~impact_balance.sim.studies.push.PushOutcome.safe`), ``omega`` (1/s) being its stance's.

Pooled over every file, the false-safe rate P(failed | predicted safe) at each margin of a grid
(:data:`~.scores.MARGIN_GRID`, 0 to 60 mm by 1 mm) is scored with :func:`~.scores.confusion`
against the **strict** outcome (``strict_fail``) or the lenient one (``fell``). The calibrated
margin is the smallest one of the grid whose rate is at most the target; the *upper* margin the
smallest one whose upper Wilson bound is at most a second target. A margin that calls no push
safe has no rate and never qualifies: when none does, the answer is None ("no margin reaches
the target"). Aborted trials are left out, as in the scores.
"""

from __future__ import annotations

import hashlib
import json
import math
import operator
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from impact_balance.exceptions import ScenarioError
from impact_balance.files import read_bounded
from impact_balance.sim.studies.scores import FALSE_SAFE_TARGET, MARGIN_GRID, confusion

__all__ = [
    "AXIS_SHARE",
    "KNOWN_KEYS",
    "MAX_TRAINING_BYTES",
    "REMOVAL_AXES",
    "UPPER_TARGET",
    "Calibration",
    "TrainingPush",
    "TrainingSet",
    "angular_momentum_removal",
    "calibrate",
    "read_training",
    "training_set",
]

#: Target of the false-safe rate's upper Wilson bound (the second answer).
UPPER_TARGET = 0.12
#: Largest training file read (bytes).
MAX_TRAINING_BYTES = 512 * 1024 * 1024
#: The top-level keys of ``push-test --json`` that are not criterion settings. Any other key
#: (a criterion option added later) is a setting of the trials' predictions, recorded verbatim
#: and required to agree between files.
KNOWN_KEYS = frozenset(
    {
        "scenario",
        "robot",
        "body",
        "zmp_margin",
        "controller_margin",
        "omega",
        "pushes",
        "start_com_velocity",
        "counts",
        "scores_scope",
        "scores",
        "band",
        "band_scores",
        "margin_study",
        "contact_breaks",
        "controller",
        "outcome_criteria",
        "journal",
        "reused_trials",
        "wall_time",
        "log",
        "calibration",
    }
)


@dataclass(frozen=True)
class TrainingPush:
    """One scored training push.

    Attributes:
        margin: The CoM criterion's predicted margin in the CoM velocity area without ZMP
            margin, m/s (>= 0 inside).
        omega: Its stance's LIPM ``omega``, 1/s.
        fell: The trial fell (lenient failure).
        strict_fail: The trial failed strictly.
        angular_momentum_at_end: The centroidal angular momentum the push left (N m s, world),
            None when the file does not have it.
        angular_momentum_removed: Its divergence-weighted decrements after the push (N m s,
            world; :mod:`impact_balance.sim.trials.angular_momentum_removal`), None likewise.
    """

    margin: float
    omega: float
    fell: bool
    strict_fail: bool
    angular_momentum_at_end: tuple[float, float, float] | None = None
    angular_momentum_removed: tuple[float, float, float] | None = None

    def safe(self, zmp_margin: float) -> bool:
        """Whether the CoM criterion calls the push safe at ZMP margin ``zmp_margin`` (m)."""
        return self.margin >= self.omega * zmp_margin


@dataclass(frozen=True)
class TrainingSet:
    """One training file's pushes and what they were run with.

    Attributes:
        file: The path as given.
        sha256: SHA-256 (hex) of its bytes (None when built from a mapping).
        scenario: The scenario's name.
        robot: The robot's model name.
        body: The pushed body.
        controller: The trials' controller (``push-test``'s ``controller``).
        outcome_criteria: The outcome thresholds.
        criterion: The criterion settings (``start_com_velocity`` and unknown keys, verbatim).
        pushes: The scored pushes.
        controller_margin: The ZMP margin the trials' controller keeps (m), None when the file
            does not say.
    """

    file: str
    sha256: str | None
    scenario: str | None
    robot: str
    body: str | None
    controller: dict[str, Any]
    outcome_criteria: dict[str, Any]
    criterion: dict[str, Any]
    pushes: list[TrainingPush] = field(default_factory=list)
    controller_margin: float | None = None


def _bad(file: str, key: str, reason: str, value: Any = None) -> ScenarioError:
    return ScenarioError(key, value, reason, file)


def _push(p: Any, i: int, omega: float, zmp_margin: float, file: str) -> TrainingPush | None:
    """A push of the JSON, None when its trial was aborted."""
    where = f"pushes[{i}]"
    if not isinstance(p, Mapping):
        raise _bad(file, where, "not a push (a mapping)")
    if p.get("outcome") == "aborted":
        return None
    raw = p.get("predicted_com_velocity_margin")
    if raw is None:
        scored = p.get("com_velocity_margin")
        if not isinstance(scored, (int, float)) or isinstance(scored, bool):
            raise _bad(file, f"{where}.com_velocity_margin", "missing or not a number", scored)
        raw = float(scored) + omega * zmp_margin
    if not isinstance(raw, (int, float)) or isinstance(raw, bool) or not math.isfinite(raw):
        raise _bad(file, f"{where}.predicted_com_velocity_margin", "not a finite number", raw)
    fell, strict = p.get("fell"), p.get("strict_fail")
    if not isinstance(fell, bool) or not isinstance(strict, bool):
        raise _bad(file, f"{where}.fell", "fell and strict_fail must be true or false", fell)
    found = p.get("trial")
    trial: Mapping[str, Any] = found if isinstance(found, Mapping) else {}
    return TrainingPush(
        float(raw),
        omega,
        fell,
        strict,
        _vector3(trial.get("angular_momentum_at_end")),
        _vector3(trial.get("angular_momentum_removed")),
    )


def _vector3(value: Any) -> tuple[float, float, float] | None:
    """``value`` as three finite floats, None when it is not (absent from older files)."""
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        return None
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value):
        return None
    x, y, z = (float(v) for v in value)
    if not all(math.isfinite(v) for v in (x, y, z)):
        return None
    return x, y, z


def _number(data: Mapping[str, Any], key: str, file: str) -> float:
    value = data.get(key)
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise _bad(file, key, "missing or not a finite number", value)
    return float(value)


def training_set(data: Any, file: str, sha256: str | None = None) -> TrainingSet:
    """The training pushes of one ``push-test --json`` document.

    Args:
        data: The parsed JSON.
        file: Its name, in errors.
        sha256: SHA-256 of the file's bytes.

    Returns:
        Its :class:`TrainingSet`.

    Raises:
        ScenarioError: Not a push-test output, a push without its prediction or outcome, or no
            robot recorded (the field named, with the file).
    """
    if not isinstance(data, Mapping) or not isinstance(data.get("pushes"), list):
        raise _bad(file, "pushes", "not a push-test --json output (no list of pushes)")
    robot = data.get("robot")
    if not isinstance(robot, str) or not robot:
        raise _bad(file, "robot", "no robot recorded: run push-test again with this version", robot)
    if data.get("com_reach") is not None:
        raise _bad(
            file,
            "com_reach",
            "calibrate scans the ZMP margin without the reach check: calibrate from push-test "
            "runs without --com-reach",
            "set",
        )
    omega = _number(data, "omega", file)
    zmp_margin = _number(data, "zmp_margin", file)
    pushes = [_push(p, i, omega, zmp_margin, file) for i, p in enumerate(data["pushes"])]
    criterion = {"start_com_velocity": data.get("start_com_velocity")}
    criterion.update({k: v for k, v in data.items() if k not in KNOWN_KEYS})
    controller = data.get("controller")
    outcome_criteria = data.get("outcome_criteria")
    own = data.get("controller_margin")
    if own is not None:
        own = _number(data, "controller_margin", file)
        if own < 0:
            raise _bad(file, "controller_margin", "must be >= 0 m", own)
    return TrainingSet(
        file,
        sha256,
        data.get("scenario"),
        robot,
        data.get("body"),
        dict(controller) if isinstance(controller, Mapping) else {},
        dict(outcome_criteria) if isinstance(outcome_criteria, Mapping) else {},
        criterion,
        [p for p in pushes if p is not None],
        own,
    )


def read_training(path: str | os.PathLike[str]) -> TrainingSet:
    """Read one ``push-test --json`` output (the package's file-reading rule).

    Raises:
        ScenarioError: Unreadable, not strict JSON, or not a push-test output (naming the file).
    """
    shown = os.fspath(path)
    data = read_bounded(path, limit=MAX_TRAINING_BYTES, what="FILE")
    try:
        parsed = json.loads(data, parse_constant=_no_constant)
    except (ValueError, UnicodeDecodeError) as exc:
        raise ScenarioError("FILE", shown, f"not strict JSON: {exc}") from None
    return training_set(parsed, shown, hashlib.sha256(data).hexdigest())


def _no_constant(name: str) -> None:
    raise ValueError(f"{name} is not strict JSON")


def _same_controller(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    """One controller: equal descriptions, but for the gains when both derive them from the robot.

    Gains derived from the robot (``gains_from_robot``) follow its stance (CoM height, omega),
    so two stances of one robot give different numbers from the same rules.
    """
    if a.get("gains_from_robot") is True and b.get("gains_from_robot") is True:
        return {k: v for k, v in a.items() if k != "gains"} == {
            k: v for k, v in b.items() if k != "gains"
        }
    return a == b


def _check_same(sets: Sequence[TrainingSet]) -> None:
    """Refuse training files of several robots, controllers or settings, naming the files."""
    first = sets[0]
    for key in ("robot", "controller", "outcome_criteria", "criterion"):
        same = _same_controller if key == "controller" else operator.eq
        other = next((s for s in sets[1:] if not same(getattr(s, key), getattr(first, key))), None)
        if other is not None:
            what = f"{first.robot!r} and {other.robot!r}" if key == "robot" else "different values"
            raise ScenarioError(
                key,
                getattr(other, key),
                f"the training files {first.file} and {other.file} mix {key}s ({what}): "
                "calibrate one robot and one controller with one set of criterion settings "
                "at a time",
            )


@dataclass(frozen=True)
class Calibration:
    """The calibrated margin and the whole curve behind it.

    Attributes:
        sets: The training files.
        target: The false-safe rate aimed at.
        upper_target: The target of its upper Wilson bound.
        strict: Whether the strict outcome was scored (else the lenient one).
        grid: The margins searched, m.
        curve: Per margin of ``grid``, the pooled :func:`~.scores.confusion`.
        zmp_margin: The smallest margin at or above ``floor`` meeting ``target`` (m), None
            when none does.
        upper_margin: The smallest margin at or above ``floor`` whose upper bound meets
            ``upper_target``, or None.
        floor: The smallest margin searched (m): the controller's own margin by default.
        unfloored_margin: The smallest margin of the whole grid meeting ``target`` (m), None
            when none does: what the training stances alone would allow.
    """

    sets: list[TrainingSet]
    target: float
    upper_target: float
    strict: bool
    grid: tuple[float, ...]
    curve: list[dict[str, Any]]
    zmp_margin: float | None
    upper_margin: float | None
    floor: float = 0.0
    unfloored_margin: float | None = None

    @property
    def outcome(self) -> str:
        """``strict`` or ``lenient``."""
        return "strict" if self.strict else "lenient"

    def at(self, margin: float) -> dict[str, Any]:
        """The pooled confusion at ``margin`` (one of the grid)."""
        return self.curve[self.grid.index(margin)]

    def per_file(self, margin: float) -> list[dict[str, Any]]:
        """Each file's own scores at ``margin`` (m): where the pooled rate comes from."""
        rows = []
        for s in self.sets:
            k = _confusion(s.pushes, margin, self.strict)
            rows.append(
                {
                    "file": s.file,
                    "scenario": s.scenario,
                    "body": s.body,
                    "pushes": len(s.pushes),
                    "fell_given_safe": k["fell_given_safe"],
                    "safe_given_stood": k["safe_given_stood"],
                }
            )
        return rows

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``calibrate --json``."""
        first = self.sets[0]
        chosen = None if self.zmp_margin is None else self.at(self.zmp_margin)
        upper = None if self.upper_margin is None else self.at(self.upper_margin)
        return {
            "robot": first.robot,
            "controller": first.controller,
            "criterion": first.criterion,
            "outcome_criteria": first.outcome_criteria,
            "outcome": self.outcome,
            "target": self.target,
            "upper_target": self.upper_target,
            "zmp_margin": self.zmp_margin,
            "answer": _answer(self.zmp_margin, self.target),
            "margin_floor": self.floor,
            "unfloored_margin": self.unfloored_margin,
            "fell_given_safe": None if chosen is None else chosen["fell_given_safe"],
            "safe_given_stood": None if chosen is None else chosen["safe_given_stood"],
            "stood_given_unsafe": None if chosen is None else chosen["stood_given_unsafe"],
            "upper_margin": self.upper_margin,
            "upper_fell_given_safe": None if upper is None else upper["fell_given_safe"],
            "upper_safe_given_stood": None if upper is None else upper["safe_given_stood"],
            "files": [
                {"file": s.file, "sha256": s.sha256, "scenario": s.scenario, "body": s.body}
                for s in self.sets
            ],
            "per_file": None if self.zmp_margin is None else self.per_file(self.zmp_margin),
            "angular_momentum_removal": angular_momentum_removal(
                [p for s in self.sets for p in s.pushes], self.strict
            ),
            "pushes": sum(len(s.pushes) for s in self.sets),
            "curve": [
                {
                    "zmp_margin": m,
                    "fell_given_safe": k["fell_given_safe"],
                    "safe_given_stood": k["safe_given_stood"],
                    "stood_given_unsafe": k["stood_given_unsafe"],
                }
                for m, k in zip(self.grid, self.curve, strict=True)
            ],
        }


#: A push counts on an axis when that axis carries at least this share of the momentum it left.
AXIS_SHARE = 0.25
#: Axes of the angular momentum reported: roll (about world x) and pitch (about world y).
REMOVAL_AXES = ("x", "y")


def angular_momentum_removal(
    pushes: Sequence[TrainingPush], strict: bool = True
) -> dict[str, dict[str, Any]]:
    """The controller's realised removal of the angular momentum pushes left, per axis.

    Pooled over the pushes that did not fail (strictly, or by falling with ``strict`` False)
    and whose axis carries at least :data:`AXIS_SHARE` of the momentum left: the share
    ``rho = sum(sign(L0_i) removed_i) / sum(|L0_i|)`` of the immediate removal's capture cost,
    and ``tau = (1 / rho - 1) / omega`` (s, ``omega`` the pushes' ``|L0_i|``-weighted mean),
    the exponential removal's time constant that costs the same
    (:mod:`impact_balance.sim.trials.angular_momentum_removal`).

    Returns:
        Per axis (``x``: roll, ``y``: pitch) ``{pushes, share, damping_time}``; ``share`` and
        ``damping_time`` are None without pushes (files written before the measurement, or no
        push left momentum on that axis), ``damping_time`` None also when ``share <= 0``.
    """
    from impact_balance.sim.trials.angular_momentum_removal import equivalent_damping_time

    out: dict[str, dict[str, Any]] = {}
    for i, axis in enumerate(REMOVAL_AXES):
        left = removed = weighted_omega = 0.0
        count = 0
        for p in pushes:
            if (p.strict_fail if strict else p.fell) or p.angular_momentum_at_end is None:
                continue
            if p.angular_momentum_removed is None:
                continue
            at_end = p.angular_momentum_at_end
            if abs(at_end[i]) < AXIS_SHARE * math.hypot(*at_end) or at_end[i] == 0.0:
                continue
            sign = math.copysign(1.0, at_end[i])
            left += abs(at_end[i])
            removed += sign * p.angular_momentum_removed[i]
            weighted_omega += abs(at_end[i]) * p.omega
            count += 1
        share = removed / left if count else None
        tau = None
        if share is not None:
            tau = equivalent_damping_time(removed, left, weighted_omega / left)
        out[axis] = {"pushes": count, "share": share, "damping_time": tau}
    return out


def _answer(margin: float | None, target: float) -> str:
    if margin is None:
        return f"no margin reaches the target ({100 * target:g} %)"
    return f"{1000 * margin:g} mm"


def _confusion(pushes: Sequence[TrainingPush], margin: float, strict: bool) -> dict[str, Any]:
    safe = [p.safe(margin) for p in pushes]
    failed = [p.strict_fail if strict else p.fell for p in pushes]
    return confusion(safe, failed)


def _check_target(name: str, value: float) -> float:
    if isinstance(value, bool) or not (isinstance(value, (int, float)) and 0 < value < 1):
        raise ScenarioError(name, value, "must be a rate in (0, 1)")
    return float(value)


def calibrate(
    results: Sequence[TrainingSet | Mapping[str, Any] | str | os.PathLike[str]],
    target: float = FALSE_SAFE_TARGET,
    strict: bool = True,
    upper_target: float = UPPER_TARGET,
    grid: Sequence[float] = MARGIN_GRID,
    floor: float | str = "controller",
) -> Calibration:
    """The smallest ZMP margin that brings the pooled false-safe rate to ``target``.

    Args:
        results: Training trials: ``push-test --json`` files, their parsed documents or
            :class:`TrainingSet` s, of one robot and one controller.
        target: The false-safe rate P(failed | predicted safe) aimed at, in (0, 1).
        strict: Score the strict outcome (``strict_fail``); False: the lenient one (``fell``).
        upper_target: The target of the rate's upper Wilson bound, in (0, 1).
        grid: The margins searched (m), in increasing order.
        floor: The smallest margin the answers may take (m), or ``"controller"`` (the
            default): the controller's own ZMP margin recorded in the files
            (``controller_margin``; 0 when no file records it). 0: no floor.

    Returns:
        The :class:`Calibration` (its ``zmp_margin`` None when no margin reaches the target).

    Raises:
        ScenarioError: No training file, a bad file, mixed robots, controllers or settings
            (naming the files), a target outside (0, 1), a bad floor.
    """
    target = _check_target("--target", target)
    upper_target = _check_target("--upper-target", upper_target)
    if not results:
        raise ScenarioError("FILE", [], "give at least one training file")
    sets = [_as_set(r, i) for i, r in enumerate(results)]
    _check_same(sets)
    low = _floor(floor, sets)
    pushes = [p for s in sets for p in s.pushes]
    margins = tuple(sorted({float(m) for m in grid} | {low}))
    curve = [_confusion(pushes, m, strict) for m in margins]

    def meets(r: dict[str, Any]) -> bool:
        return r["rate"] is not None and r["rate"] <= target

    def upper_meets(r: dict[str, Any]) -> bool:
        return r["ci95"] is not None and r["ci95"][1] <= upper_target

    return Calibration(
        sets,
        target,
        upper_target,
        strict,
        margins,
        curve,
        _first(margins, curve, meets, low),
        _first(margins, curve, upper_meets, low),
        low,
        _first(margins, curve, meets, 0.0),
    )


def _floor(floor: float | str, sets: Sequence[TrainingSet]) -> float:
    """The floor in metres: ``floor``, or the files' controller margin for ``"controller"``."""
    if floor == "controller":
        own = [s.controller_margin for s in sets if s.controller_margin is not None]
        return max(own, default=0.0)
    if isinstance(floor, bool) or not isinstance(floor, (int, float)):
        raise ScenarioError("--floor", floor, "must be a margin in metres or 'controller'")
    if not (math.isfinite(floor) and 0.0 <= floor <= 1.0):
        raise ScenarioError("--floor", floor, "must be in [0, 1] m")
    return float(floor)


def _as_set(r: Any, i: int) -> TrainingSet:
    if isinstance(r, TrainingSet):
        return r
    if isinstance(r, Mapping):
        return training_set(r, f"results[{i}]")
    return read_training(r)


def _first(
    margins: Sequence[float], curve: Sequence[dict[str, Any]], ok: Any, low: float
) -> float | None:
    for m, k in zip(margins, curve, strict=True):
        if m >= low and ok(k["fell_given_safe"]):
            return m
    return None
