"""Every file the GUI reads or writes, through the workspace rule (:mod:`.workspace`).

- load: a bundled scenario by name, or a ``.yaml`` file of the workspace, read through the
  workspace folder's descriptors (no link followed, a regular file only, bounded) and parsed from
  the bytes read, never from a second read of the path;
- ``extends:`` in a loaded or uploaded file: a bundled name or a workspace file;
- ``robot: {urdf, srdf}`` in a loaded or uploaded file: workspace files (``.urdf``/``.srdf``);
- upload: at most :data:`~impact_balance.gui.workspace.MAX_FILE_BYTES`, parsed like a file;
- save: a workspace name, an existing file replaced only with ``overwrite``.

:func:`describe` turns an error into the line the browser shows: the file, the field, the
reason, and the value only cut short (at most 80 characters) and never for an unknown key,
whose value is content of a file that is not a scenario.
"""

from __future__ import annotations

import functools
import reprlib
from importlib import resources
from pathlib import Path

from impact_balance.exceptions import (
    ImpactBalanceError,
    ScenarioError,
    UnknownScenarioError,
    WorkspaceError,
)
from impact_balance.gui.state import GuiState
from impact_balance.gui.workspace import MAX_FILE_BYTES, Workspace
from impact_balance.robot.urdf_check import MAX_ROBOT_FILE_BYTES
from impact_balance.scenario import (
    ExtendsResolver,
    FileReader,
    RobotFiles,
    Scenario,
    bundled_scenarios,
    load_scenario,
)
from impact_balance.scenario.reader import read_text

__all__ = ["MAX_MESSAGE", "GuiFiles", "bundled_path", "describe"]

#: The folder an upload is named in (never created nor opened: the upload is read from memory).
_UPLOADS = Path("/.impact-balance-upload")

#: Longest message shown in the browser, characters.
MAX_MESSAGE = 300
_VALUE = reprlib.Repr()
_VALUE.maxlevel, _VALUE.maxdict, _VALUE.maxlist, _VALUE.maxtuple = 2, 4, 6, 6
_VALUE.maxstring = _VALUE.maxother = 70


def _short(value: object, limit: int = 80) -> str:
    """``repr(value)`` bounded in time and length (reprlib stops early on huge or deep values)."""
    text = _VALUE.repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


@functools.lru_cache(maxsize=1)
def _bundled_names() -> frozenset[str]:
    return frozenset(bundled_scenarios())


def bundled_path(name: str) -> Path | None:
    """The file of the bundled scenario ``name``, None if there is no such bundled scenario."""
    if name not in _bundled_names():
        return None
    return Path(str(resources.files("impact_balance") / "scenarios" / f"{name}.yaml"))


def describe(exc: BaseException, workspace: Workspace | None = None) -> str:
    """The one line the GUI shows for a refused load, save or edit (no file content)."""
    if isinstance(exc, ScenarioError):
        source = exc.source
        if source and workspace is not None:
            source = workspace.relative(source) or Path(source).name
        where = f"{source}: " if source else ""
        if str(exc.reason).startswith("unknown key") or exc.value is None:
            text = f"{where}{exc.field}: {exc.reason}"
        else:
            text = f"{where}{exc.field} = {_short(exc.value)}: {exc.reason}"
        text = " ".join(text.split())  # one line
    elif isinstance(exc, ImpactBalanceError):
        text = " ".join(str(exc).split())
    else:  # the command line's rule (impact_balance.exit_status): a YAML, OS or other error
        from impact_balance.exit_status import describe_error

        line, _ = describe_error(
            exc, quote=False
        )  # never a third party's text: it may quote a file
        text = line.split("; rerun with --debug")[0]
    return text if len(text) <= MAX_MESSAGE else text[: MAX_MESSAGE - 3] + "..."


def _load(path: Path, resolve: ExtendsResolver, shown: str, read: FileReader) -> Scenario:
    """:func:`load_scenario` with a last net: a file nested too deeply for Python is refused."""
    try:
        return load_scenario(path, resolve_path=resolve, read_file=read)
    except RecursionError:
        raise ScenarioError("scenario", shown, "nested too deeply", shown) from None


