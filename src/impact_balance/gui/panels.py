"""The control panels: the Impact, Contacts and Joints tabs of the GUI.

Each control edits the session through :meth:`~.host.GuiHost.edit` (all-or-nothing); after
every edit :meth:`PanelsMixin._sync_panels` puts the widgets back in line with the session, so
a refused value reverts. Positions are in metres, angles in radians, velocities in m/s, in the
frames the scenario file uses (README, "Scenario files").
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from impact_balance.gui.contact_orientation import (
    ORIENTATION_MODES,
    WORLD_NORMAL_MODE,
    mode_of,
    normal_angle,
    switch_changes,
)
from impact_balance.gui.host import GuiHost, WidgetCallback, set_value, vec2, vec3
from impact_balance.gui.limbs import joint_groups, joint_values
from impact_balance.gui.state import FieldPath
from impact_balance.robot.robot import Robot

if TYPE_CHECKING:
    import viser

__all__ = ["PanelsMixin"]

#: Frame offered first for a new impact (if the robot has it).
_DEFAULT_IMPACT_FRAMES = ("gripper_right_base_link", "right_wrist_yaw_link", "r_hand")


def _set_options(dropdown: viser.GuiDropdownHandle[str], options: list[str]) -> None:
    """Set a dropdown's options only when they change (each assignment is a message)."""
    if tuple(dropdown.options) != tuple(options):
        dropdown.options = options


