"""The GUI parts' shared base: widget values, the edit loop and field callbacks (no server)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from impact_balance.gui.host import GuiHost, set_value, vec2, vec3
from impact_balance.gui.session import Session


class _Host(GuiHost):
    """A host without a server: refresh() records its calls."""

    def __init__(self, session: Session):
        self.session = session
        self._syncing = False
        self.refreshed: list[float | None] = []

    def refresh(self, t0: float | None = None) -> None:
        self.refreshed.append(t0)


@pytest.fixture(scope="module")
def session():
    return Session()


def test_vectors_are_plain_floats_of_the_first_values():
    out = vec3(np.array([1, 2.5, -3.0, 9.0]))
    assert out == (1.0, 2.5, -3.0)
    assert all(type(v) is float for v in out)
    assert vec2([0.25, np.float32(0.5), 7]) == (0.25, 0.5)
    with pytest.raises(ValueError):
        vec3([1.0, 2.0])


def test_set_value_assigns_the_widget_value():
    widget = SimpleNamespace(value=0.0)
    set_value(widget, 0.7)  # type: ignore[arg-type]
    assert widget.value == 0.7


def test_an_edit_applies_then_refreshes_once(session):
    host = _Host(session)
    revision = session.revision
    host.edit(lambda: session.set(("plane_height",), 0.01))
    try:
        assert session.state.scenario.plane_height == 0.01
        assert session.revision == revision + 1
        assert len(host.refreshed) == 1 and host.refreshed[0] is not None
    finally:
        session.set(("plane_height",), 0.0)


def test_a_value_that_cannot_be_converted_is_refused_and_the_state_kept(session):
    host = _Host(session)
    before = session.state
    host.edit(lambda: session.set(("plane_height",), float("not a number")))
    assert session.refused and session.message.startswith("bad value: ")
    assert session.state == before
    assert len(host.refreshed) == 1  # the widgets are put back in line


def test_a_callback_fired_by_the_refresh_is_not_an_edit(session):
    host = _Host(session)
    host._syncing = True
    before = session.state
    host.edit(lambda: session.set(("plane_height",), 0.02))
    assert session.state == before
    assert host.refreshed == []


def test_a_field_callback_reads_the_value_when_it_runs(session):
    host = _Host(session)
    callback = host._field(("zmp_margin",), float)
    event = SimpleNamespace(target=SimpleNamespace(value="0.005"))
    callback(event)
    try:
        assert session.state.scenario.zmp_margin == 0.005
        assert session.analysis.areas.zmp_margin == 0.005
    finally:
        session.set(("zmp_margin",), 0.0)


def test_the_base_refresh_is_left_to_the_app(session):
    host = GuiHost()
    with pytest.raises(NotImplementedError):
        host.refresh()
