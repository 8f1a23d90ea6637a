"""What the parts of the GUI app share: the viser server, the session, and the one way to edit.

:class:`~impact_balance.gui.app.GuiApp` is assembled from parts (the 3D scene, the gizmos,
the panels, the Scenario tab), each a mixin that builds and updates its own widgets. They all
derive from :class:`GuiHost`, which declares what they share and holds the edit loop: every
control runs :meth:`GuiHost.edit`, which applies a change to the session (all-or-nothing,
under the session's lock) and then calls :meth:`GuiHost.refresh` to put every widget back in
line with the session. A part that reads another part's widget declares it too, with the same
type.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, TypeVar

from impact_balance.gui.session import Session
from impact_balance.gui.state import FieldPath
from impact_balance.gui.workspace import Workspace

if TYPE_CHECKING:
    import viser

__all__ = ["GuiHost", "WidgetCallback", "set_value", "vec2", "vec3"]

#: A viser ``on_update``/``on_click`` callback: it gets the event (a ``viser.GuiEvent``).
WidgetCallback = Callable[[Any], None]

_T = TypeVar("_T")


def set_value(widget: viser.GuiInputHandle[_T], value: _T) -> None:
    """Set a widget's value (sent to the browser when it changes).

    viser's ``value`` setter is typed in a way mypy reads as read-only; this one place assigns
    it, with the value checked against the widget's type.
    """
    widget.value = value  # type: ignore[misc]


def vec2(values: Iterable[float]) -> tuple[float, float]:
    """The first two values as floats (a vector2 widget's value)."""
    x, y = list(values)[:2]
    return float(x), float(y)


def vec3(values: Iterable[float]) -> tuple[float, float, float]:
    """The first three values as floats (a vector3 widget's value)."""
    x, y, z = list(values)[:3]
    return float(x), float(y), float(z)


class GuiHost:
    """The base of the GUI app's parts: the server, the session, and the edit loop.

    Attributes:
        server: The viser server (its ``gui`` and ``scene`` APIs).
        session: The model (state, analysis, last message), with its lock.
    """

    server: viser.ViserServer
    session: Session
    #: True while :meth:`refresh` sets widgets: their callbacks are then not edits.
    _syncing: bool

    @property
    def workspace(self) -> Workspace:
        """The folder the GUI loads from and saves to."""
        return self.session.files.workspace

    def refresh(self, t0: float | None = None) -> None:
        """Put every widget in line with the session and redraw (the app defines it).

        Args:
            t0: ``time.perf_counter()`` when the update began (now if None), for its timing.
        """
        raise NotImplementedError

    def edit(self, apply: Callable[[], Any]) -> None:
        """Run one edit of the session, then refresh the widgets and redraw.

        A value that cannot even be converted (``ValueError``, ``TypeError``,
        ``OverflowError``) is shown as refused, like a value the session refuses. A refusal
        shown before is cleared by the next edit that is not refused (whatever it changes).

        Args:
            apply: The edit, e.g. ``lambda: session.set(path, value)``.
        """
        with self.session.lock:
            if self._syncing:  # a callback fired by refresh() setting a widget: not an edit
                return
            t0 = time.perf_counter()
            if self.session.refused:  # the next edit's own outcome replaces the refusal
                self.session.message, self.session.refused = None, False
            try:
                apply()
            except (ValueError, TypeError, OverflowError) as exc:
                self.session.message, self.session.refused = f"bad value: {exc}", True
            self.refresh(t0)

    def _field(
        self, path: FieldPath, convert: Callable[[Any], Any] = lambda v: v
    ) -> WidgetCallback:
        """A widget callback that sets the scenario field at ``path`` to the converted value."""

        def callback(event: Any) -> None:
            # Read the value when the edit runs, not when the event came: callbacks of a fast
            # slider run in a thread pool, in any order, and the last one must apply the last value.
            self.edit(lambda: self.session.set(path, convert(event.target.value)))

        return callback
