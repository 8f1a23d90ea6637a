"""Gizmo drags: a transform control on each contact and on the impact point.

A drag is solved by whole-body IK (:mod:`.drag`) in a worker thread, never in viser's event
loop, and a burst of updates costs one solve: only the gizmo's latest pose is solved. Gizmo
poses are world poses (m), at the contact centre or the impact point, with the frame's axes.
"""

from __future__ import annotations

import asyncio
import functools
import threading
from collections.abc import Callable, Coroutine
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.gui.drag import DragTarget, handle_pose
from impact_balance.gui.host import GuiHost

if TYPE_CHECKING:
    import viser

__all__ = ["GizmoMixin"]


def _wxyz(rotation: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The unit quaternion (w, x, y, z) of a rotation matrix."""
    x, y, z, w = pin.Quaternion(np.asarray(rotation)).coeffs()
    return np.array([w, x, y, z])


class GizmoMixin(GuiHost):
    """The drag gizmos of :class:`~.app.GuiApp`, one per contact and one on the impact point."""

    #: The gizmos by key (``contact<i>``, ``impact``).
    _gizmos: dict[str, viser.TransformControlsHandle]
    #: The gizmo being dragged (not moved by a redraw), None between drags.
    _dragging: str | None
    #: Gizmos moved since their last solve; ``_drag_lock`` guards it and ``_dragging``.
    _drag_pending: set[str]
    _drag_lock: threading.Lock
    #: Held by the thread that solves drags (one at a time).
    _drag_busy: threading.Lock

    def _drag_targets(self) -> dict[str, DragTarget]:
        """The draggable things of the current stance, by gizmo key."""
        n = len(self.session.analysis.stance.contacts)
        out = {f"contact{i}": DragTarget("contact", i) for i in range(n)}
        if self.session.analysis.impact is not None:
            out["impact"] = DragTarget("impact")
        return out

    def _draw_gizmos(self, show: bool) -> None:
        """Add, move or remove the gizmos to match the stance (none unless ``show``).

        The gizmo being dragged is left where the user holds it.
        """
        targets = self._drag_targets() if show else {}
        for key in list(self._gizmos):
            if key not in targets:
                self._gizmos.pop(key).remove()
        state, stance = self.session.state, self.session.analysis.stance
        for key, target in targets.items():
            pose = handle_pose(state, stance, target)
            gizmo = self._gizmos.get(key)
            if gizmo is None:
                gizmo = self.server.scene.add_transform_controls(
                    f"/gizmos/{key}",
                    scale=0.18,
                    line_width=2.0,
                    depth_test=False,
                    position=pose.translation,
                    wxyz=_wxyz(pose.rotation),
                )
                gizmo.on_update(self._on_gizmo(key))
                self._gizmos[key] = gizmo
            elif key != self._dragging:
                gizmo.position = pose.translation
                gizmo.wxyz = _wxyz(pose.rotation)

    def _on_gizmo(self, key: str) -> Callable[[Any], Coroutine[Any, Any, None]]:
        """The update callback of gizmo ``key``: records the drag, then solves pending drags."""

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
                    self.edit(functools.partial(self._drag, key))
            finally:
                self._drag_busy.release()
            with self._drag_lock:
                if not self._drag_pending:
                    return

    def _drag(self, key: str) -> bool:
        """Move the target of gizmo ``key`` to the gizmo's pose; False when refused."""
        gizmo, target = self._gizmos.get(key), self._drag_targets().get(key)
        if gizmo is None or target is None:
            return False
        pose = pin.SE3(
            pin.Quaternion(*np.asarray(gizmo.wxyz, dtype=float)).normalized().matrix(),
            np.asarray(gizmo.position, dtype=float),
        )
        return self.session.drag(target, pose)
