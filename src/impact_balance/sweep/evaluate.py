"""Evaluate the points of a chunk: one row per point, never an exception for a bad point.

A worker builds one :class:`Evaluator` (the robot is loaded once) and evaluates chunks with
it. A stance's areas are :func:`~impact_balance.analyze`'s
(:func:`~impact_balance.analysis.analyze.stance_posture`: the compiled posture where it
answers, with the impact model and CoM criterion of the stance's first point; the steps where
it does not). Within a chunk, points that share a stance (same values of every stance
dimension) share its areas: only the impact model and the two criteria are recomputed (a point
with the first point's impact reuses its model and criterion). Each chunk starts from a
clean cache and the posture IK of each chunk starts from the base stance, so that a chunk's
rows depend on the plan alone, never on which worker ran it or what it ran before.

Each row says what was evaluated: the robot, the contact frames, the configuration ``q`` and a
short digest of the stance (rows with the same digest share their areas). A robot axis loads
each robot once per evaluator.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin
import pyarrow as pa

from impact_balance.analysis.analyze import impact_answer, stance_posture
from impact_balance.balance.areas import BalanceAreas
from impact_balance.contacts.stance import Stance
from impact_balance.criteria.com import ComCriterion
from impact_balance.exceptions import ImpactBalanceError, ScenarioError
from impact_balance.impact.model import ImpactModel, impact_model
from impact_balance.robot.ik import IKError, IKOptions, solve_stance
from impact_balance.robot.robot import Robot
from impact_balance.scenario import ImpactConfig, Scenario, scenario_from_dict
from impact_balance.sweep.columns import RESULT_COLUMNS, STATUSES, Status, Verdict
from impact_balance.sweep.paths import get_path, set_path
from impact_balance.sweep.plan import Dimension, SweepPlan
from impact_balance.sweep.spec import PostureAxis

__all__ = ["RESULT_COLUMNS", "STATUSES", "Evaluator", "result_schema"]


def result_schema(plan: SweepPlan) -> pa.Schema:
    """Arrow schema of the rows: ``point``, ``chunk``, one column per dimension, the results."""
    fields = [pa.field("point", pa.int64()), pa.field("chunk", pa.int32())]
    fields += [pa.field(d.name, pa.float64() if d.numeric else pa.string()) for d in plan.dims]
    fields += [pa.field(name, typ) for name, typ, _ in RESULT_COLUMNS]
    return pa.schema(fields, metadata={"impact_balance.sweep": plan.digest})


@dataclass(frozen=True)
class _CompiledImpact:
    """The impact model and CoM criterion the compiled posture made for one impact."""

    impact: ImpactConfig
    velocity_margin: float
    model: ImpactModel
    criterion: ComCriterion


@dataclass
class _ReadyStance:
    """A stance whose areas are computed, shared by the points of a chunk that have it.

    ``compiled``: the impact model and criterion of the stance's first point, where the
    compiled posture answered it (a point with the same impact and margin reuses them).
    """

    stance: Stance
    areas: BalanceAreas
    com_velocity_area: float
    zmp_area: float
    edge_directions: list[float]
    identity: dict[str, Any]
    verdicts: dict[tuple[float, float], Verdict]
    compiled: _CompiledImpact | None = None


@dataclass
class _StanceEntry:
    """The stance of a group of points: ``ready``, or why not (``status`` and ``message``)."""

    ready: _ReadyStance | None
    status: Status | None = None
    message: str | None = None
    ik_residual: float | None = None

    @property
    def stance(self) -> Stance | None:
        """The stance, None when it could not be computed."""
        return self.ready.stance if self.ready is not None else None


#: The stance entries of a chunk, by the values of the stance dimensions.
_Cache = dict[tuple[Any, ...], _StanceEntry]
#: The last configuration the posture IK reached, by the values of the other stance dimensions.
_Warm = dict[tuple[Any, ...], npt.NDArray[np.float64]]


def _verdict(areas: BalanceAreas, com_velocity: tuple[float, float]) -> Verdict:
    if not areas.can_balance:
        return "cannot balance"
    return (
        "balanced"
        if areas.com_velocity_area.contains(np.asarray(com_velocity, dtype=float), 1e-10)
        else "falling"
    )


class Evaluator:
    """Evaluates chunks of a plan; holds the robot and the base scenario (built once).

    Thread-safe: :meth:`evaluate_chunk` keeps its caches local (the robot's scratch data are
    per thread), so one evaluator may serve the threads of a Dask worker.
    """

    def __init__(self, plan: SweepPlan, robot: Robot | None = None) -> None:
        self.plan = plan
        self.base_scenario = scenario_from_dict(plan.base, plan.base_source)
        self.robot = robot or self.base_scenario.load_robot()
        self._robots = {_robot_key(self.base_scenario): self.robot}
        self.schema = result_schema(plan)
        self._path_dims = [d for d in plan.dims if d.kind == "path"]
        # Unchanged top-level keys go to the validation as the base's validated models (pydantic
        # does not revalidate model instances); only the changed ones are validated per point.
        self._base_fields = {
            name: getattr(self.base_scenario, name)
            for name in Scenario.model_fields
            if name != "source"
        }
        # the first token of a path is a top-level key: a string
        self._roots = sorted({str(d.tokens[0]) for d in plan.dims if d.tokens})
        self._direction: dict[int, dict[str, Dimension]] = {}
        for d in plan.dims:
            if d.kind in ("azimuth", "elevation"):
                self._direction.setdefault(d.axis, {})[d.kind] = d
        self._stance_dims = [d.name for d in plan.dims if d.stance]
        self._posture_dims = [d for d in plan.dims if d.kind == "posture"]
        posture = plan.posture
        self._posture = posture
        if posture is not None:
            impact = self.base_scenario.impact
            if impact is None:  # the plan refuses a base scenario without impact
                raise ValueError("the base scenario has no impact")
            self._posture_frame = posture.frame or impact.frame
            if posture.offset is not None:
                self._posture_offset = posture.offset.se3()
            elif self._posture_frame == impact.frame:
                self._posture_offset = impact.offset.se3()
            else:
                self._posture_offset = pin.SE3.Identity()

    def warm_up(self, points: int = 20) -> None:
        """Evaluate the first few points of the sweep and drop the rows.

        This loads the compiled kernel and every lazy import and cache, so that a worker's
        first chunk is not slower than the others.

        Args:
            points: How many points to evaluate.
        """
        start, stop = self.plan.chunk_range(0)
        self._rows(0, start, min(stop, start + points))

    # -- one chunk --------------------------------------------------------------------------
    def evaluate_chunk(self, chunk: int) -> pa.Table:
        """The rows of chunk ``chunk`` (a table with :func:`result_schema`)."""
        start, stop = self.plan.chunk_range(chunk)
        return self._rows(chunk, start, stop)

    def _rows(self, chunk: int, start: int, stop: int) -> pa.Table:
        points = self.plan.points(start, stop)
        names = [d.name for d in self.plan.dims]
        columns: dict[str, list[Any]] = {f.name: [] for f in self.schema}
        cache: _Cache = {}
        warm: _Warm = {}
        for k in range(stop - start):
            values = {name: points[name][k] for name in names}
            try:
                row = self._evaluate_point(values, cache, warm)
            except Exception as exc:
                row = {"status": "error", "message": f"{exc.__class__.__name__}: {exc}"}
            columns["point"].append(start + k)
            columns["chunk"].append(chunk)
            for d in self.plan.dims:
                v = values[d.name]
                columns[d.name].append(
                    float(v) if d.numeric else (v if isinstance(v, str) else repr(v))
                )
            for name, _, _ in RESULT_COLUMNS:
                columns[name].append(row.get(name))
        return pa.table(columns, schema=self.schema)

    # -- one point --------------------------------------------------------------------------
    def _scenario(self, values: dict[str, Any]) -> Scenario:
        raw = dict(self._base_fields)
        for root in self._roots:
            raw[root] = self.plan.base[root]
        for d in self._path_dims:
            raw = set_path(raw, d.tokens, values[d.name])
        for pair in self._direction.values():
            az_dim, el_dim = pair["azimuth"], pair["elevation"]
            base_vec = np.asarray(get_path(self.plan.base, az_dim.tokens), dtype=float)
            az, el = (
                math.radians(float(values[az_dim.name])),
                math.radians(float(values[el_dim.name])),
            )
            length = float(np.linalg.norm(base_vec))
            vec = [
                length * math.cos(el) * math.cos(az),
                length * math.cos(el) * math.sin(az),
                length * math.sin(el),
            ]
            raw = set_path(raw, az_dim.tokens, vec)
        # The base and the sweep file passed the size checks when the sweep was planned.
        return scenario_from_dict(raw, None, check_size=False)

    def _evaluate_point(self, values: dict[str, Any], cache: _Cache, warm: _Warm) -> dict[str, Any]:
        try:
            scenario = self._scenario(values)
        except ScenarioError as exc:
            return {"status": "invalid", "message": str(exc)}
        key = tuple(_key(values[name]) for name in self._stance_dims)
        entry = cache.get(key)
        if entry is None:
            entry = cache[key] = self._stance_entry(scenario, values, warm)
        ready = entry.ready
        out: dict[str, Any] = {"ik_residual": entry.ik_residual}
        if ready is None:
            return {**out, "status": entry.status, "message": entry.message}
        out.update(ready.identity)
        stance, areas = ready.stance, ready.areas
        cfg = scenario.impact
        if cfg is None:  # an error row (the plan refuses a base scenario without impact)
            raise ValueError("the scenario has no impact")
        compiled = ready.compiled
        if (
            compiled is not None
            and compiled.velocity_margin == scenario.velocity_margin
            and compiled.impact == cfg
        ):
            model, criterion = compiled.model, compiled.criterion
        else:
            try:
                model = impact_model(stance, cfg.spec())
            except ImpactBalanceError as exc:
                return {**out, "status": "invalid", "message": str(exc)}
            criterion = None
        answer = impact_answer(scenario, stance, areas, model, criterion)
        com, zmp = answer.com, answer.zmp
        verdict = ready.verdicts.get(scenario.com_velocity)
        if verdict is None:
            verdict = ready.verdicts[scenario.com_velocity] = _verdict(areas, scenario.com_velocity)
        out.update(
            status=com.status,
            verdict=verdict,
            max_contact_velocity=com.max_contact_velocity,
            zmp_max_contact_velocity=zmp.max_contact_velocity,
            zmp_status=zmp.status,
            com_velocity_area=ready.com_velocity_area,
            zmp_area=ready.zmp_area,
            limiting_vertex=com.limiting_vertex,
            limiting_edge=com.limiting_edge,
            limiting_direction=None
            if com.limiting_edge is None
            else ready.edge_directions[com.limiting_edge],
            impact_x=float(model.point[0]),
            impact_y=float(model.point[1]),
            impact_z=float(model.point[2]),
        )
        return out

    def _robot(self, scenario: Scenario) -> Robot:
        """The scenario's robot, loaded once per evaluator (a robot axis varies it)."""
        key = _robot_key(scenario)
        robot = self._robots.get(key)
        if robot is None:
            # Robot files are relative to the base scenario's file, as in the plan's check.
            robot = scenario.model_copy(update={"source": self.plan.base_source}).load_robot()
            self._robots[key] = robot
        return robot

    def _stance_entry(
        self, scenario: Scenario, values: dict[str, Any], warm: _Warm
    ) -> _StanceEntry:
        """The stance of a point and its areas, or why they cannot be computed."""
        residual = None
        try:
            stance = scenario.build_stance(self._robot(scenario))
            if self._posture is not None:
                stance, residual = self._place(self._posture, stance, values, warm)
            areas, model, criterion = stance_posture(scenario, stance)
        except IKError as exc:
            return _StanceEntry(None, "unreachable", str(exc), _worst(exc.residuals))
        except ScenarioError as exc:
            return _StanceEntry(None, "invalid", str(exc), residual)
        except ImpactBalanceError as exc:
            return _StanceEntry(None, "error", f"{exc.__class__.__name__}: {exc}", residual)
        ready = _ReadyStance(
            stance,
            areas,
            com_velocity_area=areas.com_velocity_area.area,
            zmp_area=areas.zmp_area.area,
            edge_directions=_directions(areas),
            identity=_identity(scenario, stance),
            verdicts={},
        )
        if model is not None and criterion is not None and scenario.impact is not None:
            ready.compiled = _CompiledImpact(
                scenario.impact, scenario.velocity_margin, model, criterion
            )
        return _StanceEntry(ready, ik_residual=residual)

    def _place(
        self, posture: PostureAxis, stance: Stance, values: dict[str, Any], warm: _Warm
    ) -> tuple[Stance, float]:
        """The stance with the posture point moved to its target, the contact frames kept."""
        frame, offset = self._posture_frame, self._posture_offset
        point = stance.frame_pose(frame) * offset
        target = np.array(point.translation)
        for d in self._posture_dims:
            target[d.coord] = float(values[d.name])
        goal = pin.SE3(point.rotation, target) * offset.inverse()
        fixed = [c.spec.frame for c in stance.contacts if c.spec.frame != frame]
        targets = {name: stance.frame_pose(name) for name in fixed}
        targets[frame] = goal
        # Warm start from the previous target reached in this chunk with the same base stance:
        # neighbouring grid targets need a few IK steps instead of tens.
        base_key = tuple(_key(values[d]) for d in self._stance_dims if not d.startswith("posture."))
        q0 = warm.get(base_key, stance.q)
        q = solve_stance(
            self.robot,
            q0,
            targets,
            posture_target=stance.q,
            options=IKOptions(tolerance=posture.tolerance, max_iterations=posture.max_iterations),
        )
        warm[base_key] = q
        placed = Stance(self.robot, q, [c.spec for c in stance.contacts])
        residual = _worst_pose_error(placed, targets)
        return placed, residual


