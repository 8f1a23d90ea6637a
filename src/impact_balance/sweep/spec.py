"""Sweep files: a base scenario and axes, validated with pydantic like scenario files.

```yaml
description: "maximum contact velocity against impact friction and restitution"
base: palm_push_two_feet    # bundled scenario name, a path (relative to this file), or a mapping
sampling: grid              # or {method: sobol | halton | lhs, samples: 4096, seed: 0}
chunk_size: 1000            # points per chunk (work, output, resume); 1000, or 25 with posture
axes:
  - path: impact.friction         # any scenario key path
    range: [0.0, 0.6]             # with count (grid), or values: [...]
    count: 25
  - path: impact.restitution[1]
    values: [0.0, 0.2, 0.5, 1.0]
  - direction: impact.normal      # a 3-vector by azimuth/elevation, degrees (length kept)
    azimuth: {range: [150, 210], count: 13}
    elevation: {values: [0]}
  - posture:                      # move a frame to world targets by IK, the contacts kept
      frame: gripper_right_base_link   # default: the impact frame (with the impact offset)
      y: {range: [-0.6, 0.1], count: 15}   # world target of the point, m; x, y, z each optional
      z: {range: [0.7, 1.4], count: 15}
```

Every problem becomes a :class:`~impact_balance.exceptions.SweepError` naming the field and
the value. Numbers are strict (a bool or a quoted number is refused), finite, and a range's
width must be finite too; the number of points is computed exactly (Python integers) from the
file alone and refused above :data:`~impact_balance.ranges.MAX_SWEEP_POINTS` before the
robot is loaded or anything is allocated. The content of a file that is not a sweep file (a
link to a system file, say) is never quoted: only its name and the key.
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from impact_balance.exceptions import ScenarioError, SweepError, UnknownNameError
from impact_balance.files import describe_mode
from impact_balance.ranges import MAX_SWEEP_CHUNKS, MAX_SWEEP_POINTS
from impact_balance.scenario import Offset, field_name
from impact_balance.scenario.bundled import bundled_descriptions
from impact_balance.scenario.fields import Integer, Number
from impact_balance.scenario.reader import read_yaml

if TYPE_CHECKING:
    from importlib.abc import Traversable

__all__ = [
    "QMC_METHODS",
    "SAMPLING_METHODS",
    "Axis",
    "Dim",
    "DirectionAxis",
    "PathAxis",
    "PostureAxis",
    "QmcMethod",
    "Sampling",
    "SamplingMethod",
    "SweepSpec",
    "UnknownSweepError",
    "bundled_sweeps",
    "load_sweep_spec",
    "sweep_path",
    "sweep_spec_from_dict",
]

#: Quasi-random sampling methods (``scipy.stats.qmc``): Sobol, Halton, Latin hypercube.
QmcMethod = Literal["sobol", "halton", "lhs"]
#: How the points are drawn: ``grid`` (every combination) or a quasi-random method.
SamplingMethod = Literal["grid", "sobol", "halton", "lhs"]
QMC_METHODS: tuple[QmcMethod, ...] = get_args(QmcMethod)
SAMPLING_METHODS: tuple[SamplingMethod, ...] = get_args(SamplingMethod)


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Dim(_Model):
    """Values of one dimension: explicit ``values``, or a closed ``range`` [lo, hi].

    A grid needs ``count`` with a range (``count`` evenly spaced values, both ends included);
    quasi-random sampling draws from the range (or picks among the values).
    """

    values: list[Any] | None = Field(default=None, min_length=1)
    range: tuple[Number, Number] | None = None
    count: Integer | None = Field(default=None, ge=1, le=MAX_SWEEP_POINTS)

    @model_validator(mode="after")
    def _one_of(self) -> Dim:
        if (self.values is None) == (self.range is None):
            raise ValueError("give either values: [...] or range: [lo, hi] (with count for a grid)")
        if self.values is not None and self.count is not None:
            raise ValueError("count goes with range, not with values")
        if self.range is not None:
            lo, hi = self.range
            if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
                raise ValueError("range must be [lo, hi], finite, with lo <= hi")
            if not math.isfinite(hi - lo):
                raise ValueError(
                    "range is wider than a float can hold (hi - lo overflows): narrow it"
                )
        if self.values is not None:
            for k, v in enumerate(self.values):
                if isinstance(v, float) and not math.isfinite(v):
                    raise ValueError(f"values[{k}] is {v}: values must be finite")
        return self

    @property
    def size(self) -> int | None:
        """Number of grid values (None for a range without count)."""
        return len(self.values) if self.values is not None else self.count

    @property
    def bounds(self) -> tuple[float, float]:
        """The range's ends ``(lo, hi)``.

        Raises:
            ValueError: The dimension has values, not a range.
        """
        if self.range is None:
            raise ValueError("the dimension has values, not a range")
        return self.range

    @property
    def numeric(self) -> bool:
        """Every value is a number (a bool is not): always for a range."""
        return self.values is None or all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in self.values
        )


class PathAxis(Dim):
    """One scenario key, e.g. ``impact.friction`` or ``joints.arm_right_4_joint``."""

    path: str


class DirectionAxis(_Model):
    """A 3-vector key (``impact.normal``...) by azimuth and elevation in degrees, world axes.

    ``v = |v_base| (cos el cos az, cos el sin az, sin el)``: azimuth about world z from +x,
    elevation above the horizontal plane. The base vector's length is kept.
    """

    direction: str
    azimuth: Dim = Dim(values=[0.0])
    elevation: Dim = Dim(values=[0.0])

    @model_validator(mode="after")
    def _numbers(self) -> DirectionAxis:
        if not (self.azimuth.numeric and self.elevation.numeric):
            raise ValueError("azimuth and elevation must be numbers (degrees)")
        return self


class PostureAxis(_Model):
    """Move a point of a frame to world targets by whole-body IK; the contact frames stay put.

    The point is ``frame * offset``; its world orientation is kept from the base stance and
    its world position takes the targets ``x``, ``y``, ``z`` (m), each optional (a missing
    coordinate keeps the base value).
    """

    frame: str | None = None
    offset: Offset | None = None
    x: Dim | None = None
    y: Dim | None = None
    z: Dim | None = None
    tolerance: Number = Field(default=1e-4, gt=0, le=1e-2)
    max_iterations: Integer = Field(default=200, ge=1, le=10_000)

    @model_validator(mode="after")
    def _some_target(self) -> PostureAxis:
        dims = [d for d in (self.x, self.y, self.z) if d is not None]
        if not dims:
            raise ValueError("give at least one target coordinate: x, y or z (world, m)")
        if not all(d.numeric for d in dims):
            raise ValueError("target coordinates must be numbers (m)")
        return self


class Sampling(_Model):
    """``grid`` (every combination) or quasi-random ``samples`` points (scipy.stats.qmc)."""

    method: SamplingMethod = "grid"
    samples: Integer | None = Field(default=None, ge=1, le=MAX_SWEEP_POINTS)
    seed: Integer = Field(default=0, ge=0, le=2**63 - 1)

    @model_validator(mode="after")
    def _samples(self) -> Sampling:
        if self.method == "grid" and self.samples is not None:
            raise ValueError(
                "samples goes with a quasi-random method (sobol, halton, lhs), not grid"
            )
        if self.method != "grid" and self.samples is None:
            raise ValueError(f"{self.method} sampling needs samples: N")
        return self

    @property
    def points(self) -> int:
        """The number of quasi-random points.

        Raises:
            ValueError: The sampling is a grid (its points come from the axes).
        """
        if self.samples is None:
            raise ValueError("a grid has no samples: its points come from the axes")
        return int(self.samples)


#: One axis of a sweep file.
Axis = PathAxis | DirectionAxis | PostureAxis


class SweepSpec(_Model):
    """A validated sweep file (see the module docstring for every key)."""

    description: str | None = None
    base: str | dict[str, Any]
    axes: tuple[Axis, ...]
    sampling: Sampling = Sampling()
    chunk_size: Integer | None = Field(default=None, ge=1, le=MAX_SWEEP_POINTS)
    source: str | None = Field(default=None, exclude=True)

    def dimension_sizes(self) -> list[int | None]:
        """Grid values per dimension, in the file's order (None: a range without count)."""
        sizes: list[int | None] = []
        for axis in self.axes:
            if isinstance(axis, PathAxis):
                sizes.append(axis.size)
            elif isinstance(axis, DirectionAxis):
                sizes += [axis.azimuth.size, axis.elevation.size]
            else:
                sizes += [d.size for d in (axis.x, axis.y, axis.z) if d is not None]
        return sizes

    def point_count(self) -> int | None:
        """The number of points, exact (Python integers; None: a grid range lacks its count)."""
        if self.sampling.method != "grid":
            return self.sampling.points
        sizes = [s for s in self.dimension_sizes() if s is not None]
        return None if len(sizes) < len(self.dimension_sizes()) else math.prod(sizes)

    def digest_data(self) -> dict[str, Any]:
        """The keys that define the results (not the description), JSON-ready."""
        return self.model_dump(mode="json", exclude={"description", "source"})


