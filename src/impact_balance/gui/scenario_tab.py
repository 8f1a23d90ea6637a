"""The Scenario tab: general settings, view options, and the file controls.

The file controls load a bundled scenario, load and save a workspace file, upload a file and
download the scenario; every file access goes through the session's workspace rule
(:mod:`.files`). The view options (gizmos, robot opacity) change the drawing, not the scenario.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from impact_balance.gui.host import GuiHost, set_value, vec2
from impact_balance.gui.state import DEFAULT_SCENARIO
from impact_balance.scenario import bundled_scenarios

if TYPE_CHECKING:
    import viser

    from impact_balance.gui.meshes import RobotMeshes

__all__ = ["ScenarioTabMixin"]


class ScenarioTabMixin(GuiHost):
    """The Scenario tab of :class:`~.app.GuiApp`: built once, synced after every edit."""

    # General settings.
    w_torque: viser.GuiCheckboxHandle
    w_com_velocity: viser.GuiVector2Handle
    w_plane: viser.GuiNumberHandle[float]
    w_zmp_margin: viser.GuiNumberHandle[float]
    w_angular_momentum: viser.GuiNumberHandle[float]
    # View options.
    w_gizmos: viser.GuiCheckboxHandle
    w_opacity: viser.GuiSliderHandle[float]
    # Files.
    w_bundled: viser.GuiDropdownHandle[str]
    w_file: viser.GuiTextHandle
    w_overwrite: viser.GuiCheckboxHandle
    #: The robot's meshes (drawn by the 3D scene): the opacity slider sets theirs.
    _meshes: RobotMeshes | None

    def _build_scenario(self) -> None:
        gui = self.server.gui
        self.w_torque = gui.add_checkbox(
            "torque limits", True, hint="Joint torque limits from the URDF efforts"
        )
        self.w_torque.on_update(self._field(("torque_limits",), bool))
        self.w_com_velocity = gui.add_vector2(
            "CoM velocity (m/s)",
            (0.0, 0.0),
            step=0.01,
            hint="Pre-impact planar CoM velocity, world, m/s",
        )
        self.w_com_velocity.on_update(self._field(("com_velocity",), list))
        self.w_plane = gui.add_number(
            "plane height (m)", 0.0, step=0.01, hint="Height of the ZMP plane, m"
        )
        self.w_plane.on_update(self._field(("plane_height",), float))
        self.w_zmp_margin = gui.add_number(
            "ZMP margin (m)",
            0.0,
            min=0.0,
            step=0.005,
            hint="Shrink the ZMP support area by this margin (and the CoM velocity area with it), "
            "m",
        )
        self.w_zmp_margin.on_update(self._field(("zmp_margin",), float))
        self.w_angular_momentum = gui.add_number(
            "angular momentum tau (s)",
            -1.0,
            min=-1.0,
            step=0.01,
            hint="CoM criterion: count the angular momentum the impulse leaves, removed with this "
            "time constant, s (0: at once; 0.1: the id controller); below 0: off, the paper's",
        )
        self.w_angular_momentum.on_update(
            self._field(("angular_momentum_damping_time",), _damping_time)
        )
        self.w_friction_scale = gui.add_number(
            "friction scale",
            1.0,
            min=0.05,
            max=1.0,
            step=0.05,
            hint="The criterion sees every contact's friction times this, in (0, 1]: what a "
            "controller that uses that share of the cones can realise (0.65: the id "
            "controller); 1: the paper's",
        )
        self.w_friction_scale.on_update(self._field(("friction_scale",), float))
        self.w_gizmos = gui.add_checkbox(
            "drag gizmos",
            True,
            hint="Gizmos on the contacts and the impact point: drag one, IK moves the robot",
        )
        self.w_gizmos.on_update(lambda _: self.edit(lambda: None))
        self.w_opacity = gui.add_slider(
            "robot opacity",
            min=0.1,
            max=1.0,
            step=0.05,
            initial_value=0.7,
            hint="See the CoM and the contacts through the robot",
        )
        self.w_opacity.on_update(self._on_opacity)
        gui.add_divider()
        names = list(bundled_scenarios())
        self.w_bundled = gui.add_dropdown(
            "bundled",
            names,
            initial_value=DEFAULT_SCENARIO if DEFAULT_SCENARIO in names else names[0],
        )
        load_bundled = gui.add_button("Load bundled scenario")
        load_bundled.on_click(lambda _: self._load(self.w_bundled.value))
        root = self.workspace.root
        self.w_file = gui.add_text(
            "file",
            "scenario.yaml",
            hint=f"A .yaml file in the workspace {root} (a name relative to it)",
        )
        load = gui.add_button("Load file", hint=f"Read the file from the workspace {root}")
        load.on_click(lambda _: self._load(self.w_file.value))
        self.w_overwrite = gui.add_checkbox(
            "overwrite", False, hint="Allow the next save to replace an existing file"
        )
        save = gui.add_button("Save file", hint=f"Write the scenario to the workspace {root}")
        save.on_click(lambda _: self.edit(self._save))
        upload = gui.add_upload_button(
            "Upload YAML", mime_type=".yaml,.yml,application/x-yaml,text/yaml"
        )
        upload.on_upload(self._on_upload)
        download = gui.add_button("Download YAML")
        download.on_click(self._on_download)

    def _sync_scenario_tab(self) -> None:
        """Put the general settings and the file name in line with the session.

        The file name becomes the workspace name of the file last loaded (not a bundled one,
        not an upload).
        """
        state = self.session.state
        scenario = state.scenario
        set_value(self.w_torque, bool(scenario.torque_limits))
        set_value(self.w_com_velocity, vec2(scenario.com_velocity))
        set_value(self.w_plane, float(scenario.plane_height))
        set_value(self.w_zmp_margin, float(scenario.zmp_margin))
        tau = scenario.angular_momentum_damping_time
        set_value(self.w_angular_momentum, -1.0 if tau is None else float(tau))
        set_value(self.w_friction_scale, float(scenario.friction_scale))
        source = state.source
        name = (
            self.workspace.relative(os.path.abspath(source))
            if source and source.endswith((".yaml", ".yml"))
            else None
        )
        if name is not None:
            set_value(self.w_file, name)

    def _save(self) -> None:
        try:
            self.session.save(self.w_file.value, overwrite=bool(self.w_overwrite.value))
        finally:
            set_value(self.w_overwrite, False)  # one confirmation, one save

    def _on_opacity(self, event: Any) -> None:
        with self.session.lock:
            if self._meshes is not None:
                self._meshes.set_opacity(float(event.target.value))

    def _load(self, name: str) -> None:
        read = self.session.read_file(str(name))  # read and parsed before taking the lock
        self.edit(lambda: self.session.commit(read))

    def _on_upload(self, event: Any) -> None:
        file = event.target.value
        read = self.session.read_upload(str(file.name), bytes(file.content))  # before the lock
        self.edit(lambda: self.session.commit(read))

    def _on_download(self, event: Any) -> None:
        with self.session.lock:
            name = (self.session.state.scenario.name or "scenario") + ".yaml"
            content = self.session.state.to_yaml().encode()
        target = event.client if event.client is not None else self.server
        target.send_file_download(name, content)


def _damping_time(value: float) -> float | None:
    """The GUI's tau field as the scenario key: a negative value is off (None: key removed)."""
    return None if float(value) < 0 else float(value)
