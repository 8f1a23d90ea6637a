"""The scenarios shipped with the package (``impact_balance/scenarios/*.yaml``) and name lookup."""

from __future__ import annotations

import functools
import os
from importlib import resources
from pathlib import Path

import yaml

from impact_balance.exceptions import ScenarioError, UnknownScenarioError
from impact_balance.scenario.reader import check_path_text

__all__ = ["bundled_descriptions", "bundled_scenarios", "scenario_path"]


@functools.cache
def _scenario_dir() -> Path:
    # Cached: importlib.resources' lookup costs more than reading a cached scenario.
    return Path(str(resources.files("impact_balance") / "scenarios"))


def bundled_descriptions(folder: str) -> dict[str, str]:
    """The ``*.yaml`` files of the package data folder ``impact_balance/<folder>``.

    Returns:
        Name -> one-line description.
    """
    out = {}
    for entry in sorted(
        (resources.files("impact_balance") / folder).iterdir(), key=lambda e: e.name
    ):
        if entry.name.endswith(".yaml"):
            raw = yaml.safe_load(entry.read_text()) or {}
            out[entry.name[:-5]] = str(raw.get("description", "")).strip()
    return out


def bundled_scenarios() -> dict[str, str]:
    """Bundled scenario names and their one-line descriptions."""
    return bundled_descriptions("scenarios")


def scenario_path(name_or_path: str | Path) -> Path:
    """A scenario file's path: an existing file, or the name of a bundled scenario.

    A path that names something else (a FIFO, a device, a folder) is returned as is: reading it
    refuses it with what it is (:func:`impact_balance.files.read_bounded`).
    """
    check_path_text("scenario", str(name_or_path))
    path = Path(name_or_path)
    if _is_file(path):
        return path
    if path.suffix in (".yaml", ".yml") or "/" in str(name_or_path) or "\\" in str(name_or_path):
        if _exists(path):  # a FIFO, a device, a folder: the reader refuses it, naming what it is
            return path
        raise ScenarioError("scenario", str(name_or_path), "no such file")
    bundled = _scenario_dir() / f"{name_or_path}.yaml"
    if _is_file(bundled):
        return bundled
    raise UnknownScenarioError(
        "scenario", str(name_or_path), list(bundled_scenarios()), listing="impact-balance scenarios"
    )


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):  # a name the OS refuses is simply not an existing file
        return False


def _exists(path: Path) -> bool:
    try:
        return os.path.lexists(path)
    except (OSError, ValueError):
        return False