def _raise(exc: ValidationError, raw: Any, prefix: str, source: str | None) -> None:
    err = exc.errors()[0]
    loc = tuple(
        p
        for p in err["loc"]
        if not (isinstance(p, str) and ("[" in p or p in ("function-after", "tagged-union")))
    )
    field = field_name(loc)
    field = f"{prefix}.{field}" if prefix and field != "scenario" else (prefix or field)
    reason = err["msg"].removeprefix("Value error, ")
    value = err.get("input")
    if err["type"] == "extra_forbidden":
        # The value of an unknown key is content of a file that may not be a sweep file: not shown.
        value, reason = None, "unknown key"
    elif err["type"] == "missing":
        value, reason = None, "missing required key"
    raise SweepError(field, value, reason, source) from None


def _axis(raw: Any, i: int, source: str | None) -> Axis:
    field = f"axes[{i}]"
    if not isinstance(raw, dict):
        raise SweepError(
            field, raw, "an axis is a mapping with one of path, direction or posture", source
        )
    kinds = [k for k in ("path", "direction", "posture") if k in raw]
    if len(kinds) != 1:
        raise SweepError(
            field, raw, "an axis needs exactly one of path, direction or posture", source
        )
    try:
        if kinds[0] == "posture":
            extra = set(raw) - {"posture"}
            if extra:
                raise SweepError(
                    f"{field}.{sorted(extra)[0]}",
                    raw[sorted(extra)[0]],
                    "unknown key (posture options go under posture:)",
                    source,
                )
            body = raw["posture"]
            if not isinstance(body, dict):
                raise SweepError(
                    f"{field}.posture", body, "must be a mapping (frame, x, y, z, ...)", source
                )
            return PostureAxis.model_validate(body)
        return (PathAxis if kinds[0] == "path" else DirectionAxis).model_validate(raw)
    except ValidationError as exc:
        _raise(exc, raw, field + (".posture" if kinds[0] == "posture" else ""), source)
        raise AssertionError("unreachable") from exc  # pragma: no cover


