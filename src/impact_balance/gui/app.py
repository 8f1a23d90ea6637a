"""The web GUI: a viser server with the 3D scene, the 2D view and the controls.

Wiring only: every control edits the :class:`~.session.Session` (all-or-nothing), then
:meth:`GuiApp.refresh` puts the widgets back in line with the session (a refused value
reverts), and redraws the robot, the scene objects of :mod:`.scene` and the SVG of
:mod:`.view2d`. Callbacks come from viser's thread pool; the session's lock makes them
one-at-a-time. Gizmo drags are coalesced: only the latest pose of a burst is solved.
"""

from __future__ import annotations

import asyncio
import html
import logging
import os
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from ..exceptions import ImpactBalanceError
from ..scenario import bundled_scenarios
from ..workspace import Workspace
from .drag import DragTarget, handle_pose
from .guard import AccessPolicy, guarded_start
from .limbs import joint_groups, joint_values
from .meshes import RobotMeshes
from .scene import Arrows, Label, Points, Segments, Surface, scene_objects
from .session import Session, format_speed
from .state import DEFAULT_SCENARIO, GuiState
from .view2d import svg_view

__all__ = ["GuiApp", "GuiError", "run"]

log = logging.getLogger(__name__)

#: Frame offered first for a new impact (if the robot has it).
_DEFAULT_IMPACT_FRAMES = ("gripper_right_base_link", "right_wrist_yaw_link", "r_hand")


class GuiError(ImpactBalanceError):
    """The GUI server cannot start (a host it cannot listen on, a bad port).

    Attributes:
        host, port: Where it was asked to listen.
    """

    def __init__(self, host: str, port: int, reason: str):
        self.host, self.port, self.reason = host, port, reason
        super().__init__(f"cannot serve on {host}:{port}: {reason}")


def check_listen_address(host: str, port: int) -> None:
    """Raise :class:`GuiError` unless ``host`` is an address of this machine and ``port`` valid.

    viser retries the next port on any bind error, so an address that can never be bound
    would make it loop for ever: check it first.
    """
    import socket

    if not 0 <= int(port) <= 65535:
        raise GuiError(host, port, "the port must be in 0..65535")
    try:
        infos = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        raise GuiError(host, port, f"unknown host ({getattr(exc, 'strerror', None) or exc})") from None
    family, _, _, _, address = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        try:
            sock.bind((address[0], 0))
        except OSError as exc:
            raise GuiError(host, port, f"not an address of this machine ({exc.strerror or exc})") from None


def _rgb(color: str) -> tuple[int, int, int]:
    c = color.lstrip("#")
    return int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)


def _wxyz(rotation: np.ndarray) -> np.ndarray:
    x, y, z, w = pin.Quaternion(np.asarray(rotation)).coeffs()
    return np.array([w, x, y, z])


def _vec(values: Any, n: int) -> tuple[float, ...]:
    return tuple(float(v) for v in list(values)[:n])


def _geometry(obj: Any) -> tuple[np.ndarray, ...] | None:
    """The arrays viser gets for a scene object (float32, as sent), None if there is nothing to draw."""
    if isinstance(obj, Segments):
        return (np.asarray(obj.segments, dtype=np.float32),) if len(obj.segments) else None
    if isinstance(obj, Points):
        return (np.asarray(obj.points[0], dtype=np.float32),)
    if isinstance(obj, Arrows):
        return (np.stack([obj.starts, obj.ends], axis=1).astype(np.float32),)
    if isinstance(obj, Surface):
        return np.asarray(obj.vertices, dtype=np.float32), np.asarray(obj.faces, dtype=np.uint32)
    if isinstance(obj, Label):
        return (np.asarray(obj.position, dtype=np.float32),)
    return None


def _set_options(dropdown: Any, options: list[str]) -> None:
    """Set a dropdown's options only when they change (each assignment is a message)."""
    if tuple(dropdown.options) != tuple(options):
        dropdown.options = options


