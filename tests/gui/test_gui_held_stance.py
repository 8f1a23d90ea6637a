"""The GUI's "Held stance" button: the held-stance maximum on demand, shown, cleared by an edit."""

from __future__ import annotations

import pytest

pytest.importorskip("viser", reason="needs the gui extra (viser)")

from impact_balance.analysis.held_stance import held_stance_max_contact_velocity
from impact_balance.gui import DEFAULT_SCENARIO, Session
from impact_balance.gui.session import format_speed
from tests.helpers.held_stance import NOT_CONVERGING


@pytest.fixture()
def session(tmp_path) -> Session:
    return Session(DEFAULT_SCENARIO, workspace=tmp_path)


def test_the_answer_is_the_analysis_held_stance_and_an_edit_clears_it(session):
    assert session.held_stance is None
    assert session.compute_held_stance()
    expected = held_stance_max_contact_velocity(session.analysis)
    got = session.held_stance
    assert got.max_contact_velocity == expected.max_contact_velocity and not got.fell_back
    assert got.max_contact_velocity != session.analysis.impact.max_contact_velocity
    assert not session.refused
    assert session.message.startswith(
        f"held-stance max contact velocity {format_speed(expected.max_contact_velocity)}"
    )
    assert f"binding restitution {expected.binding_restitution:g}" in session.message
    assert session.set(("zmp_margin",), 0.02)
    assert session.held_stance is None


def test_a_fixed_point_not_reached_says_it_fell_back(tmp_path):
    session = Session(NOT_CONVERGING, workspace=tmp_path)
    assert session.set(("zmp_margin",), 0.01)
    assert session.compute_held_stance()
    assert session.held_stance.fell_back
    assert session.held_stance.max_contact_velocity == session.analysis.impact.max_contact_velocity
    assert "the fixed point was not reached" in session.message
    from impact_balance.gui.results import results_html

    html = results_html(session, 0.0)
    assert "held stance (paper's: not converged)" in html
    assert f'id="ib-vmax-held">{format_speed(session.held_stance.max_contact_velocity)}' in html


def test_without_an_impact_it_is_refused_naming_the_field(session):
    assert session.set(("impact",), None)
    assert not session.compute_held_stance()
    assert session.refused and "impact" in session.message and session.held_stance is None


def test_the_button_shows_the_answer_and_an_edit_removes_it(tmp_path):
    from impact_balance.gui.app import GuiApp

    app = GuiApp(DEFAULT_SCENARIO, port=0, workspace=tmp_path)
    try:
        app._on_held_stance(None)  # what the button's click runs
        held = app.session.held_stance
        assert held is not None
        expected = held_stance_max_contact_velocity(app.session.analysis).max_contact_velocity
        assert f'id="ib-vmax-held">{format_speed(expected)}' in app.w_results.content
        assert "held stance</td>" in app.w_results.content  # converged: no fallback note
        app._joint_widgets["arm_right_1_joint"].value = 0.3
        assert app.session.held_stance is None
        assert "ib-vmax-held" not in app.w_results.content
    finally:
        app.stop()