def sweep_spec_from_dict(raw: Any, source: str | None = None) -> SweepSpec:
    """Validate a sweep mapping; raises :class:`SweepError` on the first bad field."""
    if not isinstance(raw, dict):
        # Name the file, not its content (a link to a system file must not be quoted).
        raise SweepError(
            "sweep",
            source or "(mapping)",
            f"must be a YAML mapping of keys, got {type(raw).__name__}",
            source,
        )
    axes_raw = raw.get("axes")
    if not isinstance(axes_raw, list) or not axes_raw:
        shown = (
            axes_raw
            if axes_raw is None or isinstance(axes_raw, (list, int, float))
            else type(axes_raw).__name__
        )
        raise SweepError("axes", shown, "must be a non-empty list of axes", source)
    axes = tuple(_axis(a, i, source) for i, a in enumerate(axes_raw))
    if sum(isinstance(a, PostureAxis) for a in axes) > 1:
        raise SweepError("axes", "posture", "at most one posture axis", source)
    body = {k: v for k, v in raw.items() if k != "axes"}
    if isinstance(body.get("sampling"), str):
        body["sampling"] = {"method": body["sampling"]}
    try:
        spec = SweepSpec.model_validate({**body, "axes": axes, "source": source})
    except ValidationError as exc:
        _raise(exc, raw, "", source)
        raise AssertionError("unreachable") from exc  # pragma: no cover
    _check_size(spec, source)
    return spec


