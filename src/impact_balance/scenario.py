"""Scenario files: one YAML file describes one situation (robot, stance, contacts, impact).

Files are validated with pydantic; every problem becomes a :class:`ScenarioError` naming the
field and the bad value. A scenario may ``extends:`` another (a bundled name or a path):
mappings are merged recursively, everything else is replaced.
"""

from __future__ import annotations

import functools
import math
import typing
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pinocchio as pin
import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError, field_validator

from .constants import (
    GRAVITY_RANGE,
    MAX_ANGLE,
    MAX_DESCRIPTION,
    MAX_DURATION,
    MAX_FRICTION,
    MAX_NAME,
    MAX_PEAK_FACTOR,
    MAX_POSITION,
    MAX_SIZE,
    MAX_SPEED,
)
from .exceptions import ScenarioError, UnknownKeyError, UnknownScenarioError
from .input_limits import MAX_EXTENDS, check_path_text, check_structure, read_yaml
from .impact import ImpactSpec
from .robot import Robot, load_robot
from .spatial import pose
from .stance import ContactSpec, Stance

__all__ = [
    "Offset",
    "ContactConfig",
    "QPConfig",
    "ImpactConfig",
    "RobotFiles",
    "BasePose",
    "Scenario",
    "load_scenario",
    "bundled_scenarios",
    "scenario_path",
    "scenario_from_dict",
]

#: ``extends`` resolver: (the value, the file that extends) -> the file to read.
ExtendsResolver = typing.Callable[[str, Path], Path]

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]

# The physical ranges the schema accepts are in constants.py (shared with lipm.py).


