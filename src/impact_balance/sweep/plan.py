"""A sweep plan: the base scenario resolved, the axes checked, the points enumerated in chunks.

The plan is everything a worker needs (it pickles): the base scenario as a full mapping (every
default filled in), the dimensions, and how to produce the points of any chunk. Points are
numbered once and for all by the plan, so a chunk's rows never depend on the number of
workers or on which worker computes it.

Grid order: dimensions that change the stance vary slowest, then those of the impact and of the
CoM velocity, so that consecutive points share a stance and its areas (only the impact part
is recomputed). Within each group the axes keep the file's order.

Every axis does what it says: an axis on ``robot`` (``robot: [g1, icub]``, or ``robot.urdf``
for files) varies the robot, and each of its values is loaded and the base stance built with
it when the sweep is planned, so that a robot that cannot take the base scenario's contacts
(unknown frames) or cannot be read is refused at once, naming the value.
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
from scipy.stats import qmc

from impact_balance.exceptions import ImpactBalanceError, ScenarioError, SweepError
from impact_balance.ranges import MAX_SWEEP_POINTS
from impact_balance.robot.robot import Robot
from impact_balance.scenario import merge_mappings, read_mapping, scenario_from_dict, scenario_path
from impact_balance.sweep.paths import (
    STANCE_FREE_ROOTS,
    Token,
    check_path,
    format_path,
    parse_path,
    set_path,
)
from impact_balance.sweep.spec import (
    Dim,
    DirectionAxis,
    PathAxis,
    PostureAxis,
    SweepSpec,
    _check_size,
    load_sweep_spec,
)

__all__ = [
    "DEFAULT_CHUNK",
    "DEFAULT_CHUNK_IK",
    "PLAN_VERSION",
    "Dimension",
    "DimensionKind",
    "SweepPlan",
    "chunk_size_of",
    "make_plan",
    "plan_sweep",
]

#: What a dimension varies: a scenario key, a 3-vector's azimuth or elevation (degrees), or
#: one world coordinate of the posture target (m).
DimensionKind = Literal["path", "azimuth", "elevation", "posture"]

#: Default points per chunk, without and with a posture axis.
DEFAULT_CHUNK, DEFAULT_CHUNK_IK = 1000, 25

#: Bumped when the rows of the same spec would change (columns, ordering): old results are
#: not resumed.
#: 2: rows carry robot, contacts, stance and q; parts carry their chunk, row count and checksum.
PLAN_VERSION = 2


@dataclass(frozen=True)
class Dimension:
    """One column of the points.

    Attributes:
        name: Column name (the axis path, ``PATH.azimuth`` / ``PATH.elevation`` in degrees, or
            ``posture.x`` / ``.y`` / ``.z`` in m).
        axis: Index of its axis in the sweep file.
        kind: "path", "azimuth", "elevation" or "posture".
        dim: The values or range.
        tokens: The scenario key path (path and direction axes).
        coord: 0, 1, 2 for posture x, y, z.
        stance: True when it changes the stance (hence the areas).
    """

    name: str
    axis: int
    kind: DimensionKind
    dim: Dim
    tokens: tuple[Token, ...] = ()
    coord: int = -1
    stance: bool = True

    @property
    def numeric(self) -> bool:
        """Every value is a number."""
        return self.dim.numeric

    @property
    def robot(self) -> bool:
        """True when it varies the robot (an axis on ``robot`` or a key of it)."""
        return bool(self.tokens) and self.tokens[0] == "robot"

    def grid_values(self) -> list[Any]:
        """Every grid value, in order.

        Raises:
            SweepError: A range without count.
        """
        d = self.dim
        if d.values is not None:
            return list(d.values)
        if d.count is None:
            raise SweepError(
                f"axes[{self.axis}]", self.name, "a grid needs count with range (or values: [...])"
            )
        lo, hi = d.bounds
        values: list[Any] = np.linspace(lo, hi, d.count).tolist()
        return values

    def grid_value(self, index: npt.NDArray[np.intp]) -> list[Any]:
        """The grid values at ``index`` (``grid_values()[i]``, without building the list).

        Raises:
            SweepError: A range without count.
        """
        d = self.dim
        if d.values is not None:
            return [d.values[i] for i in index]
        if d.count is None:
            raise SweepError(
                f"axes[{self.axis}]", self.name, "a grid needs count with range (or values: [...])"
            )
        lo, hi = d.bounds
        if d.count == 1:
            return [float(lo)] * len(index)
        # numpy.linspace's own formula (start + i * step, the last value exactly hi).
        step = (hi - lo) / (d.count - 1)
        values = lo + np.asarray(index, dtype=float) * step
        values[np.asarray(index) == d.count - 1] = hi
        out: list[Any] = values.tolist()
        return out

    def from_unit(self, u: npt.NDArray[np.float64]) -> list[Any] | npt.NDArray[np.float64]:
        """Map quasi-random samples in [0, 1) to values."""
        d = self.dim
        if d.values is not None:
            idx = np.minimum((u * len(d.values)).astype(int), len(d.values) - 1)
            return (
                [d.values[i] for i in idx]
                if not d.numeric
                else np.asarray(d.values, dtype=float)[idx]
            )
        lo, hi = d.bounds
        return lo + u * (hi - lo)


@dataclass(frozen=True)
class SweepPlan:
    """A checked sweep, ready to run (see the module docstring).

    Attributes:
        spec: The sweep file.
        base: The base scenario, a full mapping (defaults filled in, ``extends`` resolved).
        base_source: File the base scenario came from (resolves relative robot paths).
        dims: The dimensions, in enumeration order (stance first for a grid).
        shape: Grid shape (grid only).
        samples: Quasi-random points, one column per dimension (qmc only).
        n_points: Number of points.
        digest: Hash of everything that defines the rows (resume checks it).
    """

    spec: SweepSpec
    base: dict[str, Any]
    base_source: str | None
    dims: tuple[Dimension, ...]
    shape: tuple[int, ...] | None
    samples: dict[str, Any] | None
    n_points: int
    digest: str

    @property
    def chunk_size(self) -> int:
        """Points per chunk: the file's ``chunk_size``, else 1000, or 25 with a posture axis.

        IK takes milliseconds per point: small chunks keep every worker busy to the end.
        """
        return chunk_size_of(self.spec)

    @property
    def n_chunks(self) -> int:
        """Number of chunks."""
        return math.ceil(self.n_points / self.chunk_size)

    def chunk_range(self, chunk: int) -> tuple[int, int]:
        """The points of chunk ``chunk``: ``start`` (included) and ``stop`` (excluded)."""
        start = chunk * self.chunk_size
        return start, min(self.n_points, start + self.chunk_size)

    def points(self, start: int, stop: int) -> dict[str, list[Any]]:
        """The values of points ``start .. stop - 1``, by dimension name."""
        if self.samples is not None:
            return {d.name: list(self.samples[d.name][start:stop]) for d in self.dims}
        if self.shape is None:
            raise ValueError("a plan has either samples or a grid shape")
        index = np.unravel_index(np.arange(start, stop), self.shape)
        return {d.name: d.grid_value(idx) for d, idx in zip(self.dims, index, strict=True)}

    @property
    def posture(self) -> PostureAxis | None:
        """The posture axis, if any (a sweep has at most one)."""
        return next((a for a in self.spec.axes if isinstance(a, PostureAxis)), None)


def chunk_size_of(spec: SweepSpec) -> int:
    """Points per chunk of a sweep file: its ``chunk_size``, else 1000 (25 with a posture axis)."""
    if spec.chunk_size is not None:
        return spec.chunk_size
    posture = any(isinstance(a, PostureAxis) for a in spec.axes)
    return DEFAULT_CHUNK_IK if posture else DEFAULT_CHUNK


def _base_mapping(spec: SweepSpec) -> tuple[dict[str, Any], str | None]:
    here = Path(spec.source).parent if spec.source else Path.cwd()
    if isinstance(spec.base, str):
        candidate = here / spec.base
        try:
            path = candidate if candidate.is_file() else scenario_path(spec.base)
        except ScenarioError as exc:
            raise type(exc)(*_args(exc, "base")) from None
        raw = read_mapping(path)
        raw.setdefault("name", path.stem)
        return raw, str(path)
    raw = dict(spec.base)
    parent = raw.pop("extends", None)
    if parent is not None:
        candidate = here / str(parent)
        try:
            path = candidate if candidate.is_file() else scenario_path(parent)
        except ScenarioError as exc:
            raise type(exc)(*_args(exc, "base.extends")) from None
        raw = merge_mappings(read_mapping(path), raw)
    raw.setdefault("name", Path(spec.source).stem if spec.source else "sweep")
    return raw, spec.source


def _args(exc: ScenarioError, field: str) -> tuple[Any, ...]:
    valid = getattr(exc, "valid", None)
    return (
        (field, exc.value, valid, exc.source)
        if valid is not None
        else (field, exc.value, exc.reason, exc.source)
    )


def _dimensions(spec: SweepSpec, base: dict[str, Any], robot: Robot) -> list[Dimension]:
    dims: list[Dimension] = []
    joints = robot.joint_names
    for i, axis in enumerate(spec.axes):
        if isinstance(axis, PathAxis):
            tokens = parse_path(axis.path, f"axes[{i}].path")
            leaf = check_path(base, tokens, f"axes[{i}].path", joints)
            if axis.range is not None and leaf is not None and not isinstance(leaf, (int, float)):
                raise SweepError(
                    f"axes[{i}].path",
                    axis.path,
                    f"is {leaf!r}, not a number: a range needs a number (use values: [...])",
                )
            dims.append(
                Dimension(
                    format_path(tokens),
                    i,
                    "path",
                    axis,
                    tokens,
                    stance=tokens[0] not in STANCE_FREE_ROOTS,
                )
            )
        elif isinstance(axis, DirectionAxis):
            tokens = parse_path(axis.direction, f"axes[{i}].direction")
            leaf = check_path(base, tokens, f"axes[{i}].direction", joints)
            if not (isinstance(leaf, (list, tuple)) and len(leaf) == 3):
                raise SweepError(
                    f"axes[{i}].direction", axis.direction, f"is {leaf!r}, not a 3-vector"
                )
            if float(np.linalg.norm(np.asarray(leaf, dtype=float))) == 0.0:
                raise SweepError(
                    f"axes[{i}].direction",
                    axis.direction,
                    "is the zero vector in the base scenario: no length to keep",
                )
            name = format_path(tokens)
            stance = tokens[0] not in STANCE_FREE_ROOTS
            dims.append(
                Dimension(f"{name}.azimuth", i, "azimuth", axis.azimuth, tokens, stance=stance)
            )
            dims.append(
                Dimension(
                    f"{name}.elevation", i, "elevation", axis.elevation, tokens, stance=stance
                )
            )
        else:
            for coord, key in enumerate("xyz"):
                d = getattr(axis, key)
                if d is not None:
                    dims.append(Dimension(f"posture.{key}", i, "posture", d, coord=coord))
    names = [d.name for d in dims]
    for name in names:
        if names.count(name) > 1:
            raise SweepError("axes", name, "appears in two axes")
    from impact_balance.sweep.columns import RESULT_COLUMNS  # the result columns' names are taken

    taken = {"point", "chunk"} | {c[0] for c in RESULT_COLUMNS}
    for d in dims:
        if d.name in taken:
            raise SweepError(
                f"axes[{d.axis}]",
                d.name,
                f"{d.name!r} is the name of a result column: vary a key inside it",
            )
    # Stance dimensions first (stable): consecutive grid points then share a stance.
    return sorted(dims, key=lambda d: not d.stance)


def _samples(spec: SweepSpec, dims: list[Dimension]) -> dict[str, Any]:
    s = spec.sampling
    n, d = s.points, len(dims)
    engine = {"sobol": qmc.Sobol, "halton": qmc.Halton, "lhs": qmc.LatinHypercube}[s.method](
        d, rng=s.seed
    )
    with warnings.catch_warnings():
        # Sobol warns when n is not a power of two (balance properties): the user chose n.
        warnings.simplefilter("ignore", UserWarning)
        u = engine.random(n)
    return {dim.name: dim.from_unit(u[:, k]) for k, dim in enumerate(dims)}


def make_plan(spec: SweepSpec, robot: Robot | None = None) -> SweepPlan:
    """Resolve the base scenario, check every axis against it, and enumerate the points.

    Args:
        spec: The sweep file.
        robot: The base scenario's robot, if already loaded.

    Returns:
        The plan.

    Raises:
        SweepError, UnknownPathError: a bad axis (the message names the path and the valid keys).
        ScenarioError: a bad base scenario.
    """
    raw, source = _base_mapping(spec)
    try:
        base_scenario = scenario_from_dict(raw, source)
    except ScenarioError as exc:
        raise type(exc)(*_args(exc, f"base: {exc.field}")) from None
    impact = base_scenario.impact
    if impact is None:
        raise SweepError(
            "base",
            spec.base if isinstance(spec.base, str) else "(mapping)",
            "the base scenario has no impact: a sweep maps the maximum contact velocity",
            spec.source,
        )
    robot = robot or base_scenario.load_robot()
    base_scenario.build_stance(
        robot
    )  # unknown frames, plane above the CoM...: fail now, not per point
    base = base_scenario.model_dump(mode="python", exclude={"source"})
    try:
        dims = _dimensions(spec, base, robot)
    except ScenarioError as exc:
        exc.source = spec.source
        exc.args = (f"{spec.source}: {exc.args[0]}",) if spec.source else exc.args
        raise
    for i, axis in enumerate(spec.axes):
        if isinstance(axis, PostureAxis):
            try:
                robot.frame_id(axis.frame or impact.frame, field=f"axes[{i}].posture.frame")
            except ScenarioError as exc:
                field, value, reason = _args(exc, exc.field)[:3]
                raise type(exc)(field, value, reason, spec.source) from None
    _check_robots(spec, base, source, dims)
    _check_size(spec, spec.source)  # a spec built without sweep_spec_from_dict is bounded too
    if spec.sampling.method == "grid":
        for d in dims:
            d.grid_value(np.zeros(0, dtype=int))  # a range without count: named now
        # every size is set: a range without count was refused just above
        sizes = tuple(d.dim.size or 0 for d in dims)
        shape: tuple[int, ...] | None = sizes
        n_points, samples = math.prod(sizes), None  # exact: Python integers
    else:
        shape, samples = None, _samples(spec, dims)
        n_points = spec.sampling.points
    if n_points > MAX_SWEEP_POINTS:  # pragma: no cover - _check_size refuses it first
        raise SweepError("axes", n_points, f"more than {MAX_SWEEP_POINTS} points", spec.source)
    digest_input = {
        "version": PLAN_VERSION,
        "spec": spec.digest_data(),
        "base": json.loads(json.dumps(base, default=list)),
    }
    digest = hashlib.sha256(json.dumps(digest_input, sort_keys=True).encode()).hexdigest()[:16]
    return SweepPlan(spec, base, source, tuple(dims), shape, samples, n_points, digest)


def _check_robots(
    spec: SweepSpec, base: dict[str, Any], source: str | None, dims: list[Dimension]
) -> None:
    """Load every robot of a robot axis and build the base stance with it.

    A robot that cannot be read, or lacks the base scenario's frames, is refused now, naming
    its value.
    """
    for d in dims:
        if not d.robot:
            continue
        if d.dim.values is None:
            raise SweepError(
                f"axes[{d.axis}]",
                d.name,
                "a robot axis takes values: [...] (robot names or files)",
                spec.source,
            )
        for k, value in enumerate(d.dim.values):
            field = f"axes[{d.axis}].values[{k}]"
            try:
                scenario = scenario_from_dict(set_path(base, d.tokens, value), source)
                scenario.build_stance()
            except ImpactBalanceError as exc:
                raise SweepError(
                    field, value, f"this robot cannot take the base scenario: {exc}", spec.source
                ) from None


def plan_sweep(name_or_path: str | Path) -> SweepPlan:
    """Load a sweep file (or a bundled sweep by name) and plan it."""
    return make_plan(load_sweep_spec(name_or_path))