def _check_size(spec: SweepSpec, source: str | None) -> None:
    """Refuse a sweep of more than MAX_SWEEP_POINTS points or MAX_SWEEP_CHUNKS chunks.

    The count comes from the file alone (exact integers: no float overflow, no wrap-around),
    before anything is allocated.
    """
    n = spec.point_count()
    if n is None:
        return  # a range without count: the plan names the axis
    if n > MAX_SWEEP_POINTS:
        field = "sampling.samples" if spec.sampling.method != "grid" else "axes"
        how = (
            ""
            if spec.sampling.method != "grid"
            else " (the product of the axes' counts "
            f"{' x '.join(str(s) for s in spec.dimension_sizes())})"
        )
        text = str(n) if n < 10**30 else f"about 10^{len(str(n)) - 1}"
        raise SweepError(
            field,
            f"{text} points",
            f"a sweep has at most {MAX_SWEEP_POINTS:,} points{how}; "
            "split the study into several sweeps",
            source,
        )
    chunk = spec.chunk_size
    if chunk is not None and -(-n // chunk) > MAX_SWEEP_CHUNKS:
        raise SweepError(
            "chunk_size",
            chunk,
            f"{-(-n // chunk):,} chunks for {n:,} points: at most "
            f"{MAX_SWEEP_CHUNKS:,} chunks (use a chunk_size of at least "
            f"{-(-n // MAX_SWEEP_CHUNKS)})",
            source,
        )


# -- files ------------------------------------------------------------------------------
def _sweep_dir() -> Traversable:
    return resources.files("impact_balance") / "sweeps"


def bundled_sweeps() -> dict[str, str]:
    """Bundled sweep names and their one-line descriptions."""
    return bundled_descriptions("sweeps")


class UnknownSweepError(UnknownNameError, SweepError):
    """The sweep is neither a file nor a bundled sweep's name."""

    kind = "sweep"


def sweep_path(name_or_path: str | Path) -> Path:
    """A sweep file's path: an existing file, or the name of a bundled sweep."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    if path.exists():  # a FIFO, a device, a folder: named for what it is, never opened
        raise SweepError(
            "sweep", str(name_or_path), f"{describe_mode(path.stat().st_mode)}, not a regular file"
        )
    if path.suffix in (".yaml", ".yml") or "/" in str(name_or_path):
        raise SweepError("sweep", str(name_or_path), "no such file")
    bundled = _sweep_dir() / f"{name_or_path}.yaml"
    if bundled.is_file():
        return Path(str(bundled))
    raise UnknownSweepError("sweep", str(name_or_path), list(bundled_sweeps()))


def load_sweep_spec(name_or_path: str | Path) -> SweepSpec:
    """Read and validate a sweep file (or a bundled sweep by name)."""
    path = sweep_path(name_or_path)
    try:  # the project's bounded reader: size, nesting and expanded-alias limits, as for scenarios
        raw = read_yaml(path)
    except ScenarioError as exc:
        raise SweepError("sweep", str(path), exc.reason) from None
    if raw is None:
        raise SweepError("sweep", str(path), "the file is empty")
    return sweep_spec_from_dict(raw, str(path))
