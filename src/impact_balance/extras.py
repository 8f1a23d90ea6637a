"""Optional parts of impact-balance (pip extras), and the check that names a missing one.

The core (``import impact_balance; impact_balance.analyze(...)``, and the commands ``analyze``,
``demo``, ``phase-portrait``, ``scenarios``, ``robots``, ``frames`` without figures) needs none
of them, so a controller can depend on ``impact-balance`` alone. ``pip install
'impact-balance[all]'`` installs every extra.

- ``plots`` (matplotlib): ``--plots`` / ``--plot`` of any command;
- ``logs`` (pandas, pyarrow): ``check-log``, ``--log``;
- ``sim`` (mujoco, imageio, imageio-ffmpeg, pandas, pyarrow, matplotlib): ``simulate``,
  ``validate``, ``push-test``, ``approach``;
- ``gui`` (viser, and trimesh, which it brings): ``gui``;
- ``sweep`` (dask.distributed, pandas, pyarrow, matplotlib): ``sweep`` (figures included);
- ``mink`` (mink, which brings MuJoCo): the governor's mink limit
  (:mod:`impact_balance.governor.mink_limit`), no command.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys

from impact_balance.exceptions import MissingExtraError

__all__ = ["COMMAND_EXTRAS", "EXTRAS", "OPTION_EXTRAS", "installed", "require", "require_for"]

#: Modules each extra installs (import names), as declared in pyproject.toml.
EXTRAS: dict[str, tuple[str, ...]] = {
    "plots": ("matplotlib",),
    "logs": ("pandas", "pyarrow"),
    "sim": ("mujoco", "imageio", "imageio_ffmpeg", "pandas", "pyarrow", "matplotlib"),
    "gui": ("viser",),
    "sweep": ("distributed", "pandas", "pyarrow", "matplotlib"),
    "mink": ("mink",),
}

#: The extra each command needs, whatever its options.
COMMAND_EXTRAS: dict[str, str] = {
    "simulate": "sim",
    "validate": "sim",
    "push-test": "sim",
    "calibrate": "sim",
    "approach": "sim",
    "check-log": "logs",
    "gui": "gui",
    "sweep": "sweep",
}

#: Options (argparse destinations) that need an extra when given: figures and logs.
OPTION_EXTRAS: dict[str, tuple[str, str]] = {
    "plots": ("--plots", "plots"),
    "plot": ("--plot", "plots"),
    "plots_dir": ("--plots", "plots"),
    "log": ("--log", "logs"),
}


def installed(module: str) -> bool:
    """Whether ``module`` can be imported, without importing it.

    A blocked import (a ``None`` in ``sys.modules``) counts as missing.
    """
    if module in sys.modules:
        return sys.modules[module] is not None
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def require(extra: str, what: str) -> None:
    """:class:`MissingExtraError` naming ``extra`` if one of its modules is not installed.

    Checked without importing them: ``sweep --list`` must not pay for importing Dask.
    """
    missing = [name for name in EXTRAS[extra] if not installed(name)]
    if missing:
        raise MissingExtraError(what, extra, missing)


def require_for(command: str, args: argparse.Namespace) -> None:
    """Check the extras a command line needs (the command's own, then its options')."""
    if command in COMMAND_EXTRAS:
        require(COMMAND_EXTRAS[command], command)
    if command == "demo" and not getattr(args, "no_plots", True):
        require("plots", "demo (its figures; --no-plots skips them)")
    for dest, (option, extra) in OPTION_EXTRAS.items():
        if getattr(args, dest, None):
            require(extra, f"{command} {option}")
