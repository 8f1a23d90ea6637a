"""Interactive web GUI (``impact-balance gui``): edit a stance and see its balance areas live.

- :mod:`.state`: the editable scenario (a validated mapping; load and save YAML).
- :mod:`.session`: state + analysis, all-or-nothing edits, the numbers shown.
- :mod:`.files`: every load, upload and save, confined to the workspace folder.
- :mod:`.workspace`: the rule that confines them (no absolute path, no ``..``, no link).
- :mod:`.guard`: the Host and Origin checks in front of the server (no other page drives it).
- :mod:`.drag`: gizmo drags solved by whole-body IK (pink), other contacts fixed.
- :mod:`.scene`: what the 3D view draws, as plain data.
- :mod:`.view2d`: the 2D view (areas and post-impact sets) as SVG.
- :mod:`.limbs`: joints grouped by limb for the sliders.
- :mod:`.app`: the viser server, wiring the parts below (imported lazily: it needs ``viser``):
  :mod:`.server` (where it may listen), :mod:`.host` (what the parts share: the server, the
  session, the edit loop), :mod:`.viser_scene` and :mod:`.meshes` (the 3D view),
  :mod:`.gizmos` (drag handles), :mod:`.panels` (the Impact, Contacts and Joints tabs),
  :mod:`.scenario_tab` (settings and file controls), :mod:`.results` (the numbers as HTML),
  :mod:`.uploads` (uploads counted as they arrive).
"""

from typing import TYPE_CHECKING, Any

from impact_balance.gui.drag import DragResult, DragTarget, drag_changes, handle_pose
from impact_balance.gui.limbs import JointSlider, joint_groups, joint_values
from impact_balance.gui.scene import (
    Arrows,
    Label,
    Points,
    SceneObject,
    Segments,
    Surface,
    scene_objects,
)
from impact_balance.gui.session import Session, Summary, format_speed
from impact_balance.gui.state import DEFAULT_SCENARIO, FieldPath, GuiState
from impact_balance.gui.view2d import svg_view

if TYPE_CHECKING:
    from impact_balance.gui.app import GuiApp, run

__all__ = [
    "DEFAULT_SCENARIO",
    "Arrows",
    "DragResult",
    "DragTarget",
    "FieldPath",
    "GuiApp",
    "GuiState",
    "JointSlider",
    "Label",
    "Points",
    "SceneObject",
    "Segments",
    "Session",
    "Summary",
    "Surface",
    "drag_changes",
    "format_speed",
    "handle_pose",
    "joint_groups",
    "joint_values",
    "run",
    "scene_objects",
    "svg_view",
]


def __getattr__(name: str) -> Any:
    # viser is only needed to serve: keep `import impact_balance.gui` light for tests.
    if name in ("GuiApp", "run"):
        from impact_balance.gui import app

        return getattr(app, name)
    raise AttributeError(name)
