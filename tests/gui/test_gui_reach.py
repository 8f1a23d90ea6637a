"""The GUI's "CoM reach" button: the reach on demand, drawn in 2D and 3D, cleared with a move."""

from __future__ import annotations

import functools

import numpy as np
import pytest

pytest.importorskip("viser", reason="needs the gui extra (viser)")

from impact_balance.analysis.reach import reach_answer
from impact_balance.balance.reach import ReachOptions
from impact_balance.gui import DEFAULT_SCENARIO, Session, scene_objects, svg_view
from impact_balance.gui.scene import PLANE_LIFT

#: A cheap search (the button's is the default one; the code is the same).
CHEAP = ReachOptions(directions=8, bisections=3, iterations=150)


@pytest.fixture()
def session(tmp_path) -> Session:
    return Session(DEFAULT_SCENARIO, workspace=tmp_path)


def test_the_reach_is_reach_answer_of_the_stance_and_drawn_around_the_com(session):
    assert session.reach is None
    assert session.compute_reach(CHEAP)
    expected = reach_answer(session.analysis, CHEAP)
    got = session.reach
    assert np.array_equal(got.reach.radii, expected.reach.radii)
    assert got.max_contact_velocity == expected.max_contact_velocity
    assert "CoM reach at constant height" in session.message and not session.refused
    # 3D: c + R(a) u(a) on the ZMP plane (lifted above the floor grid)
    areas = session.analysis.areas
    (outline,) = [o for o in scene_objects(session.analysis, got.reach) if "com_reach" in o.name]
    starts = outline.segments[:, 0, :]
    a = got.reach.azimuths
    ring = areas.com[:2] + got.reach.radii[:, None] * np.column_stack([np.cos(a), np.sin(a)])
    assert np.allclose(starts[:, :2], ring, atol=1e-12)
    assert np.all(starts[:, 2] > areas.plane_height) and np.all(
        starts[:, 2] <= areas.plane_height + 2 * PLANE_LIFT + 1e-12
    )
    assert not [o for o in scene_objects(session.analysis) if "com_reach" in o.name]
    # 2D: the polygon and its legend
    assert "CoM reach at constant height" in svg_view(session.analysis, reach=got.reach)
    assert "CoM reach" not in svg_view(session.analysis)


def test_an_edit_keeping_the_stance_keeps_the_reach_and_one_moving_it_clears_it(session):
    assert session.compute_reach(CHEAP)
    radii = session.reach.reach.radii.copy()
    before = session.reach.max_contact_velocity
    assert session.set(("zmp_margin",), 0.02)  # the areas change, not the stance
    assert session.reach is not None and np.array_equal(session.reach.reach.radii, radii)
    again = reach_answer(session.analysis, reach=session.reach.reach)
    assert session.reach.max_contact_velocity == again.max_contact_velocity <= before
    assert session.set(("joints", "arm_right_1_joint"), 0.3)  # the stance moves
    assert session.reach is None


def test_the_button_draws_the_reach_and_a_joint_edit_removes_it(tmp_path):
    from impact_balance.gui.app import GuiApp

    app = GuiApp(DEFAULT_SCENARIO, port=0, workspace=tmp_path)
    try:
        app.session.compute_reach = functools.partial(app.session.compute_reach, CHEAP)
        app._on_com_reach(None)  # what the button's click runs
        assert "/analysis/com_reach/outline" in app._scene_handles
        within = app.session.reach.max_contact_velocity
        assert f'id="ib-vmax-reach">{within:.3f} m/s' in app.w_results.content
        assert "CoM reach at constant height" in app.w_view2d.content
        app._joint_widgets["arm_right_1_joint"].value = 0.3
        assert app.session.reach is None
        assert "/analysis/com_reach/outline" not in app._scene_handles
        assert "ib-vmax-reach" not in app.w_results.content
    finally:
        app.stop()