def _interval(lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> str:
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


def _scalar(lo: float, hi: float, unit: str = "", lo_open: bool = False, hi_open: bool = False) -> AfterValidator:
    """A validator keeping a number within [lo, hi] (or open ends), naming the range."""
    text = _interval(lo, hi, lo_open, hi_open) + (f" {unit}" if unit else "")

    def check(v: float) -> float:
        if not ((lo < v if lo_open else lo <= v) and (v < hi if hi_open else v <= hi)):
            raise ValueError(f"must be in {text}")
        return v

    return AfterValidator(check)


def _coordinates(limit: float, unit: str) -> AfterValidator:
    """A validator keeping every coordinate of a vector within [-limit, limit]."""

    def check(v: tuple) -> tuple:
        if any(abs(x) > limit for x in v):
            raise ValueError(f"each coordinate must be in [{-limit:g}, {limit:g}] {unit}")
        return v

    return AfterValidator(check)


def _speed(v: tuple) -> tuple:
    if math.hypot(*v) > MAX_SPEED:
        raise ValueError(f"the speed must be at most {MAX_SPEED:g} m/s")
    return v


Position = Annotated[Vec3, _coordinates(MAX_POSITION, "m")]
Angles = Annotated[Vec3, _coordinates(MAX_ANGLE, "rad")]
Friction = Annotated[float, _scalar(0.0, MAX_FRICTION, lo_open=True)]


class _Model(BaseModel):
    # allow_inf_nan=False: NaN and infinities are refused in every float field.
    model_config = ConfigDict(extra="forbid", frozen=True, strict=False, allow_inf_nan=False)


def _finite(values: Any, what: str = "value") -> Any:
    for v in np.atleast_1d(np.asarray(values, dtype=float)):
        if not math.isfinite(v):
            raise ValueError(f"{what} must be finite")
    return values


class Offset(_Model):
    """Fixed pose in a robot frame: position (m) and roll-pitch-yaw (rad)."""

    position: Position = (0.0, 0.0, 0.0)
    rpy: Angles = (0.0, 0.0, 0.0)

    def se3(self) -> pin.SE3:
        return pose(self.position, self.rpy)


class ContactConfig(_Model):
    """A sustained rectangular contact (see :class:`impact_balance.stance.ContactSpec`)."""

    frame: str
    friction: Friction
    size: Vec2
    offset: Offset = Offset()

    @field_validator("size")
    @classmethod
    def _size(cls, v: Vec2) -> Vec2:
        if not all(0 < x <= MAX_SIZE for x in v):
            raise ValueError(f"size must be [length, width], both in (0, {MAX_SIZE:g}] m")
        return v

    def spec(self) -> ContactSpec:
        """The contact's :class:`ContactSpec` (cached by content: treat it as immutable)."""
        return _contact_spec(self.frame, self.friction, tuple(self.size), self.offset.position, self.offset.rpy)


# Specs are cached by content, not on the models (pydantic's model_copy would carry a cached
# value over to an updated copy): a scenario is analysed again and again, and building the
# offset SE3 through pinocchio costs more than the rest of the model update's bookkeeping.
@functools.lru_cache(maxsize=256)
def _contact_spec(frame: str, friction: float, size: Vec2, position: Vec3, rpy: Vec3) -> ContactSpec:
    return ContactSpec(frame, friction, size, pose(position, rpy))


@functools.lru_cache(maxsize=64)
def _impact_spec(
    frame: str,
    normal: Vec3,
    friction: float,
    restitution: Vec2,
    cone_edges: int,
    reference_velocity: Vec3 | None,
    duration: float,
    position: Vec3,
    rpy: Vec3,
    inertia: str,
) -> ImpactSpec:
    return ImpactSpec(
        frame=frame,
        normal=normal,
        friction=friction,
        restitution=restitution,
        cone_edges=cone_edges,
        reference_velocity=reference_velocity,
        duration=duration,
        offset=pose(position, rpy),
        inertia=inertia,
    )


@functools.lru_cache(maxsize=256)
def _quaternion(rpy: Vec3) -> np.ndarray:
    """Quaternion coefficients (x, y, z, w) of roll-pitch-yaw angles (rad), read-only."""
    coeffs = np.array(pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs(), dtype=float)
    coeffs.setflags(write=False)
    return coeffs


class QPConfig(_Model):
    """The paper's QP in joint velocities (optional; the exact answer never needs it)."""

    solve: bool = False
    joint_velocity_limits: bool = False
    impulsive_torque_limits: bool = False
    peak_factor: Annotated[float, _scalar(0.0, MAX_PEAK_FACTOR, lo_open=True)] = 1.0
    solver: str = "daqp"


class ImpactConfig(_Model):
    """The intended impact (see :class:`impact_balance.impact.ImpactSpec`)."""

    frame: str
    offset: Offset = Offset()
    normal: Annotated[Vec3, _coordinates(1e6, "(any scale; it is normalised)")]
    friction: Annotated[float, _scalar(0.0, MAX_FRICTION)] = 0.24
    restitution: Vec2 = (0.0, 0.2)
    cone_edges: int = Field(16, ge=3, le=1024)
    reference_velocity: Annotated[Vec3, AfterValidator(_speed)] | None = None
    duration: Annotated[float, _scalar(0.0, MAX_DURATION, "s", lo_open=True)] = 0.005
    inertia: Literal["composite", "joint_space"] = "composite"
    qp: QPConfig = QPConfig()

    @field_validator("normal")
    @classmethod
    def _normal(cls, v: Vec3) -> Vec3:
        _finite(v, "normal")
        if float(np.linalg.norm(v)) < 1e-9:
            raise ValueError("normal must be a non-zero vector")
        return v

    @field_validator("restitution")
    @classmethod
    def _restitution(cls, v: Vec2) -> Vec2:
        lo, hi = v
        if not (0.0 <= lo <= 1.0 and 0.0 <= hi <= 1.0):
            raise ValueError("restitution values must lie in [0, 1]")
        if lo > hi:
            raise ValueError("restitution must be [lo, hi] with lo <= hi")
        return v

    def spec(self) -> ImpactSpec:
        """The impact's :class:`ImpactSpec` (cached by content: treat it as immutable)."""
        return _impact_spec(
            self.frame,
            tuple(self.normal),
            self.friction,
            tuple(self.restitution),
            self.cone_edges,
            None if self.reference_velocity is None else tuple(self.reference_velocity),
            self.duration,
            self.offset.position,
            self.offset.rpy,
            self.inertia,
        )


class RobotFiles(_Model):
    """A robot given by files (paths relative to the scenario file)."""

    urdf: str
    srdf: str | None = None
    standing: str | None = None


class BasePose(_Model):
    """Free-flyer pose override in world: position (m), roll-pitch-yaw (rad)."""

    position: Position | None = None
    rpy: Angles | None = None


class Scenario(_Model):
    """One situation. See README, "Scenario files", for every key."""

    name: Annotated[str, Field(max_length=MAX_NAME)] | None = None
    description: Annotated[str, Field(max_length=MAX_DESCRIPTION)] | None = None
    robot: str | RobotFiles = "talos"
    configuration: str | None = None
    joints: dict[str, float] = {}
    base: BasePose | None = None
    com_velocity: Annotated[Vec2, AfterValidator(_speed)] = (0.0, 0.0)
    plane_height: Annotated[float, _scalar(-MAX_POSITION, MAX_POSITION, "m")] = 0.0
    torque_limits: bool = True
    gravity: Annotated[float, _scalar(*GRAVITY_RANGE, "m/s^2")] = 9.81
    contacts: list[ContactConfig] = Field(min_length=1)
    impact: ImpactConfig | None = None
    source: str | None = Field(None, exclude=True)

    @field_validator("joints")
    @classmethod
    def _joint_values(cls, joints: dict[str, float]) -> dict[str, float]:
        bad = [name for name, value in joints.items() if not math.isfinite(value)]
        if bad:
            raise ValueError(f"joint values must be finite (not {', '.join(bad)})")
        return joints

    # -- resolution against a robot model -------------------------------------------------
    def load_robot(self) -> Robot:
        if isinstance(self.robot, RobotFiles):
            check_path_text("robot.urdf", self.robot.urdf, self.source)
            if self.robot.srdf:
                check_path_text("robot.srdf", self.robot.srdf, self.source)
            base = Path(self.source).parent if self.source else Path.cwd()
            urdf = (base / self.robot.urdf).resolve()
            srdf = (base / self.robot.srdf).resolve() if self.robot.srdf else None
            return load_robot(None, urdf, srdf, self.robot.standing)
        return load_robot(self.robot)

    def configuration_vector(self, robot: Robot) -> np.ndarray:
        """q from the named configuration, the joint overrides and the base override."""
        q = robot.configuration(self.configuration)
        indices, values = robot.joint_assignment(self.joints, field="joints")
        q[indices] = values
        if self.base is not None:
            if self.base.position is not None:
                q[:3] = self.base.position
            if self.base.rpy is not None:
                q[3:7] = _quaternion(self.base.rpy)
        return q

    def build_stance(self, robot: Robot | None = None) -> Stance:
        """Resolve robot, configuration and contacts into a :class:`Stance` (see ``_build_stance``)."""
        try:
            return self._build_stance(robot)
        except ScenarioError as exc:
            raise with_source(exc, self.source) from None

    def _build_stance(self, robot: Robot | None = None) -> Stance:
        """Resolve robot, configuration and contacts into a :class:`Stance`.

        Without a ``base`` key the robot is translated vertically so that its lowest contact
        corner touches z = 0 (robots' neutral configurations often float or sink).
        """
        robot = robot or self.load_robot()
        q = self.configuration_vector(robot)
        specs = [c.spec() for c in self.contacts]
        stance = Stance(robot, q, specs)
        if self.base is None:
            lift = -stance.lowest_contact_height()
            if abs(lift) > 1e-12:
                q = q.copy()
                q[2] += lift
                stance = Stance(robot, q, specs)
        if not stance.com[2] > self.plane_height:
            raise ScenarioError(
                "plane_height", self.plane_height, f"must be below the CoM height {stance.com[2]:.4g} m"
            )
        return stance


# -- loading ------------------------------------------------------------------------------
def _scenario_dir():
    return resources.files("impact_balance") / "scenarios"


def bundled_scenarios() -> dict[str, str]:
    """Bundled scenario names and their one-line descriptions."""
    out = {}
    for entry in sorted(_scenario_dir().iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".yaml"):
            raw = yaml.safe_load(entry.read_text()) or {}
            out[entry.name[:-5]] = str(raw.get("description", "")).strip()
    return out


def scenario_path(name_or_path: str | Path) -> Path:
    """A scenario file's path: an existing file, or the name of a bundled scenario."""
    check_path_text("scenario", str(name_or_path))
    path = Path(name_or_path)
    if _is_file(path):
        return path
    if path.suffix in (".yaml", ".yml") or "/" in str(name_or_path) or "\\" in str(name_or_path):
        raise ScenarioError("scenario", str(name_or_path), "no such file")
    bundled = _scenario_dir() / f"{name_or_path}.yaml"
    if _is_file(Path(str(bundled))):
        return Path(str(bundled))
    raise UnknownScenarioError("scenario", str(name_or_path), list(bundled_scenarios()))


def _merge(base: dict, override: dict) -> dict:
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):  # a name the OS refuses is simply not an existing file
        return False