def _robot_key(scenario: Scenario) -> str:
    robot = scenario.robot
    return (
        robot
        if isinstance(robot, str)
        else json.dumps(robot.model_dump(mode="json"), sort_keys=True)
    )


def _identity(scenario: Scenario, stance: Stance) -> dict[str, Any]:
    """The row's robot, contacts, configuration and stance digest."""
    robot = scenario.robot if isinstance(scenario.robot, str) else scenario.robot.urdf
    q = np.asarray(stance.q, dtype=float)
    specs = [
        (
            c.spec.frame,
            c.spec.friction,
            tuple(c.spec.size),
            tuple(np.round(c.position, 12)),
            tuple(np.round(c.rotation.ravel(), 12)),
        )
        for c in stance.contacts
    ]
    text = json.dumps([_robot_key(scenario), np.round(q, 12).tolist(), repr(specs)])
    return {
        "robot_name": robot,
        "contact_frames": ",".join(c.spec.frame for c in stance.contacts),
        "stance_digest": hashlib.sha256(text.encode()).hexdigest()[:12],
        "q": q.tolist(),
    }


def _directions(areas: BalanceAreas) -> list[float]:
    """Outward normal angle (deg, world, from +x about z) of each half-plane of the CoM area."""
    if areas.com_velocity_area.is_empty:
        return []
    G, _ = areas.com_velocity_area.halfplanes
    return [math.degrees(math.atan2(float(gy), float(gx))) for gx, gy in G]


def _key(value: Any) -> Any:
    """A hashable stand-in for a dimension value (lists and mappings by their repr)."""
    return repr(value) if isinstance(value, (list, dict)) else value


def _worst(residuals: dict[str, float]) -> float:
    return float(max(residuals.values(), default=0.0))


def _worst_pose_error(stance: Stance, targets: dict[str, pin.SE3]) -> float:
    worst = 0.0
    for name, target in targets.items():
        actual = stance.frame_pose(name)
        worst = max(
            worst,
            float(np.linalg.norm(actual.translation - target.translation)),
            float(np.linalg.norm(pin.log3(target.rotation.T @ actual.rotation))),
        )
    return worst
