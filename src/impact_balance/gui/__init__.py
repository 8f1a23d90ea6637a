"""Interactive web GUI (``impact-balance gui``): edit a stance and see its balance areas live.

- :mod:`.state`: the editable scenario (a validated mapping; load and save YAML).
- :mod:`.session`: state + analysis, all-or-nothing edits, the numbers shown.
- :mod:`.files`: every load, upload and save, confined to the workspace folder.
- :mod:`.guard`: the Host and Origin checks in front of the server (no other page drives it).
- :mod:`.drag`: gizmo drags solved by whole-body IK (pink), other contacts fixed.
- :mod:`.scene`: what the 3D view draws, as plain data.
- :mod:`.view2d`: the 2D view (areas and post-impact sets) as SVG.
- :mod:`.limbs`: joints grouped by limb for the sliders.
- :mod:`.meshes`, :mod:`.app`: the viser server (imported lazily: it needs ``viser``).
"""

from .drag import DragResult, DragTarget, drag_changes, handle_pose
from .limbs import JointSlider, joint_groups, joint_values
from .scene import Arrows, Label, Points, SceneObject, Segments, Surface, scene_objects
from .session import Session, Summary, format_speed
from .state import DEFAULT_SCENARIO, FieldPath, GuiState
from .view2d import svg_view

__all__ = [
    "DragResult", "DragTarget", "drag_changes", "handle_pose",
    "JointSlider", "joint_groups", "joint_values",
    "Arrows", "Label", "Points", "SceneObject", "Segments", "Surface", "scene_objects",
    "Session", "Summary", "format_speed",
    "DEFAULT_SCENARIO", "FieldPath", "GuiState",
    "svg_view",
    "GuiApp", "run",
]


def __getattr__(name: str):
    # viser is only needed to serve: keep `import impact_balance.gui` light for tests.
    if name in ("GuiApp", "run"):
        from . import app

        return getattr(app, name)
    raise AttributeError(name)
