"""The outcome rules of a point contact: it slips and lifts, it never tilts."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.sim.trials.outcomes import STRICT_BOUNDS, OutcomeCriteria, OutcomeMonitor


def _rot_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _trial(points, tilt=0.0, slip=0.0, unloaded=0.0):
    """Both contacts turn ``tilt`` (rad) and slide ``slip`` (m); ``a`` unloads ``unloaded`` s."""
    R = np.eye(3)
    mon = OutcomeMonitor(
        ["a", "b"], np.zeros((2, 3)), np.stack([R, R]), 1.0, R, OutcomeCriteria(), points=points
    )
    mon.start_disturbance(0.0)
    for k in range(600):
        t = 0.001 * k
        share = min(1.0, t / 0.1)
        P = np.zeros((2, 3))
        P[:, 0] = share * slip
        rot = np.stack([_rot_y(share * tilt)] * 2)
        fa = 0.0 if 0.05 <= t < 0.05 + unloaded else 100.0
        mon.update(t, P, rot, np.array([fa, 100.0]), 1.0, R, 0.05)
    return mon, mon.finish(0.6, np.zeros(2))


@given(tilt=st.floats(0.0, 1.2))
@settings(max_examples=20, deadline=None)
def test_a_point_never_tilts_a_sole_does(tilt):
    mon, outcome = _trial([True, False], tilt=tilt)
    kinds = {(e.contact, e.kind) for e in outcome.events}
    assert ("a", "tilted") not in kinds
    sole_tilted = tilt > OutcomeCriteria().max_tilt + 1e-9
    assert (("b", "tilted") in kinds) == sole_tilted
    strict = tilt > STRICT_BOUNDS["strict_max_tilt"] + 1e-9
    assert (outcome.stance_changed is not None) == strict
    if strict:
        assert outcome.stance_changed[1].startswith("b tilted")
    assert mon.max_tilt == pytest.approx(tilt, abs=1e-6)


def test_all_points_turning_is_balanced():
    _, outcome = _trial([True, True], tilt=0.8)
    assert outcome.outcome == "balanced" and not outcome.strict_fail


@pytest.mark.parametrize(
    ("slip", "unloaded", "kind", "strict"),
    [(0.02, 0.0, "slipped", False), (0.04, 0.0, "slipped", True), (0.0, 0.2, "lifted", True)],
)
def test_a_point_slips_and_lifts_with_the_soles_bounds(slip, unloaded, kind, strict):
    _, outcome = _trial([True, True], slip=slip, unloaded=unloaded)
    assert outcome.outcome == "contact_broken" and outcome.reason == kind
    assert outcome.strict_fail == strict


def test_points_must_match_the_contacts():
    R = np.eye(3)
    with pytest.raises(ValueError, match="points has 1 entries for 2 contacts"):
        OutcomeMonitor(["a", "b"], np.zeros((2, 3)), np.stack([R, R]), 1.0, R, points=[True])


@given(weight=st.floats(1.0, 3000.0), contacts=st.integers(1, 4))
@settings(max_examples=40, deadline=None)
def test_a_light_robots_contacts_count_as_loaded(weight, contacts):
    base = OutcomeCriteria()
    scaled = base.for_robot(weight, contacts)
    share = weight / contacts
    assert scaled.load_force == min(base.load_force, 0.5 * share)
    assert scaled.load_force <= share  # a contact carrying its share is loaded
    assert scaled.min_force == base.min_force and scaled.max_tilt == base.max_tilt
    if 0.5 * share >= base.load_force:  # a humanoid: nothing changes
        assert scaled == base