class GuiFiles:
    """Loads, uploads and saves of one GUI, confined to one workspace.

    Attributes:
        workspace: The folder.
    """

    def __init__(self, workspace: Workspace | str | Path = "."):
        self.workspace = workspace if isinstance(workspace, Workspace) else Workspace(workspace)

    def _extends(self, name: str, referrer: Path) -> Path:
        return self.workspace.extends_resolver(bundled_path)(name, referrer)

    def _reader(self, upload: Path | None = None, text: str = "") -> FileReader:
        """How a load reads each file.

        A workspace file through the workspace's descriptors (:meth:`Workspace.read_text`: no
        link, a regular file, bounded), a bundled one through
        :func:`~impact_balance.scenario.reader.read_text`, the upload from its bytes.
        """

        def read(path: Path) -> str:
            if upload is not None and path == upload:
                return text
            name = self.workspace.relative(path)
            if name is None:  # the extends resolver gives bundled files or workspace files only
                return read_text(path)
            return self.workspace.read_text(name)

        return read

    def _robot_files(self, scenario: Scenario, folder: Path) -> Scenario:
        """``scenario`` with its robot files checked against the workspace and made absolute.

        Relative paths are taken from ``folder`` (the loaded file's, the workspace's for an upload).
        """
        robot = scenario.robot
        if not isinstance(robot, RobotFiles):
            return scenario

        def check(value: str, field: str, suffix: str) -> str:
            name = self.workspace.relative(folder / value)
            if name is None:
                raise WorkspaceError(field, value, f"outside the workspace {self.workspace.root}")
            return str(self.workspace.resolve(name, field=field, suffixes=(suffix,)))

        files = RobotFiles(
            urdf=check(robot.urdf, "robot.urdf", ".urdf"),
            srdf=check(robot.srdf, "robot.srdf", ".srdf") if robot.srdf else None,
            standing=robot.standing,
        )
        return scenario.model_copy(update={"robot": files}).with_robot_reader(self._read_robot)

    def _read_robot(self, path: Path) -> bytes:
        """A robot file's bytes, read through the workspace every time it is loaded.

        No link is followed (see :meth:`~impact_balance.gui.workspace.Workspace.read_bytes`).

        Raises:
            WorkspaceError: Outside the workspace, a link, not a regular file, or too large.
        """
        try:  # lexically: the path the load checked, never a link's target
            name = Path(path).relative_to(self.workspace.root)
        except ValueError:
            where = f"outside the workspace {self.workspace.root}"
            raise WorkspaceError("robot file", str(path), where) from None
        return self.workspace.read_bytes(
            name, field="robot file", suffixes=(".urdf", ".srdf"), limit=MAX_ROBOT_FILE_BYTES
        )

    # -- loads ------------------------------------------------------------------------------
    def load(self, name: str) -> GuiState:
        """A bundled scenario (a name without suffix) or a workspace ``.yaml``/``.yml`` file.

        Raises:
            UnknownScenarioError: No bundled scenario has that name.
            WorkspaceError: The file, an ``extends`` or a robot file breaks the workspace rule.
            ScenarioError: The file is not a valid scenario.
        """
        name = str(name)
        if not name.lower().endswith((".yaml", ".yml")):
            path = bundled_path(name)
            if path is None:
                raise UnknownScenarioError(
                    "scenario",
                    name if len(name) <= 80 else name[:77] + "...",
                    sorted(_bundled_names()),
                )
            return GuiState.from_file(path)
        path = self.workspace.resolve(name)
        scenario = _load(path, self._extends, name, self._reader())
        return GuiState.from_scenario(self._robot_files(scenario, path.parent))

    def upload(self, filename: str, content: bytes) -> GuiState:
        """A scenario from an uploaded file's bytes; ``extends`` and robot files from the workspace.

        Args:
            filename: The name the browser gave (only its last part is kept, for messages).
            content: The file's bytes (at most :data:`~.workspace.MAX_FILE_BYTES`, UTF-8).

        Returns:
            The state, its source the shown file name.

        Raises:
            ScenarioError: Too large, not UTF-8 text, or not a valid scenario.
            WorkspaceError: An ``extends`` or robot file outside the workspace or refused by its
                rule.
        """
        shown = Path(str(filename).replace("\\", "/")).name[:80] or "uploaded.yaml"
        if len(content) > MAX_FILE_BYTES:
            raise ScenarioError("upload", shown, f"larger than {MAX_FILE_BYTES >> 10} KiB")
        try:
            text = content.decode("utf-8")
        except UnicodeDecodeError:
            raise ScenarioError("upload", shown, "not a UTF-8 text file") from None
        stem = (
            "".join(c if c.isalnum() or c in "-_." else "_" for c in Path(shown).stem)[:80]
            or "uploaded"
        )
        # The loader takes a path (it resolves `extends`, names the file in errors): the upload
        # gets a name outside the workspace that is never opened, its reader serves the bytes.
        path = _UPLOADS / f"{stem}.yaml"
        try:
            scenario = _load(path, self._extends, shown, self._reader(path, text))
        except ScenarioError as exc:
            value = shown if exc.value == str(path) else exc.value
            raise ScenarioError(exc.field, value, exc.reason, shown) from None
        scenario = self._robot_files(scenario, self.workspace.root)
        state = GuiState.from_scenario(scenario)
        return GuiState(state.raw, shown, robot_reader=state.robot_reader)

    # -- saves ------------------------------------------------------------------------------
    def save(self, state: GuiState, name: str, overwrite: bool = False) -> Path:
        """Write ``state`` as a scenario file to the workspace.

        Args:
            state: The state to write.
            name: The file's name, relative to the workspace (``.yaml`` or ``.yml``).
            overwrite: Replace an existing file (else it is refused).

        Returns:
            The file's path.

        Raises:
            WorkspaceError: The name breaks the workspace rule, the file exists without
                ``overwrite``, or it cannot be written.
        """
        return self.workspace.write_text(name, state.to_yaml(), overwrite=overwrite)