class GuiApp:
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

    def __init__(self, scenario: str | Path | GuiState = DEFAULT_SCENARIO, host: str = "127.0.0.1",
                 port: int = 8080, verbose: bool = False, workspace: Workspace | str | Path = ".",
                 allow_origins: tuple[str, ...] | list[str] = ()):
        import viser

        check_listen_address(host, port)
        self.policy = AccessPolicy.for_bind(host, allow_origins)
        self.session = Session(scenario, workspace)
        with guarded_start(self.policy) as started:
            self.server = viser.ViserServer(host=host, port=port, label="impact-balance", verbose=verbose)
        if not started:  # a viser that starts its server another way: do not serve unguarded
            self.server.stop()
            raise GuiError(host, port, "cannot install the Host/Origin check on this viser version")
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

    # -- edits ----------------------------------------------------------------------------
    def edit(self, apply: Callable[[], Any]) -> None:
        """Run one edit of the session, then refresh the widgets and redraw."""
        with self.session.lock:
            if self._syncing:  # a callback fired by refresh() setting a widget: not an edit
                return
            t0 = time.perf_counter()
            try:
                apply()
            except (ValueError, TypeError, OverflowError) as exc:  # a value that cannot even be converted
                self.session.message, self.session.refused = f"bad value: {exc}", True
            self.refresh(t0)

    def _field(self, path: tuple, convert: Callable[[Any], Any] = lambda v: v) -> Callable[[Any], None]:
        """A widget callback that sets one scenario field."""

        def callback(event: Any) -> None:
            # Read the value when the edit runs, not when the event came: callbacks of a fast
            # slider run in a thread pool, in any order, and the last one must apply the last value.
            self.edit(lambda: self.session.set(path, convert(event.target.value)))

        return callback

    # -- scene ----------------------------------------------------------------------------
    def _setup_scene(self) -> None:
        scene = self.server.scene
        scene.set_up_direction("+z")
        # No shadows: they cost a render pass per light, which software WebGL (no GPU, as on
        # this project's machines) pays on every redraw.
        scene.configure_default_lights(True, cast_shadow=False)
        scene.add_grid("/ground", width=4.0, height=4.0, cell_size=0.1, section_size=0.5, plane="xy",
                       shadow_opacity=0.0)
        self.server.initial_camera.position = (1.0, -1.9, 1.25)
        self.server.initial_camera.look_at = (0.1, 0.0, 0.6)

    def _draw_objects(self) -> None:
        """Draw :func:`scene_objects`: unchanged objects are skipped, changed ones updated in place."""
        scene = self.server.scene
        seen = set()
        for obj in scene_objects(self.session.analysis):
            name = f"/analysis/{obj.name}"
            data = _geometry(obj)
            if data is None:
                continue
            seen.add(name)
            previous = self._scene_data.get(name)
            if previous is not None and type(previous[0]) is type(obj):
                if all(a.shape == b.shape and np.array_equal(a, b) for a, b in zip(previous[1], data, strict=True)):
                    continue  # most objects do not move when one joint does: send nothing
                self._update_object(self._scene_handles[name], obj, data)
            else:
                if name in self._scene_handles:
                    self._scene_handles.pop(name).remove()
                self._scene_handles[name] = self._add_object(scene, name, obj, data)
            self._scene_data[name] = (obj, data)
        for name in list(self._scene_handles):
            if name not in seen:
                self._scene_handles.pop(name).remove()
                self._scene_data.pop(name, None)

    @staticmethod
    def _add_object(scene: Any, name: str, obj: Any, data: tuple[np.ndarray, ...]) -> Any:
        color = _rgb(obj.color)
        if isinstance(obj, Segments):
            return scene.add_line_segments(name, data[0], color, thickness=obj.width)
        if isinstance(obj, Points):
            return scene.add_icosphere(name, radius=obj.radius, color=color, subdivisions=2,
                                       position=tuple(data[0]), cast_shadow=False)
        if isinstance(obj, Arrows):
            return scene.add_arrows(name, data[0], color, shaft_radius=obj.radius,
                                    head_radius=2.5 * obj.radius, head_length=6 * obj.radius)
        if isinstance(obj, Label):
            return scene.add_label(name, obj.text, position=tuple(data[0]), anchor="bottom-left")
        return scene.add_mesh_simple(name, data[0], data[1], color=color, opacity=obj.opacity,
                                     side="double", cast_shadow=False, receive_shadow=False)

    @staticmethod
    def _update_object(handle: Any, obj: Any, data: tuple[np.ndarray, ...]) -> None:
        if isinstance(obj, (Segments, Arrows)):
            handle.points = data[0]
        elif isinstance(obj, (Points, Label)):
            handle.position = data[0]
        else:
            handle.vertices, handle.faces = data

    def _draw_robot(self) -> None:
        stance = self.session.analysis.stance
        if self._meshes is None or self._meshes.robot is not stance.robot:
            if self._meshes is not None:
                self._meshes.remove()
            self._meshes = RobotMeshes(self.server.scene, stance.robot, opacity=self.w_opacity.value)
        self._meshes.update(stance.data)

    def _drag_targets(self) -> dict[str, DragTarget]:
        n = len(self.session.analysis.stance.contacts)
        out = {f"contact{i}": DragTarget("contact", i) for i in range(n)}
        if self.session.analysis.impact is not None:
            out["impact"] = DragTarget("impact")
        return out

    def _draw_gizmos(self) -> None:
        targets = self._drag_targets() if self.w_gizmos.value else {}
        for key in list(self._gizmos):
            if key not in targets:
                self._gizmos.pop(key).remove()
        state, stance = self.session.state, self.session.analysis.stance
        for key, target in targets.items():
            pose = handle_pose(state, stance, target)
            gizmo = self._gizmos.get(key)
            if gizmo is None:
                gizmo = self.server.scene.add_transform_controls(
                    f"/gizmos/{key}", scale=0.18, line_width=2.0, depth_test=False,
                    position=pose.translation, wxyz=_wxyz(pose.rotation))
                gizmo.on_update(self._on_gizmo(key))
                self._gizmos[key] = gizmo
            elif key != self._dragging:
                gizmo.position = pose.translation
                gizmo.wxyz = _wxyz(pose.rotation)

    def _on_gizmo(self, key: str) -> Callable[[Any], Any]:
        # Async: viser runs it on its event loop, in order (start, update..., end). It only
        # records what is dragged; the IK runs in a worker thread so the loop stays free.
        async def callback(event: Any) -> None:
            with self._drag_lock:
                self._dragging = None if event.phase == "end" else key
                self._drag_pending.add(key)
            await asyncio.get_running_loop().run_in_executor(None, self._process_drags)

        return callback

    def _process_drags(self) -> None:
        """Solve the pending drags at the gizmos' latest poses: a burst of updates costs one IK."""
        while True:
            if not self._drag_busy.acquire(blocking=False):
                return  # another thread is solving; it will pick up what is pending
            try:
                while True:
                    with self._drag_lock:
                        if not self._drag_pending:
                            break
                        key = self._drag_pending.pop()
                    self.edit(lambda k=key: self._drag(k))
            finally:
                self._drag_busy.release()
            with self._drag_lock:
                if not self._drag_pending:
                    return

    def _drag(self, key: str) -> bool:
        gizmo, target = self._gizmos.get(key), self._drag_targets().get(key)
        if gizmo is None or target is None:
            return False
        pose = pin.SE3(pin.Quaternion(*np.asarray(gizmo.wxyz, dtype=float)).normalized().matrix(),
                       np.asarray(gizmo.position, dtype=float))
        return self.session.drag(target, pose)

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
        s = self.session.summary
        ok = s.headline == "balanced"
        color = "#2ca02c" if ok else "#d62728"
        rows = [
            f'<div id="ib-verdict" style="font-weight:bold;font-size:1.15em;color:{color}">{html.escape(s.headline.upper())}</div>',
        ]
        if not ok:
            rows.append(f'<div style="color:{color};font-size:0.85em">{html.escape(s.verdict)}</div>')
        rows.append('<table style="font-size:0.9em;margin-top:4px;width:100%">')
        rows.append('<tr><td colspan="2" style="color:#555">maximum contact velocity</td></tr>')
        rows.append(f'<tr><td>&nbsp;&nbsp;by the CoM criterion</td><td style="text-align:right"><b id="ib-vmax-com">'
                    f'{html.escape(format_speed(s.max_contact_velocity))}</b></td></tr>')
        rows.append(f'<tr><td>&nbsp;&nbsp;by the ZMP criterion</td><td style="text-align:right"><b id="ib-vmax-zmp">'
                    f'{html.escape(format_speed(s.zmp_max_contact_velocity))}</b></td></tr>')
        if s.reference_speed is not None:
            verdict = "falls" if s.falls_at_reference else "holds"
            rows.append(f'<tr><td>reference approach speed</td><td style="text-align:right" id="ib-reference">'
                        f'{s.reference_speed:.3f} m/s ({verdict})</td></tr>')
        rows.append(f'<tr><td>update (analysis + redraw)</td><td style="text-align:right" id="ib-update-ms">'
                    f'{self.last_update_ms:.1f} ms</td></tr>')
        rows.append("</table>")
        if s.warnings:
            items = "".join(f"<li>{html.escape(w if len(w) <= 300 else w[:297] + '...')}</li>" for w in s.warnings[:10])
            more = f"<li>... {len(s.warnings) - 10} more</li>" if len(s.warnings) > 10 else ""
            rows.append(f'<ul id="ib-warnings" class="ib-warning" style="color:#b36b00;font-size:0.85em;margin:4px 0;'
                        f'padding-left:1.2em;overflow-wrap:anywhere">{items}{more}</ul>')
        msg = self.session.message
        if msg:
            mcolor = "#d62728" if self.session.refused else "#555"
            prefix = "refused: " if self.session.refused else ""
            text = msg if len(msg) <= 400 else msg[:400] + "..."
            rows.append(f'<div id="ib-message" style="color:{mcolor};font-size:0.85em;margin-top:4px;'
                        f'overflow-wrap:anywhere">{html.escape(prefix + text)}</div>')
        return '<div style="padding:0 0.75em">' + "".join(rows) + "</div>"

    def _frame_options(self, current: list[str]) -> list[str]:
        model = self.session.analysis.stance.robot.model
        names = [f.name for f in model.frames if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)]
        return sorted(set(names) | {c for c in current if c})

    def _sync_widgets(self) -> None:
        state, analysis = self.session.state, self.session.analysis
        scenario, stance = state.scenario, analysis.stance
        if self._robot is not stance.robot:
            self._build_joint_sliders()
        # General.
        self.w_torque.value = bool(scenario.torque_limits)
        self.w_com_velocity.value = _vec(scenario.com_velocity, 2)
        self.w_plane.value = float(scenario.plane_height)
        # Base and joints (the actual values, whether set or from the configuration).
        self.w_base_auto.value = state.get(("base",)) is None
        self.w_base_position.value = _vec(stance.q[:3], 3)
        quat = pin.Quaternion(np.asarray(stance.q[3:7], dtype=float)).normalized()
        self.w_base_rpy.value = _vec(pin.rpy.matrixToRpy(quat.matrix()), 3)
        for name, value in joint_values(stance.robot, stance.q).items():
            widget = self._joint_widgets.get(name)
            if widget is not None:
                widget.value = float(np.clip(value, widget.min, widget.max))
        # Contacts.
        frames = [c.frame for c in scenario.contacts] + ([scenario.impact.frame] if scenario.impact else [])
        options = self._frame_options(frames)
        labels = [f"{i}: {c.frame}" for i, c in enumerate(scenario.contacts)]
        index = self._contact_index = min(max(self._contact_index, 0), len(labels) - 1)
        _set_options(self.w_contact_select, labels)
        self.w_contact_select.value = labels[index]
        contact = scenario.contacts[index]
        _set_options(self.w_contact_frame, options)
        self.w_contact_frame.value = contact.frame
        self.w_contact_friction.value = float(contact.friction)
        self.w_contact_size.value = _vec(contact.size, 2)
        self.w_contact_offset.value = _vec(contact.offset.position, 3)
        self.w_contact_rpy.value = _vec(contact.offset.rpy, 3)
        _set_options(self.w_new_frame, options)
        self.w_contact_remove.disabled = len(labels) <= 1
        # Impact.
        impact = scenario.impact
        self.w_impact_on.value = impact is not None
        for w in self._impact_widgets:
            w.disabled = impact is None
        if impact is not None:
            _set_options(self.w_impact_frame, options)
            self.w_impact_frame.value = impact.frame
            self.w_impact_normal.value = _vec(impact.normal, 3)
            self.w_impact_friction.value = float(impact.friction)
            self.w_impact_restitution.value = _vec(impact.restitution, 2)
            self.w_impact_edges.value = int(impact.cone_edges)
            ref = impact.reference_velocity
            self.w_impact_reference.value = _vec(ref if ref is not None else (0.0, 0.0, 0.0), 3)
            self.w_impact_offset.value = _vec(impact.offset.position, 3)
            self.w_impact_inertia.value = impact.inertia
            self.w_impact_duration.value = float(impact.duration)
        # File: the workspace name of the file last loaded (not a bundled one, not an upload).
        source = state.source
        name = self.workspace.relative(os.path.abspath(source)) if source and source.endswith((".yaml", ".yml")) else None
        if name is not None:
            self.w_file.value = name

    # -- controls -------------------------------------------------------------------------
    def _build_gui(self) -> None:
        gui = self.server.gui
        # No share button: sharing goes through viser's public relay, and this server is local.
        gui.configure_theme(control_width="large", dark_mode=False, show_logo=False, show_share_button=False)
        gui.set_panel_label("impact-balance")
        self.w_results = gui.add_html("")
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

    def _build_impact(self) -> None:
        gui = self.server.gui
        self.w_impact_on = gui.add_checkbox("impact", True, hint="Analyse an impact (uncheck: areas only)")
        self.w_impact_on.on_update(self._on_impact_toggle)
        self.w_impact_frame = gui.add_dropdown("impact frame", ["-"], hint="Robot frame of the impact point")
        self.w_impact_frame.on_update(self._field(("impact", "frame")))
        self.w_impact_offset = gui.add_vector3("impact offset (m)", (0.0, 0.0, 0.0), step=0.001,
                                               hint="Impact point in the frame, m")
        self.w_impact_offset.on_update(self._field(("impact", "offset", "position"), list))
        self.w_impact_normal = gui.add_vector3("impact normal", (-1.0, 0.0, 0.0), step=0.01,
                                               hint="World normal, from the impacted surface into the robot")
        self.w_impact_normal.on_update(self._field(("impact", "normal"), list))
        self.w_impact_friction = gui.add_number("impact friction", 0.24, step=0.01, hint="Friction at the impact (>= 0)")
        self.w_impact_friction.on_update(self._field(("impact", "friction"), float))
        self.w_impact_restitution = gui.add_vector2("restitution [lo, hi]", (0.0, 0.2), step=0.01,
                                                    hint="Restitution range, within [0, 1]")
        self.w_impact_restitution.on_update(self._field(("impact", "restitution"), list))
        self.w_impact_edges = gui.add_number("cone edges", 16, step=1, hint="Friction cone edges N (>= 3)")
        self.w_impact_edges.on_update(self._field(("impact", "cone_edges"), lambda v: int(round(v))))
        self.w_impact_reference = gui.add_vector3("reference velocity (m/s)", (0.0, 0.0, 0.0), step=0.01,
                                                  hint="Intended end-effector velocity, world, m/s")
        self.w_impact_reference.on_update(self._field(("impact", "reference_velocity"), list))
        self.w_impact_duration = gui.add_number("impact duration (s)", 0.005, step=0.001,
                                                hint="Impact duration of the ZMP criterion, s")
        self.w_impact_duration.on_update(self._field(("impact", "duration"), float))
        self.w_impact_inertia = gui.add_dropdown("inertia", ["composite", "joint_space"], initial_value="composite",
                                                 hint="composite: one rigid body; joint_space: J M^-1 J^T")
        self.w_impact_inertia.on_update(self._field(("impact", "inertia")))
        self._impact_widgets = [self.w_impact_frame, self.w_impact_offset, self.w_impact_normal,
                                self.w_impact_friction, self.w_impact_restitution, self.w_impact_edges,
                                self.w_impact_reference, self.w_impact_duration, self.w_impact_inertia]

    def _on_impact_toggle(self, _: Any) -> None:
        def apply() -> bool:
            state = self.session.state
            if not self.w_impact_on.value:
                self._impact_stash = state.get(("impact",))
                return self.session.set(("impact",), None)
            impact = self._impact_stash
            if impact is None:
                model = self.session.analysis.stance.robot.model
                frame = next((f for f in _DEFAULT_IMPACT_FRAMES if model.existFrame(f)), model.frames[-1].name)
                impact = {"frame": frame, "normal": [-1.0, 0.0, 0.0], "reference_velocity": [0.5, 0.0, 0.0]}
            return self.session.set(("impact",), impact)

        self.edit(apply)

    def _build_contacts(self) -> None:
        gui = self.server.gui
        self.w_contact_select = gui.add_dropdown("contact", ["0: -"], hint="The contact the fields below edit")
        self.w_contact_select.on_update(self._on_select_contact)

        def contact_field(key: tuple, convert: Callable[[Any], Any] = lambda v: v) -> Callable[[Any], None]:
            def callback(event: Any) -> None:
                self.edit(lambda: self.session.set(("contacts", self._contact_index) + key, convert(event.target.value)))
            return callback

        self.w_contact_frame = gui.add_dropdown("contact frame", ["-"], hint="Robot frame; its z axis is the surface normal")
        self.w_contact_frame.on_update(contact_field(("frame",)))
        self.w_contact_friction = gui.add_number("contact friction", 0.7, step=0.01, hint="Coulomb friction (> 0)")
        self.w_contact_friction.on_update(contact_field(("friction",), float))
        self.w_contact_size = gui.add_vector2("size (m)", (0.2, 0.1), step=0.005,
                                              hint="Full length (local x) and width (local y), m")
        self.w_contact_size.on_update(contact_field(("size",), list))
        self.w_contact_offset = gui.add_vector3("offset (m)", (0.0, 0.0, 0.0), step=0.001, hint="Position in the frame, m")
        self.w_contact_offset.on_update(contact_field(("offset", "position"), list))
        self.w_contact_rpy = gui.add_vector3("offset rpy (rad)", (0.0, 0.0, 0.0), step=0.01,
                                             hint="Roll, pitch, yaw in the frame, rad")
        self.w_contact_rpy.on_update(contact_field(("offset", "rpy"), list))
        self.w_contact_remove = gui.add_button("Remove this contact", color="red")
        self.w_contact_remove.on_click(self._on_remove_contact)
        gui.add_divider()
        self.w_new_frame = gui.add_dropdown("new contact on", ["-"], hint="Frame of a contact to add")
        add = gui.add_button("Add contact")
        add.on_click(self._on_add_contact)

    def _on_select_contact(self, event: Any) -> None:
        label = str(event.target.value)

        def select() -> None:
            try:
                self._contact_index = int(label.split(":")[0])
            except ValueError:
                pass

        self.edit(select)

    def _on_remove_contact(self, _: Any) -> None:
        def apply() -> bool:
            i = self._contact_index
            ok = self.session.set(("contacts", i), None)
            if ok:
                self._contact_index = max(0, i - 1)
            return ok

        self.edit(apply)

    def _on_add_contact(self, _: Any) -> None:
        frame = self.w_new_frame.value

        def apply() -> bool:
            contacts = self.session.state.get(("contacts",), [])
            ok = self.session.set(("contacts",), contacts + [{"frame": frame, "friction": 0.7, "size": [0.1, 0.1]}])
            if ok:
                self._contact_index = len(contacts)
            return ok

        self.edit(apply)

    def _build_base(self) -> None:
        gui = self.server.gui
        with gui.add_folder("Base pose"):
            self.w_base_auto = gui.add_checkbox("auto height", True,
                                                hint="No base pose: the robot is moved vertically so that its lowest "
                                                     "contact corner is at z = 0")
            self.w_base_auto.on_update(self._on_base_auto)
            self.w_base_position = gui.add_vector3("base position (m)", (0.0, 0.0, 1.0), step=0.001)
            self.w_base_position.on_update(self._on_base)
            self.w_base_rpy = gui.add_vector3("base rpy (rad)", (0.0, 0.0, 0.0), step=0.001)
            self.w_base_rpy.on_update(self._on_base)
            reset = gui.add_button("Reset joints and base", hint="Back to the named configuration, auto height")
            reset.on_click(lambda _: self.edit(lambda: self.session.apply({("joints",): {}, ("base",): None})))

    def _on_base_auto(self, _: Any) -> None:
        if self.w_base_auto.value:
            self.edit(lambda: self.session.set(("base",), None))
        else:
            self._on_base(None)

    def _on_base(self, _: Any) -> None:
        self.edit(lambda: self.session.set(("base",), {"position": list(self.w_base_position.value),
                                                       "rpy": list(self.w_base_rpy.value)}))

    def _build_joint_sliders(self) -> None:
        """(Re)build the joint sliders for the session's robot, grouped by limb."""
        for folder in self._joint_folders:
            folder.remove()
        self._joint_folders, self._joint_widgets = [], {}
        gui = self.server.gui
        robot = self.session.analysis.stance.robot
        with self._joints_tab:
            for label, sliders in joint_groups(robot).items():
                folder = gui.add_folder(label, expand_by_default=False)
                self._joint_folders.append(folder)
                with folder:
                    for s in sliders:
                        widget = gui.add_slider(s.name.removesuffix("_joint"), min=s.lower, max=s.upper, step=0.001,
                                                initial_value=float(np.clip(0.0, s.lower, s.upper)))
                        widget.on_update(self._field(("joints", s.name), float))
                        self._joint_widgets[s.name] = widget

    def _build_scenario(self) -> None:
        gui = self.server.gui
        self.w_torque = gui.add_checkbox("torque limits", True, hint="Joint torque limits from the URDF efforts")
        self.w_torque.on_update(self._field(("torque_limits",), bool))
        self.w_com_velocity = gui.add_vector2("CoM velocity (m/s)", (0.0, 0.0), step=0.01,
                                              hint="Pre-impact planar CoM velocity, world, m/s")
        self.w_com_velocity.on_update(self._field(("com_velocity",), list))
        self.w_plane = gui.add_number("plane height (m)", 0.0, step=0.01, hint="Height of the ZMP plane, m")
        self.w_plane.on_update(self._field(("plane_height",), float))
        self.w_gizmos = gui.add_checkbox("drag gizmos", True,
                                         hint="Gizmos on the contacts and the impact point: drag one, IK moves the robot")
        self.w_gizmos.on_update(lambda _: self.edit(lambda: None))
        self.w_opacity = gui.add_slider("robot opacity", min=0.1, max=1.0, step=0.05, initial_value=0.7,
                                        hint="See the CoM and the contacts through the robot")
        self.w_opacity.on_update(self._on_opacity)
        gui.add_divider()
        names = list(bundled_scenarios())
        self.w_bundled = gui.add_dropdown("bundled", names, initial_value=DEFAULT_SCENARIO if DEFAULT_SCENARIO in names else names[0])
        load_bundled = gui.add_button("Load bundled scenario")
        load_bundled.on_click(lambda _: self.edit(lambda: self.session.load(self.w_bundled.value)))
        root = self.workspace.root
        self.w_file = gui.add_text("file", "scenario.yaml",
                                   hint=f"A .yaml file in the workspace {root} (a name relative to it)")
        load = gui.add_button("Load file", hint=f"Read the file from the workspace {root}")
        load.on_click(lambda _: self.edit(lambda: self.session.load(self.w_file.value)))
        self.w_overwrite = gui.add_checkbox("overwrite", False,
                                            hint="Allow the next save to replace an existing file")
        save = gui.add_button("Save file", hint=f"Write the scenario to the workspace {root}")
        save.on_click(lambda _: self.edit(self._save))
        upload = gui.add_upload_button("Upload YAML", mime_type=".yaml,.yml,application/x-yaml,text/yaml")
        upload.on_upload(self._on_upload)
        download = gui.add_button("Download YAML")
        download.on_click(self._on_download)

    def _save(self) -> None:
        try:
            self.session.save(self.w_file.value, overwrite=bool(self.w_overwrite.value))
        finally:
            self.w_overwrite.value = False  # one confirmation, one save

    def _on_opacity(self, event: Any) -> None:
        with self.session.lock:
            if self._meshes is not None:
                self._meshes.set_opacity(float(event.target.value))

    def _on_upload(self, event: Any) -> None:
        file = event.target.value

        self.edit(lambda: self.session.upload(str(file.name), bytes(file.content)))

    def _on_download(self, event: Any) -> None:
        with self.session.lock:
            name = (self.session.state.scenario.name or "scenario") + ".yaml"
            content = self.session.state.to_yaml().encode()
        target = event.client if event.client is not None else self.server
        target.send_file_download(name, content)


def run(scenario: str | Path = DEFAULT_SCENARIO, host: str = "127.0.0.1", port: int = 8080,
        ready: Callable[[GuiApp], None] | None = None, stop: threading.Event | None = None,
        workspace: Workspace | str | Path = ".", allow_origins: tuple[str, ...] | list[str] = ()) -> None:
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
