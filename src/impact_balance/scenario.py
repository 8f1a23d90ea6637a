"""Scenario files: one YAML file describes one situation (robot, stance, contacts, impact).

Files are validated with pydantic; every problem becomes a :class:`ScenarioError` naming the
field and the bad value. A scenario may ``extends:`` another (a bundled name or a path):
mappings are merged recursively, everything else is replaced.
"""

from __future__ import annotations

import functools
import math
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pinocchio as pin
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from .exceptions import ScenarioError, UnknownScenarioError
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

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=False)


def _finite(values: Any, what: str = "value") -> Any:
    for v in np.atleast_1d(np.asarray(values, dtype=float)):
        if not math.isfinite(v):
            raise ValueError(f"{what} must be finite")
    return values


class Offset(_Model):
    """Fixed pose in a robot frame: position (m) and roll-pitch-yaw (rad)."""

    position: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)

    _check = field_validator("position", "rpy")(lambda v: _finite(v))

    def se3(self) -> pin.SE3:
        return pose(self.position, self.rpy)


class ContactConfig(_Model):
    """A sustained rectangular contact (see :class:`impact_balance.stance.ContactSpec`)."""

    frame: str
    friction: float
    size: Vec2
    offset: Offset = Offset()

    @field_validator("friction")
    @classmethod
    def _friction(cls, v: float) -> float:
        if not (math.isfinite(v) and v > 0):
            raise ValueError("friction must be a finite number > 0")
        return v

    @field_validator("size")
    @classmethod
    def _size(cls, v: Vec2) -> Vec2:
        if not all(math.isfinite(x) and x > 0 for x in v):
            raise ValueError("size must be [length, width], both finite and > 0 (m)")
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
    peak_factor: float = Field(1.0, gt=0)
    solver: str = "daqp"


class ImpactConfig(_Model):
    """The intended impact (see :class:`impact_balance.impact.ImpactSpec`)."""

    frame: str
    offset: Offset = Offset()
    normal: Vec3
    friction: float = 0.24
    restitution: Vec2 = (0.0, 0.2)
    cone_edges: int = Field(16, ge=3, le=1024)
    reference_velocity: Vec3 | None = None
    duration: float = Field(0.005, gt=0)
    inertia: Literal["composite", "joint_space"] = "composite"
    qp: QPConfig = QPConfig()

    @field_validator("normal")
    @classmethod
    def _normal(cls, v: Vec3) -> Vec3:
        _finite(v, "normal")
        if float(np.linalg.norm(v)) < 1e-9:
            raise ValueError("normal must be a non-zero vector")
        return v

    @field_validator("friction")
    @classmethod
    def _friction(cls, v: float) -> float:
        if not (math.isfinite(v) and v >= 0):
            raise ValueError("friction must be a finite number >= 0")
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

    _check = field_validator("reference_velocity")(lambda v: _finite(v) if v is not None else v)

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

    position: Vec3 | None = None
    rpy: Vec3 | None = None


class Scenario(_Model):
    """One situation. See README, "Scenario files", for every key."""

    name: str | None = None
    description: str | None = None
    robot: str | RobotFiles = "talos"
    configuration: str | None = None
    joints: dict[str, float] = {}
    base: BasePose | None = None
    com_velocity: Vec2 = (0.0, 0.0)
    plane_height: float = 0.0
    torque_limits: bool = True
    gravity: float = Field(9.81, gt=0)
    contacts: list[ContactConfig] = Field(min_length=1)
    impact: ImpactConfig | None = None
    source: str | None = Field(None, exclude=True)

    _check = field_validator("com_velocity", "plane_height")(lambda v: _finite(v))

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
    path = Path(name_or_path)
    if path.is_file():
        return path
    if path.suffix in (".yaml", ".yml") or "/" in str(name_or_path) or "\\" in str(name_or_path):
        raise ScenarioError("scenario", str(name_or_path), "no such file")
    bundled = _scenario_dir() / f"{name_or_path}.yaml"
    if bundled.is_file():
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


def _parse(text: str) -> Any:
    """``yaml.safe_load(text)``, cached by content (parsing is ~95 % of loading a scenario:
    PyYAML's pure-Python parser takes 5-20 ms for a bundled file). The cached tree is never
    handed out: callers get a fresh copy of its dicts and lists (scalars are immutable)."""
    return _copy_tree(_parse_cached(text))


@functools.lru_cache(maxsize=64)
def _parse_cached(text: str) -> Any:
    return yaml.safe_load(text)


def _copy_tree(node: Any) -> Any:
    """Copy of a parsed YAML tree's containers (faster than copy.deepcopy for plain data)."""
    if isinstance(node, dict):
        return {k: _copy_tree(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_copy_tree(v) for v in node]
    return node


def _read(path: Path, seen: tuple[Path, ...] = ()) -> dict:
    if path.resolve() in seen:
        raise ScenarioError("extends", str(path), "circular extends")
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError("scenario", str(path), f"cannot read: {exc.__class__.__name__}") from None
    try:
        raw = _parse(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "syntax error"
        raise ScenarioError("scenario", str(path), f"not valid YAML: {problem}{where}") from None
    if raw is None:
        raise ScenarioError("scenario", str(path), "the file is empty")
    if not isinstance(raw, dict):
        raise ScenarioError("scenario", str(path), f"must be a YAML mapping of keys, got {type(raw).__name__}")
    parent = raw.pop("extends", None)
    if parent is not None:
        if not isinstance(parent, str):
            raise ScenarioError("extends", parent, "must be a bundled scenario name or a file path")
        candidate = path.parent / parent
        try:
            parent_path = candidate if candidate.is_file() else scenario_path(parent)
        except UnknownScenarioError as exc:
            raise UnknownScenarioError("extends", parent, exc.valid, str(path)) from None
        except ScenarioError as exc:
            raise ScenarioError("extends", parent, exc.reason, str(path)) from None
        raw = _merge(_read(parent_path, seen + (path.resolve(),)), raw)
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
    try:
        return Scenario.model_validate({**raw, "source": source})
    except ValidationError as exc:
        errors = exc.errors()
        # A typo shows up as an unknown key AND a missing one: report the typo.
        err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
        loc = tuple(p for p in err["loc"] if p not in ("str", "RobotFiles"))
        reason = err["msg"].removeprefix("Value error, ")
        value = err.get("input")
        if err["type"] == "extra_forbidden":
            reason = "unknown key"
        elif err["type"] == "missing":
            if loc and isinstance(loc[-1], int):  # a short list/tuple: report the whole list
                value, reason, loc = _lookup(raw, loc[:-1]), f"too few items (item {loc[-1]} is missing)", loc[:-1]
            else:
                value, reason = None, "missing required key"
        raise ScenarioError(_field(loc), value, reason, source) from None
    except ScenarioError as exc:
        raise ScenarioError(exc.field, exc.value, exc.reason, source) from None


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


def load_scenario(name_or_path: str | Path) -> Scenario:
    """Load and validate a scenario file (or a bundled scenario by name)."""
    path = scenario_path(name_or_path)
    raw = _read(path)
    raw.setdefault("name", path.stem)
    return scenario_from_dict(raw, str(path))
