"""Gizmo drags: a transform control on each contact and on the impact point; a drag is solved
by whole-body IK (:mod:`.drag`) in a worker thread, and a burst of updates costs one solve.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin

from impact_balance.gui.drag import DragTarget, handle_pose

__all__ = ["GizmoMixin"]


def _wxyz(rotation: np.ndarray) -> np.ndarray:
    x, y, z, w = pin.Quaternion(np.asarray(rotation)).coeffs()
    return np.array([w, x, y, z])


class GizmoMixin:
    """The gizmos of :class:`~.app.GuiApp` (uses its ``server``, ``session``, ``edit``, ``w_gizmos``,
    ``_gizmos``, ``_dragging``, ``_drag_pending``, ``_drag_lock`` and ``_drag_busy``).
    """

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
        pose = pin.SE3(
            pin.Quaternion(*np.asarray(gizmo.wxyz, dtype=float)).normalized().matrix(),
            np.asarray(gizmo.position, dtype=float),
        )
        return self.session.drag(target, pose)