class PanelsMixin(GuiHost):
    """The Impact and Contacts tabs and the Joints tab's controls, part of :class:`~.app.GuiApp`.

    Each tab is built once (``_build_*``); :meth:`_sync_panels` puts its widgets back in line
    with the session after every edit (a refused value reverts), and rebuilds the joint sliders
    when the robot changes.
    """

    # Impact tab.
    w_impact_on: viser.GuiCheckboxHandle
    w_impact_frame: viser.GuiDropdownHandle[str]
    w_impact_offset: viser.GuiVector3Handle
    w_impact_normal: viser.GuiVector3Handle
    w_impact_friction: viser.GuiNumberHandle[float]
    w_impact_restitution: viser.GuiVector2Handle
    w_impact_edges: viser.GuiNumberHandle[int]
    w_impact_reference: viser.GuiVector3Handle
    w_impact_duration: viser.GuiNumberHandle[float]
    w_impact_inertia: viser.GuiDropdownHandle[str]
    #: The impact's fields, disabled while there is no impact.
    _impact_widgets: list[viser.GuiInputHandle[Any]]
    #: The impact last switched off, restored when it is switched on again.
    _impact_stash: dict[str, Any] | None
    # Contacts tab.
    w_contact_select: viser.GuiDropdownHandle[str]
    w_contact_frame: viser.GuiDropdownHandle[str]
    w_contact_friction: viser.GuiNumberHandle[float]
    w_contact_size: viser.GuiVector2Handle
    w_contact_offset: viser.GuiVector3Handle
    w_contact_rpy: viser.GuiVector3Handle
    w_contact_orientation: viser.GuiDropdownHandle[str]
    w_contact_normal: viser.GuiVector3Handle
    w_contact_angle: viser.GuiNumberHandle[float]
    w_contact_remove: viser.GuiButtonHandle
    w_new_frame: viser.GuiDropdownHandle[str]
    #: The contact the Contacts tab edits.
    _contact_index: int
    # Joints tab.
    _joints_tab: viser.GuiTabHandle
    w_base_auto: viser.GuiCheckboxHandle
    w_base_position: viser.GuiVector3Handle
    w_base_rpy: viser.GuiVector3Handle
    #: The joint sliders by joint name, in folders by limb, built for ``_robot``.
    _joint_widgets: dict[str, viser.GuiSliderHandle[float]]
    _joint_folders: list[viser.GuiFolderHandle]
    _robot: Robot | None

    def _frame_options(self, current: list[str]) -> list[str]:
        """The robot's body and operational frames, and the frames in ``current``, sorted."""
        model = self.session.analysis.stance.robot.model
        names = [
            f.name for f in model.frames if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)
        ]
        return sorted(set(names) | {c for c in current if c})

    def _sync_panels(self) -> None:
        """Put the Impact, Contacts and Joints tabs in line with the session."""
        scenario, stance = self.session.state.scenario, self.session.analysis.stance
        if self._robot is not stance.robot:
            self._build_joint_sliders()
        self._sync_joints()
        frames = [c.frame for c in scenario.contacts] + (
            [scenario.impact.frame] if scenario.impact else []
        )
        options = self._frame_options(frames)
        self._sync_contacts(options)
        self._sync_impact(options)

    def _sync_joints(self) -> None:
        """The base pose and the joint sliders: the actual values, whether set or defaulted."""
        state, stance = self.session.state, self.session.analysis.stance
        set_value(self.w_base_auto, state.get(("base",)) is None)
        set_value(self.w_base_position, vec3(stance.q[:3]))
        quat = pin.Quaternion(np.asarray(stance.q[3:7], dtype=float)).normalized()
        set_value(self.w_base_rpy, vec3(pin.rpy.matrixToRpy(quat.matrix())))
        for name, value in joint_values(stance.robot, stance.q).items():
            widget = self._joint_widgets.get(name)
            if widget is not None:
                set_value(widget, float(np.clip(value, widget.min, widget.max)))

    def _sync_contacts(self, options: list[str]) -> None:
        """The Contacts tab; ``options``: the frames offered."""
        scenario = self.session.state.scenario
        labels = [f"{i}: {c.frame}" for i, c in enumerate(scenario.contacts)]
        index = self._contact_index = min(max(self._contact_index, 0), len(labels) - 1)
        _set_options(self.w_contact_select, labels)
        set_value(self.w_contact_select, labels[index])
        contact = scenario.contacts[index]
        _set_options(self.w_contact_frame, options)
        set_value(self.w_contact_frame, contact.frame)
        set_value(self.w_contact_friction, float(contact.friction))
        set_value(self.w_contact_size, vec2(contact.size))
        set_value(self.w_contact_offset, vec3(contact.offset.position))
        self._sync_contact_orientation(index)
        _set_options(self.w_new_frame, options)
        self.w_contact_remove.disabled = len(labels) <= 1

    def _sync_contact_orientation(self, index: int) -> None:
        """The orientation fields of contact ``index``.

        The form the scenario gives is editable; the other one shows the same rotation, disabled.
        """
        raw = self.session.state.get(("contacts", index), {})
        mode = mode_of(raw)
        stance = self.session.analysis.stance
        contact = stance.contacts[index]
        frame_rotation = stance.frame_pose(contact.spec.frame).rotation
        normal, angle = normal_angle(frame_rotation, contact.rotation)
        if mode == WORLD_NORMAL_MODE:  # as the scenario gives them (the normal at any scale)
            normal, angle = raw["normal"], float(raw.get("angle") or 0.0)
        rpy = pin.rpy.matrixToRpy(frame_rotation.T @ contact.rotation)
        set_value(self.w_contact_orientation, mode)
        # Rounded to a micro-unit: no "-0.00" for a component at rounding-error level.
        set_value(self.w_contact_rpy, vec3(np.round(rpy, 6) + 0.0))
        set_value(self.w_contact_normal, vec3(np.round(normal, 6) + 0.0))
        set_value(self.w_contact_angle, round(float(angle), 6) + 0.0)
        by_normal = mode == WORLD_NORMAL_MODE
        self.w_contact_rpy.disabled = by_normal
        self.w_contact_normal.disabled = self.w_contact_angle.disabled = not by_normal

    def _on_contact_orientation(self, event: Any) -> None:
        """Switch the contact's orientation form, keeping its world rotation."""
        mode = str(event.target.value)

        def apply() -> bool:
            i = self._contact_index
            stance = self.session.analysis.stance
            contact = stance.contacts[i]
            frame_rotation = stance.frame_pose(contact.spec.frame).rotation
            position = self.session.state.get(("contacts", i, "offset", "position"), [0.0] * 3)
            return self.session.apply(
                switch_changes(i, mode, frame_rotation, contact.rotation, position)
            )

        self.edit(apply)

    def _sync_impact(self, options: list[str]) -> None:
        """The Impact tab (its fields disabled without an impact); ``options``: the frames."""
        impact = self.session.state.scenario.impact
        set_value(self.w_impact_on, impact is not None)
        for w in self._impact_widgets:
            w.disabled = impact is None
        if impact is not None:
            _set_options(self.w_impact_frame, options)
            set_value(self.w_impact_frame, impact.frame)
            set_value(self.w_impact_normal, vec3(impact.normal))
            set_value(self.w_impact_friction, float(impact.friction))
            set_value(self.w_impact_restitution, vec2(impact.restitution))
            set_value(self.w_impact_edges, int(impact.cone_edges))
            ref = impact.reference_velocity
            set_value(self.w_impact_reference, vec3(ref if ref is not None else (0.0, 0.0, 0.0)))
            set_value(self.w_impact_offset, vec3(impact.offset.position))
            set_value(self.w_impact_inertia, impact.inertia)
            set_value(self.w_impact_duration, float(impact.duration))

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
            self._field(("impact", "cone_edges"), lambda v: round(float(v)))
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
            key: FieldPath, convert: Callable[[Any], Any] = lambda v: v
        ) -> WidgetCallback:
            def callback(event: Any) -> None:
                self.edit(
                    lambda: self.session.set(
                        ("contacts", self._contact_index, *key), convert(event.target.value)
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
        self.w_contact_orientation = gui.add_dropdown(
            "orientation",
            list(ORIENTATION_MODES),
            hint="How the scenario gives the contact's orientation: roll, pitch, yaw in its "
            "frame, or the surface normal in the world and a turn about it (switching keeps "
            "the contact where it is)",
        )
        self.w_contact_orientation.on_update(self._on_contact_orientation)
        self.w_contact_rpy = gui.add_vector3(
            "offset rpy (rad)",
            (0.0, 0.0, 0.0),
            step=0.01,
            hint="Roll, pitch, yaw in the frame, rad",
        )
        self.w_contact_rpy.on_update(contact_field(("offset", "rpy"), list))
        self.w_contact_normal = gui.add_vector3(
            "world normal",
            (0.0, 0.0, 1.0),
            step=0.001,
            hint="Surface normal in the world, from the surface into the robot (any scale)",
        )
        self.w_contact_normal.on_update(contact_field(("normal",), list))
        self.w_contact_angle = gui.add_number(
            "angle about normal (rad)",
            0.0,
            step=0.01,
            hint="Turn of the contact about its world normal, rad (0: the frame's x axis "
            "projected on the surface)",
        )
        self.w_contact_angle.on_update(contact_field(("angle",), float))
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
            new = {"frame": frame, "friction": 0.7, "size": [0.1, 0.1]}
            ok = self.session.set(("contacts",), [*contacts, new])
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
            reset.on_click(self._on_reset)

    def _on_reset(self, _: Any) -> None:
        """Back to the named configuration, auto height."""
        changes: dict[FieldPath, Any] = {("joints",): {}, ("base",): None}
        self.edit(lambda: self.session.apply(changes))

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
