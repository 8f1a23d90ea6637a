"""The web GUI: a viser server with the 3D scene, the 2D view and the controls.

Wiring only: the parts (:mod:`.viser_scene`, :mod:`.gizmos`, :mod:`.panels`,
:mod:`.scenario_tab`, on the base of :mod:`.host`) build their widgets; every control edits the
:class:`~.session.Session` (all-or-nothing), then :meth:`GuiApp.refresh` puts the widgets back
in line with the session (a refused value reverts), and redraws the robot, the scene objects
of :mod:`.scene` and the SVG of :mod:`.view2d`. Callbacks come from viser's thread pool; the
session's lock makes them one-at-a-time. Gizmo drags are coalesced: only the latest pose of a
burst is solved.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from impact_balance.gui.gizmos import GizmoMixin
from impact_balance.gui.guard import AccessPolicy, guarded_start
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

if TYPE_CHECKING:
    import viser

__all__ = ["SHARED_SESSION_NOTE", "GuiApp", "GuiError", "run"]

#: Shown on the page under the numbers: every tab and browser connected to one server edits the
#: same session (one scenario, one analysis); an edit in one shows in all.
SHARED_SESSION_NOTE = (
    '<div id="ib-shared-session" style="color:#555;font-size:0.8em;margin:2px 0 4px 0">'
    "One shared session: every browser tab open on this server shows and edits the same "
    "scenario (an edit in one tab shows in all). Start another <code>impact-balance gui "
    "--port</code> for a separate one.</div>"
)


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
        uploads: The upload limit in front of viser's upload handlers (see :mod:`.uploads`).
        update_times_ms: Recent update times (edit + analysis + redraw), ms.
        last_update_ms: The last update's time, ms (NaN before the first).

    Raises:
        GuiError: The server cannot listen there, or this viser version does not let the
            Host/Origin check or the upload limit be installed (it does not serve unguarded).
    """

    w_results: viser.GuiHtmlHandle
    w_com_reach: viser.GuiButtonHandle
    w_held_stance: viser.GuiButtonHandle
    w_shared_session: viser.GuiHtmlHandle
    w_view2d: viser.GuiHtmlHandle

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
        self._scene_handles = {}
        self._scene_data = {}
        self._gizmos = {}
        self._dragging = None
        self._drag_pending = set()
        self._drag_lock = threading.Lock()
        self._drag_busy = threading.Lock()
        self._impact_stash = None
        self._contact_index = 0
        self._meshes = None
        self._robot = None
        self._joint_widgets = {}
        self._joint_folders = []
        self._setup_scene()
        self._build_gui()
        with self.session.lock:
            self._draw_robot(self.w_opacity.value)  # reads the meshes (seconds): not timed
            self.refresh()

    # -- life cycle -----------------------------------------------------------------------
    @property
    def url(self) -> str:
        """The page's address, ``http://host:port`` (127.0.0.1 for a bind to every interface)."""
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

    # -- layout ---------------------------------------------------------------------------
    def _build_gui(self) -> None:
        """The panels: the numbers and four tabs on the left, the 2D view on the right."""
        gui = self.server.gui
        # No share button: sharing goes through viser's public relay, and this server is local.
        gui.configure_theme(
            control_width="large", dark_mode=False, show_logo=False, show_share_button=False
        )
        gui.set_panel_label("impact-balance")
        self.w_results = gui.add_html("")
        self.w_shared_session = gui.add_html(SHARED_SESSION_NOTE)
        # On demand only (whole-body IK, seconds): cleared by an edit that changes the stance.
        self.w_com_reach = gui.add_button(
            "CoM reach",
            hint="Compute how far the CoM moves at its height with every contact kept (a few "
            "seconds) and draw it; an edit that moves the stance clears it",
        )
        self.w_com_reach.on_click(self._on_com_reach)
        self.w_held_stance = gui.add_button(
            "Held stance",
            hint="Compute the maximum contact velocity by the held-stance impact model (the "
            "paper's answer where its fixed point is not reached); any edit clears it",
        )
        self.w_held_stance.on_click(self._on_held_stance)
        tabs = gui.add_tab_group()
        with tabs.add_tab("Impact"):
            self._build_impact()
        with tabs.add_tab("Contacts"):
            self._build_contacts()
        self._joints_tab = tabs.add_tab("Joints")
        with self._joints_tab:
            self._build_base()
        with tabs.add_tab("Scenario"):
            self._build_scenario()
        panel = gui.add_panel()
        with panel.add_tab("2D view"):
            self.w_view2d = gui.add_html("")
        gui.main_panel.dock_left()
        gui.main_panel.set_width(400)
        panel.dock_right()
        panel.set_width(440)

    def _on_com_reach(self, _: object) -> None:
        """The "CoM reach" button: compute the reach of the current stance, then redraw."""
        self.edit(lambda: self.session.compute_reach())

    def _on_held_stance(self, _: object) -> None:
        """The "Held stance" button: the held-stance maximum of the current analysis, shown."""
        self.edit(lambda: self.session.compute_held_stance())

    # -- refresh: widgets <- session, then redraw ----------------------------------------
    def refresh(self, t0: float | None = None) -> None:
        """Put every widget in line with the session and redraw (call with the session lock held).

        Args:
            t0: ``time.perf_counter()`` when the update began (now if None), for its timing.
        """
        t0 = time.perf_counter() if t0 is None else t0
        self._syncing = True
        try:
            with self.server.atomic():
                self._sync_panels()
                self._sync_scenario_tab()
                self._draw_robot(self.w_opacity.value)
                self._draw_objects()
                self._draw_gizmos(bool(self.w_gizmos.value))
                reach = self.session.reach
                self.w_view2d.content = svg_view(
                    self.session.analysis, reach=None if reach is None else reach.reach
                )
                self.last_update_ms = 1e3 * (time.perf_counter() - t0)
                self.update_times_ms.append(self.last_update_ms)
                self.w_results.content = self._results_html()
        finally:
            self._syncing = False
        self._robot = self.session.analysis.stance.robot

    def _results_html(self) -> str:
        """The numbers panel for the session and the last update's time."""
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
        host: Interface to bind (default: localhost only).
        port: TCP port (0 picks a free one).
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
