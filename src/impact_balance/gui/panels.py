"""The control panels: the Impact, Contacts and Joints tabs, and putting every widget back in
line with the session after an edit (a refused value reverts).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin

from impact_balance.gui.limbs import joint_groups, joint_values

__all__ = ["PanelsMixin"]

#: Frame offered first for a new impact (if the robot has it).
_DEFAULT_IMPACT_FRAMES = ("gripper_right_base_link", "right_wrist_yaw_link", "r_hand")


def _vec(values: Any, n: int) -> tuple[float, ...]:
    return tuple(float(v) for v in list(values)[:n])


def _set_options(dropdown: Any, options: list[str]) -> None:
    """Set a dropdown's options only when they change (each assignment is a message)."""
    if tuple(dropdown.options) != tuple(options):
        dropdown.options = options


class PanelsMixin:
    """The widgets of :class:`~.app.GuiApp` (uses its ``server``, ``session``, ``edit``, ``_field``,
    ``workspace`` and the ``w_*`` widgets).
    """

    def _build_gui(self) -> None:
        gui = self.server.gui
        # No share button: sharing goes through viser's public relay, and this server is local.
        gui.configure_theme(
            control_width="large", dark_mode=False, show_logo=False, show_share_button=False
        )
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

    def _frame_options(self, current: list[str]) -> list[str]:
        model = self.session.analysis.stance.robot.model
        names = [
            f.name for f in model.frames if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)
        ]
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
        self.w_zmp_margin.value = float(scenario.zmp_margin)
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
        frames = [c.frame for c in scenario.contacts] + (
            [scenario.impact.frame] if scenario.impact else []
        )
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
        name = (
            self.workspace.relative(os.path.abspath(source))
            if source and source.endswith((".yaml", ".yml"))
            else None
        )
        if name is not None:
            self.w_file.value = name

    def _build_impact(self) -> None:
        gui = self.server.gui
        self.w_impact_on = gui.add_checkbox(
            "impact", True, hint="Analyse an impact (uncheck: areas only)"
        )
        self.w_impact_on.on_update(self._on_impact_toggle)
        self.w_impact_frame = gui.add_dropdown(
            "impact frame", ["-"], hint="Robot frame of the impact point"
        )
        self.w_impact_frame.on_update(self._field(("impact", "frame")))
        self.w_impact_offset = gui.add_vector3(
            "impact offset (m)", (0.0, 0.0, 0.0), step=0.001, hint="Impact point in the frame, m"
        )
        self.w_impact_offset.on_update(self._field(("impact", "offset", "position"), list))
        self.w_impact_normal = gui.add_vector3(
            "impact normal",
            (-1.0, 0.0, 0.0),
            step=0.01,
            hint="World normal, from the impacted surface into the robot",
        )
        self.w_impact_normal.on_update(self._field(("impact", "normal"), list))
        self.w_impact_friction = gui.add_number(
            "impact friction", 0.24, step=0.01, hint="Friction at the impact (>= 0)"
        )
        self.w_impact_friction.on_update(self._field(("impact", "friction"), float))
        self.w_impact_restitution = gui.add_vector2(
            "restitution [lo, hi]", (0.0, 0.2), step=0.01, hint="Restitution range, within [0, 1]"
        )
        self.w_impact_restitution.on_update(self._field(("impact", "restitution"), list))
        self.w_impact_edges = gui.add_number(
            "cone edges", 16, step=1, hint="Friction cone edges N (>= 3)"
        )
        self.w_impact_edges.on_update(
            self._field(("impact", "cone_edges"), lambda v: int(round(v)))
        )
        self.w_impact_reference = gui.add_vector3(
            "reference velocity (m/s)",
            (0.0, 0.0, 0.0),
            step=0.01,
            hint="Intended end-effector velocity, world, m/s",
        )
        self.w_impact_reference.on_update(self._field(("impact", "reference_velocity"), list))
        self.w_impact_duration = gui.add_number(
            "impact duration (s)", 0.005, step=0.001, hint="Impact duration of the ZMP criterion, s"
        )
        self.w_impact_duration.on_update(self._field(("impact", "duration"), float))
        self.w_impact_inertia = gui.add_dropdown(
            "inertia",
            ["composite", "joint_space"],
            initial_value="composite",
            hint="composite: one rigid body; joint_space: J M^-1 J^T",
        )
        self.w_impact_inertia.on_update(self._field(("impact", "inertia")))
        self._impact_widgets = [
            self.w_impact_frame,
            self.w_impact_offset,
            self.w_impact_normal,
            self.w_impact_friction,
            self.w_impact_restitution,
            self.w_impact_edges,
            self.w_impact_reference,
            self.w_impact_duration,
            self.w_impact_inertia,
        ]

    def _on_impact_toggle(self, _: Any) -> None:
        def apply() -> bool:
            state = self.session.state
            if not self.w_impact_on.value:
                self._impact_stash = state.get(("impact",))
                return self.session.set(("impact",), None)
            impact = self._impact_stash
            if impact is None:
                model = self.session.analysis.stance.robot.model
                frame = next(
                    (f for f in _DEFAULT_IMPACT_FRAMES if model.existFrame(f)),
                    model.frames[-1].name,
                )
                impact = {
                    "frame": frame,
                    "normal": [-1.0, 0.0, 0.0],
                    "reference_velocity": [0.5, 0.0, 0.0],
                }
            return self.session.set(("impact",), impact)

        self.edit(apply)

    def _build_contacts(self) -> None:
        gui = self.server.gui
        self.w_contact_select = gui.add_dropdown(
            "contact", ["0: -"], hint="The contact the fields below edit"
        )
        self.w_contact_select.on_update(self._on_select_contact)

        def contact_field(
            key: tuple, convert: Callable[[Any], Any] = lambda v: v
        ) -> Callable[[Any], None]:
            def callback(event: Any) -> None:
                self.edit(
                    lambda: self.session.set(
                        ("contacts", self._contact_index) + key, convert(event.target.value)
                    )
                )

            return callback

        self.w_contact_frame = gui.add_dropdown(
            "contact frame", ["-"], hint="Robot frame; its z axis is the surface normal"
        )
        self.w_contact_frame.on_update(contact_field(("frame",)))
        self.w_contact_friction = gui.add_number(
            "contact friction", 0.7, step=0.01, hint="Coulomb friction (> 0)"
        )
        self.w_contact_friction.on_update(contact_field(("friction",), float))
        self.w_contact_size = gui.add_vector2(
            "size (m)", (0.2, 0.1), step=0.005, hint="Full length (local x) and width (local y), m"
        )
        self.w_contact_size.on_update(contact_field(("size",), list))
        self.w_contact_offset = gui.add_vector3(
            "offset (m)", (0.0, 0.0, 0.0), step=0.001, hint="Position in the frame, m"
        )
        self.w_contact_offset.on_update(contact_field(("offset", "position"), list))
        self.w_contact_rpy = gui.add_vector3(
            "offset rpy (rad)",
            (0.0, 0.0, 0.0),
            step=0.01,
            hint="Roll, pitch, yaw in the frame, rad",
        )
        self.w_contact_rpy.on_update(contact_field(("offset", "rpy"), list))
        self.w_contact_remove = gui.add_button("Remove this contact", color="red")
        self.w_contact_remove.on_click(self._on_remove_contact)
        gui.add_divider()
        self.w_new_frame = gui.add_dropdown(
            "new contact on", ["-"], hint="Frame of a contact to add"
        )
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
            ok = self.session.set(
                ("contacts",), contacts + [{"frame": frame, "friction": 0.7, "size": [0.1, 0.1]}]
            )
            if ok:
                self._contact_index = len(contacts)
            return ok

        self.edit(apply)

    def _build_base(self) -> None:
        gui = self.server.gui
        with gui.add_folder("Base pose"):
            self.w_base_auto = gui.add_checkbox(
                "auto height",
                True,
                hint="No base pose: the robot is moved vertically so that its lowest "
                "contact corner is at z = 0",
            )
            self.w_base_auto.on_update(self._on_base_auto)
            self.w_base_position = gui.add_vector3("base position (m)", (0.0, 0.0, 1.0), step=0.001)
            self.w_base_position.on_update(self._on_base)
            self.w_base_rpy = gui.add_vector3("base rpy (rad)", (0.0, 0.0, 0.0), step=0.001)
            self.w_base_rpy.on_update(self._on_base)
            reset = gui.add_button(
                "Reset joints and base", hint="Back to the named configuration, auto height"
            )
            reset.on_click(
                lambda _: self.edit(lambda: self.session.apply({("joints",): {}, ("base",): None}))
            )

    def _on_base_auto(self, _: Any) -> None:
        if self.w_base_auto.value:
            self.edit(lambda: self.session.set(("base",), None))
        else:
            self._on_base(None)

    def _on_base(self, _: Any) -> None:
        self.edit(
            lambda: self.session.set(
                ("base",),
                {"position": list(self.w_base_position.value), "rpy": list(self.w_base_rpy.value)},
            )
        )

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
                        widget = gui.add_slider(
                            s.name.removesuffix("_joint"),
                            min=s.lower,
                            max=s.upper,
                            step=0.001,
                            initial_value=float(np.clip(0.0, s.lower, s.upper)),
                        )
                        widget.on_update(self._field(("joints", s.name), float))
                        self._joint_widgets[s.name] = widget