def _read(path: Path, seen: tuple[Path, ...] = (), resolve_path: ExtendsResolver | None = None) -> dict:
    if path.resolve() in seen:
        raise ScenarioError("extends", str(path), "circular extends")
    if len(seen) >= MAX_EXTENDS:
        raise ScenarioError("extends", str(path), f"a chain of more than {MAX_EXTENDS} extends")
    raw = read_yaml(path)
    if raw is None:
        raise ScenarioError("scenario", str(path), "the file is empty")
    if not isinstance(raw, dict):
        raise ScenarioError("scenario", str(path), f"must be a YAML mapping of keys, got {type(raw).__name__}")
    parent = raw.pop("extends", None)
    if parent is not None:
        if not isinstance(parent, str):
            raise ScenarioError("extends", parent, "must be a bundled scenario name or a file path", str(path))
        check_path_text("extends", parent, str(path))
        candidate = path.parent / parent
        try:
            if resolve_path is not None:
                parent_path = resolve_path(parent, path)
            else:
                parent_path = candidate if _is_file(candidate) else scenario_path(parent)
        except UnknownScenarioError as exc:
            raise UnknownScenarioError("extends", parent, exc.valid, str(path)) from None
        except ScenarioError as exc:
            raise ScenarioError("extends", parent, exc.reason, str(path)) from None
        raw = _merge(_read(parent_path, seen + (path.resolve(),), resolve_path), raw)
    return raw


