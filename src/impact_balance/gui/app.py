"""The web GUI: a viser server with the 3D scene, the 2D view and the controls.

Wiring only: every control edits the :class:`~.session.Session` (all-or-nothing), then
:meth:`GuiApp.refresh` puts the widgets back in line with the session (a refused value
reverts), and redraws the robot, the scene objects of :mod:`.scene` and the SVG of
:mod:`.view2d`. Callbacks come from viser's thread pool; the session's lock makes them
one-at-a-time. Gizmo drags are coalesced: only the latest pose of a burst is solved.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from impact_balance.gui.gizmos import GizmoMixin
from impact_balance.gui.guard import AccessPolicy, guarded_start
from impact_balance.gui.meshes import RobotMeshes
from impact_balance.gui.panels import PanelsMixin
from impact_balance.gui.results import results_html
from impact_balance.gui.scenario_tab import ScenarioTabMixin
from impact_balance.gui.server import GuiError, check_listen_address
from impact_balance.gui.session import Session
from impact_balance.gui.state import DEFAULT_SCENARIO, GuiState
from impact_balance.gui.uploads import limit_uploads
from impact_balance.gui.view2d import svg_view
from impact_balance.gui.viser_scene import SceneMixin
from impact_balance.gui.workspace import Workspace

__all__ = ["GuiApp", "GuiError", "run"]


class GuiApp(SceneMixin, GizmoMixin, PanelsMixin, ScenarioTabMixin):
    """The GUI server for one scenario.

    Args:
        scenario: A scenario file, a bundled name, or a :class:`GuiState`.
        host: Interface to bind (default: localhost only).
        port: TCP port; 0 picks a free one. viser moves to the next free port if it is taken.
        verbose: Let viser print its banner and logs.
        workspace: The only folder the GUI loads from and saves to (see :mod:`.files`).
        allow_origins: Origins allowed besides the page's own (see :mod:`.guard`).

    Attributes:
        session: The model (state, analysis).
        server: The :class:`viser.ViserServer`.
        policy: Which Host and Origin headers the server answers.
        update_times_ms: Recent update times (edit + analysis + redraw), ms.
    """

    def __init__(
        self,
        scenario: str | Path | GuiState = DEFAULT_SCENARIO,
        host: str = "127.0.0.1",
        port: int = 8080,
        verbose: bool = False,
        workspace: Workspace | str | Path = ".",
        allow_origins: tuple[str, ...] | list[str] = (),
    ):
        import viser

        check_listen_address(host, port)
        self.policy = AccessPolicy.for_bind(host, allow_origins)
        self.session = Session(scenario, workspace)
        with guarded_start(self.policy) as started:
            self.server = viser.ViserServer(
                host=host, port=port, label="impact-balance", verbose=verbose
            )
        if not started:  # a viser that starts its server another way: do not serve unguarded
            self.server.stop()
            raise GuiError(host, port, "cannot install the Host/Origin check on this viser version")
        try:  # uploads counted as they arrive (a viser without the expected handlers: do not serve)
            self.uploads = limit_uploads(self.server, self._upload_refused)
        except Exception:
            self.server.stop()
            raise GuiError(
                host, port, "cannot install the upload limit on this viser version"
            ) from None
        self.update_times_ms: deque[float] = deque(maxlen=500)
        self.last_update_ms = float("nan")
        self._syncing = False
        self._scene_handles: dict[str, Any] = {}
        self._scene_data: dict[str, tuple[Any, tuple[np.ndarray, ...]]] = {}
        self._gizmos: dict[str, Any] = {}
        self._dragging: str | None = None
        self._drag_pending: set[str] = set()
        self._drag_lock = threading.Lock()
        self._drag_busy = threading.Lock()
        self._impact_stash: dict | None = None
        self._contact_index = 0
        self._meshes: RobotMeshes | None = None
        self._robot = None
        self._joint_widgets: dict[str, Any] = {}
        self._joint_folders: list[Any] = []
        self._setup_scene()
        self._build_gui()
        with self.session.lock:
            self._draw_robot()  # reads the meshes (seconds): not part of an update's time
            self.refresh()

    # -- life cycle -----------------------------------------------------------------------
    @property
    def workspace(self) -> Workspace:
        """The folder the GUI loads from and saves to."""
        return self.session.files.workspace

    @property
    def url(self) -> str:
        host = self.server.get_host()
        host = "127.0.0.1" if host in ("0.0.0.0", "") else host
        if ":" in host:
            host = f"[{host}]"
        return f"http://{host}:{self.server.get_port()}"

    def stop(self) -> None:
        """Stop the server (its thread ends)."""
        self.server.stop()

    def _upload_refused(self, filename: str, reason: str) -> None:
        """An upload cut while it arrived (see :mod:`.uploads`): shown like a refused edit."""
        self.edit(lambda: self.session.refuse(f"upload {filename}: {reason}"))

    # -- edits ----------------------------------------------------------------------------
    def edit(self, apply: Callable[[], Any]) -> None:
        """Run one edit of the session, then refresh the widgets and redraw."""
        with self.session.lock:
            if self._syncing:  # a callback fired by refresh() setting a widget: not an edit
                return
            t0 = time.perf_counter()
            try:
                apply()
            except (
                ValueError,
                TypeError,
                OverflowError,
            ) as exc:  # a value that cannot even be converted
                self.session.message, self.session.refused = f"bad value: {exc}", True
            self.refresh(t0)

    def _field(
        self, path: tuple, convert: Callable[[Any], Any] = lambda v: v
    ) -> Callable[[Any], None]:
        """A widget callback that sets one scenario field."""

        def callback(event: Any) -> None:
            # Read the value when the edit runs, not when the event came: callbacks of a fast
            # slider run in a thread pool, in any order, and the last one must apply the last value.
            self.edit(lambda: self.session.set(path, convert(event.target.value)))

        return callback

    # -- refresh: widgets <- session, then redraw ----------------------------------------
    def refresh(self, t0: float | None = None) -> None:
        """Put every widget in line with the session and redraw (call with the session lock held)."""
        t0 = time.perf_counter() if t0 is None else t0
        self._syncing = True
        try:
            with self.server.atomic():
                self._sync_widgets()
                self._draw_robot()
                self._draw_objects()
                self._draw_gizmos()
                self.w_view2d.content = svg_view(self.session.analysis)
                self.last_update_ms = 1e3 * (time.perf_counter() - t0)
                self.update_times_ms.append(self.last_update_ms)
                self.w_results.content = self._results_html()
        finally:
            self._syncing = False
        self._robot = self.session.analysis.stance.robot

    def _results_html(self) -> str:
        return results_html(self.session, self.last_update_ms)


def run(
    scenario: str | Path = DEFAULT_SCENARIO,
    host: str = "127.0.0.1",
    port: int = 8080,
    ready: Callable[[GuiApp], None] | None = None,
    stop: threading.Event | None = None,
    workspace: Workspace | str | Path = ".",
    allow_origins: tuple[str, ...] | list[str] = (),
) -> None:
    """Start the GUI and serve until Ctrl-C, SIGTERM, or ``stop`` is set.

    Args:
        scenario: Scenario file or bundled name (read as given: it comes from the command line).
        host, port: Where to listen.
        ready: Called with the app once it serves (the CLI prints the URL there).
        stop: Optional event that ends the loop (for tests).
        workspace: The folder the GUI loads from and saves to.
        allow_origins: Origins allowed besides the page's own.
    """
    import signal

    stop = stop or threading.Event()
    previous = None
    if threading.current_thread() is threading.main_thread():
        # SIGTERM ends the process at once, by the system's default action: a Python handler
        # would wait for the main thread, which cannot run while a worker holds the interpreter
        # (a long parse), and interpreter exit would wait for busy workers. Nothing is lost: the
        # GUI keeps no unsaved files, and a save replaces its file in one step.
        previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    app = GuiApp(scenario, host=host, port=port, workspace=workspace, allow_origins=allow_origins)
    try:
        if ready is not None:
            ready(app)
        while not stop.wait(0.2):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
