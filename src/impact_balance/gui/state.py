"""The GUI's editable state: a scenario as a plain mapping, validated on every edit.

A :class:`GuiState` is immutable. An edit (:meth:`GuiState.with_changes`) returns a new state
or raises :class:`~impact_balance.exceptions.ScenarioError` naming the bad field, so that the
caller keeps the previous good state and shows the message. The mapping has the schema of the
scenario files (README, "Scenario files"): :meth:`GuiState.to_yaml` writes a file that
``impact-balance analyze`` reads, and :meth:`GuiState.from_file` reads any scenario file (the
GUI reads and writes files only through :mod:`.files`, confined to its workspace).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Hashable, Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from impact_balance.constants import MAX_DESCRIPTION
from impact_balance.exceptions import ScenarioError
from impact_balance.robot.robot import RobotFileReader
from impact_balance.scenario import RobotFiles, Scenario, load_scenario, scenario_from_dict

__all__ = ["DEFAULT_SCENARIO", "FieldPath", "GuiState", "plain"]

#: The scenario the GUI opens when none is given (the demo's first study).
DEFAULT_SCENARIO = "palm_push_two_feet"

#: Where a value sits in the scenario mapping: keys and list indices, e.g.
#: ``("contacts", 0, "friction")``.
FieldPath = tuple[Hashable, ...]


def plain(value: Any) -> Any:
    """``value`` as plain YAML-safe Python data (numpy arrays and scalars to lists and floats)."""
    if isinstance(value, np.ndarray):
        return [plain(v) for v in value.tolist()]
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return value.item()
    if isinstance(value, Mapping):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def _field_name(path: FieldPath) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "scenario"


def _set(raw: dict[str, Any], path: FieldPath, value: Any) -> None:
    """Set ``raw[path] = value`` in place, creating missing mappings; None deletes the key."""
    if not path:
        raise ScenarioError("scenario", value, "empty field path")
    node: Any = raw
    for i, part in enumerate(path[:-1]):
        try:
            child = node[part]
        except (KeyError, IndexError, TypeError):
            if isinstance(node, dict) and value is not None:
                child = node[part] = {}
            elif value is None:
                return  # deleting under a missing key: nothing to do
            else:
                raise ScenarioError(_field_name(path[: i + 1]), None, "no such item") from None
        if child is None and value is not None and isinstance(node, dict):
            child = node[part] = {}
        node = child
    last = path[-1]
    if value is None:
        if isinstance(node, dict):
            node.pop(last, None)
        elif isinstance(node, list) and isinstance(last, int) and -len(node) <= last < len(node):
            node.pop(last)
        return
    try:
        node[last] = value
    except (IndexError, TypeError):
        raise ScenarioError(_field_name(path), value, "no such item") from None


def _check_finite(path: FieldPath, value: Any) -> None:
    """Refuse NaN and infinities early, with the GUI's field name (some fields would take inf)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise ScenarioError(_field_name(path), value, "must be a finite number")
    if isinstance(value, dict):
        for key, item in value.items():
            _check_finite((*path, key), item)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            if isinstance(item, (dict, list)):
                _check_finite((*path, i), item)
            elif isinstance(item, float) and not math.isfinite(item):
                raise ScenarioError(_field_name(path), value, "must be finite numbers")


