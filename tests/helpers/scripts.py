"""Load a study script (``studies/<name>.py``, not a package module) as a module."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

__all__ = ["STUDIES", "load_study"]

#: The repository's ``studies/`` folder.
STUDIES = Path(__file__).resolve().parents[2] / "studies"


def load_study(name: str) -> ModuleType:
    """``studies/<name>.py`` as a module, registered in ``sys.modules`` (its dataclasses look
    their module up there)."""
    spec = importlib.util.spec_from_file_location(name, STUDIES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module