def _field(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("function-after", "function-before") or "[" in str(part):
            continue
        else:
            out += f".{part}" if out else str(part)
    return out or "scenario"


def scenario_from_dict(raw: dict, source: str | None = None) -> Scenario:
    """Validate a scenario mapping; raises :class:`ScenarioError` on the first bad field."""
    check_structure(raw, source)
    try:
        return Scenario.model_validate({**raw, "source": source})
    except ValidationError as exc:
        errors = exc.errors()
        # A typo shows up as an unknown key AND a missing one: report the typo.
        err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
        loc = tuple(p for p in err["loc"] if p not in ("str", "RobotFiles"))
        reason = err["msg"].removeprefix("Value error, ")
        value = err.get("input")
        if err["type"] == "extra_forbidden" and loc:
            raise UnknownKeyError(_field(loc), str(loc[-1]), value, _keys_at(loc[:-1]), source) from None
        elif err["type"] == "missing":
            if loc and isinstance(loc[-1], int):  # a short list/tuple: report the whole list
                value, reason, loc = _lookup(raw, loc[:-1]), f"too few items (item {loc[-1]} is missing)", loc[:-1]
            else:
                value, reason = None, "missing required key"
        raise ScenarioError(_field(loc), value, reason, source) from None
    except ScenarioError as exc:
        raise ScenarioError(exc.field, exc.value, exc.reason, source) from None


def _model_in(annotation: Any) -> type[BaseModel] | None:
    """The pydantic model inside an annotation (``X | None``, ``list[X]``, ``str | X``), if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in typing.get_args(annotation):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


def _keys_at(loc: tuple) -> list[str]:
    """The keys the schema accepts in the mapping at ``loc`` (for "did you mean")."""
    model: type[BaseModel] | None = Scenario
    for part in loc:
        if isinstance(part, int) or model is None:
            continue
        info = model.model_fields.get(part)
        model = _model_in(info.annotation) if info is not None else None
    if model is None:
        return []
    return [name for name, info in model.model_fields.items() if not info.exclude]


def _lookup(raw: Any, loc: tuple) -> Any:
    for part in loc:
        try:
            raw = raw[part]
        except (KeyError, IndexError, TypeError):
            return None
    return raw


def with_source(exc: ScenarioError, source: str | None) -> ScenarioError:
    """Prefix a scenario error found after loading (unknown frame...) with its file name."""
    if source and exc.source is None:
        exc.source = source
        exc.args = (f"{source}: {exc.args[0]}",) + exc.args[1:]
    return exc


def load_scenario(name_or_path: str | Path, resolve_path: ExtendsResolver | None = None) -> Scenario:
    """Load and validate a scenario file (or a bundled scenario by name).

    Args:
        resolve_path: Optional rule for ``extends:`` (value, path of the file that extends) ->
            path to read, raising :class:`ScenarioError` to refuse. The GUI passes its
            workspace's rule; without it, a path relative to the file or a bundled name.
    """
    path = scenario_path(name_or_path)
    raw = _read(path, (), resolve_path)
    raw.setdefault("name", path.stem)
    return scenario_from_dict(raw, str(path))