class GuiState:
    """A validated scenario mapping and the :class:`~impact_balance.scenario.Scenario` of it.

    Attributes:
        scenario: The validated scenario (what :func:`impact_balance.analyze` takes).
        source: File the state was read from (relative robot paths were made absolute, so the
            state can be saved anywhere).
    """

    __slots__ = ("_raw", "robot_reader", "scenario", "source")

    def __init__(
        self,
        raw: Mapping[str, Any],
        source: str | None = None,
        robot_reader: RobotFileReader | None = None,
    ):
        data = plain(copy.deepcopy(dict(raw)))
        self.scenario: Scenario = scenario_from_dict(data, source).with_robot_reader(robot_reader)
        self._raw: dict[str, Any] = data
        self.source = source
        #: How the scenario's robot files are read (the workspace's reader for a workspace
        #: file; kept by every edit), or None.
        self.robot_reader = robot_reader

    # -- construction -------------------------------------------------------------------
    @classmethod
    def from_scenario(cls, scenario: Scenario) -> GuiState:
        """The state of an already validated scenario (the keys it was given, no defaults added)."""
        raw = scenario.model_dump(mode="json", exclude_unset=True)
        if isinstance(scenario.robot, RobotFiles) and scenario.source:
            # Relative robot paths are relative to the scenario file: make them absolute so a
            # state saved elsewhere still finds its robot.
            base = Path(scenario.source).parent
            files = raw["robot"]
            files["urdf"] = str((base / scenario.robot.urdf).resolve())
            if scenario.robot.srdf:
                files["srdf"] = str((base / scenario.robot.srdf).resolve())
        return cls(raw, scenario.source, scenario.robot_reader)

    @classmethod
    def from_file(cls, name_or_path: str | Path = DEFAULT_SCENARIO) -> GuiState:
        """Read a scenario file or a bundled scenario by name (``extends`` resolved).

        Raises:
            ScenarioError: The file cannot be read or is not a valid scenario.
        """
        return cls.from_scenario(load_scenario(name_or_path))

    # -- reading ------------------------------------------------------------------------
    @property
    def raw(self) -> dict[str, Any]:
        """A deep copy of the scenario mapping."""
        return copy.deepcopy(self._raw)

    def get(self, path: FieldPath, default: Any = None) -> Any:
        """The value at ``path`` in the mapping (a copy), or ``default`` when absent."""
        node: Any = self._raw
        for part in path:
            try:
                node = node[part]
            except (KeyError, IndexError, TypeError):
                return default
        return copy.deepcopy(node)

    def to_yaml(self) -> str:
        """The scenario as YAML, in the schema of the scenario files."""
        text: str = yaml.safe_dump(self._raw, sort_keys=False, default_flow_style=None, width=100)
        return text

    def save(self, path: str | Path) -> Path:
        """Write :meth:`to_yaml` to ``path`` (folders created).

        For scripts: anywhere, no confirmation. The GUI never calls it; it saves through its
        workspace (:meth:`impact_balance.gui.files.GuiFiles.save`).

        Raises:
            ScenarioError: The name does not end with ``.yaml``/``.yml``, or it cannot be written.
        """
        path = Path(path).expanduser()
        if path.suffix not in (".yaml", ".yml"):
            raise ScenarioError(
                "file", str(path), "a scenario file name must end with .yaml or .yml"
            )
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(self.to_yaml())
        except OSError as exc:
            raise ScenarioError("file", str(path), f"cannot write: {exc.strerror or exc}") from None
        return path

    def saved_as(self, file_name: str) -> GuiState:
        """This state as saved to ``file_name``: named after the file's stem.

        When the stem changes the name, the ``description`` says which scenario it was edited
        from (``edited from NAME: DESCRIPTION``, cut to the schema's length limit).

        Args:
            file_name: The file's name (a path; its stem is the new name).

        Raises:
            ScenarioError: The stem is not a valid scenario name (too long).
        """
        stem = Path(str(file_name)).stem
        old_name = self._raw.get("name")
        if stem == old_name or not stem:
            return self
        changes: dict[FieldPath, Any] = {("name",): stem}
        if old_name:
            old = self._raw.get("description")
            text = f"edited from {old_name}" + (f": {old}" if old else "")
            changes[("description",)] = text[:MAX_DESCRIPTION]
        return self.with_changes(changes)

    # -- editing ------------------------------------------------------------------------
    def with_value(self, path: FieldPath, value: Any) -> GuiState:
        """A new state with ``value`` at ``path`` (None removes the key)."""
        return self.with_changes({path: value})

    def with_changes(
        self, changes: Mapping[FieldPath, Any] | Iterable[tuple[FieldPath, Any]]
    ) -> GuiState:
        """A new state with every change applied (None at a path removes the key).

        Changes are applied in order, then the whole mapping is validated once.

        Args:
            changes: ``{path: value}``, or (path, value) pairs.

        Returns:
            The new state; this one is unchanged.

        Raises:
            ScenarioError: A value is not finite, a path does not exist, or the result is not a
                valid scenario (naming the field).
        """
        items = list(changes.items()) if isinstance(changes, Mapping) else list(changes)
        raw = copy.deepcopy(self._raw)
        for path, value in items:
            path = tuple(path)
            value = plain(value)
            _check_finite(path, value)
            _set(raw, path, value)
        return GuiState(raw, self.source, self.robot_reader)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GuiState) and self._raw == other._raw

    def __repr__(self) -> str:
        contacts = len(self._raw.get("contacts", []))
        return f"GuiState({self.scenario.name or 'unnamed'!r}, {contacts} contacts)"
