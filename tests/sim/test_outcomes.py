"""The strict outcome: a contact beyond the strict bounds fails the criterion's premise, and the
DCM check stops once the stance is another one."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance.sim.trials.outcomes import STRICT_BOUNDS, OutcomeCriteria, OutcomeMonitor


def _monitor() -> OutcomeMonitor:
    R = np.eye(3)
    return OutcomeMonitor(["a", "b"], np.zeros((2, 3)), np.stack([R, R]), 1.0, R, OutcomeCriteria())


def _rot_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _run(slip=0.0, tilt=0.0, unloaded=0.0, dcm=0.05, steps=400):
    """A trial of ``steps`` ms after a disturbance at 0: contact ``a`` slides to ``slip`` (m) and
    turns to ``tilt`` (rad) over the first 100 ms, carries nothing for ``unloaded`` s from 50 ms;
    the DCM's margin is ``dcm`` (m) throughout."""
    mon = _monitor()
    mon.start_disturbance(0.0)
    for k in range(steps):
        t = 0.001 * k
        share = min(1.0, t / 0.1)
        P = np.zeros((2, 3))
        P[0, 0] = share * slip
        R = np.stack([_rot_x(share * tilt), np.eye(3)])
        fa = 0.0 if 0.05 <= t < 0.05 + unloaded else 400.0
        mon.update(t, P, R, np.array([fa, 400.0]), 1.0, np.eye(3), dcm)
    return mon.finish(0.001 * steps, np.zeros(3))


def test_strict_bounds_are_the_documented_ones():
    c = OutcomeCriteria()
    assert c.strict_max_tilt == pytest.approx(np.deg2rad(10.0)) == STRICT_BOUNDS["strict_max_tilt"]
    assert c.strict_max_slip == 0.03 and c.strict_max_unloaded == 0.1
    assert {"strict_max_tilt", "strict_max_slip", "strict_max_unloaded"} <= set(c.to_dict())


def test_a_small_slip_is_a_lenient_and_strict_success():
    out = _run(slip=0.02)
    assert out.outcome == "contact_broken" and out.reason == "slipped"
    assert not out.strict_fail and out.strict_reason is None and out.stance_changed is None


def test_a_sole_slid_over_3_cm_fails_strictly():
    out = _run(slip=0.05)
    assert out.outcome == "contact_broken"  # lenient: came to rest without a step
    assert out.strict_fail and out.strict_reason.startswith("a slipped")
    assert 0.05 < out.stance_changed[0] < 0.07  # 3 cm of 5 cm over 100 ms


def test_a_sole_rolled_over_10_degrees_fails_strictly():
    assert not _run(tilt=np.deg2rad(8.0)).strict_fail
    out = _run(tilt=np.deg2rad(15.0))
    assert out.outcome == "contact_broken" and out.strict_fail and "tilted" in out.strict_reason


def test_a_contact_lost_over_a_tenth_of_a_second_fails_strictly():
    short = _run(unloaded=0.05)
    assert short.outcome == "contact_broken" and short.reason == "lifted"
    assert not short.strict_fail and short.max_unloaded == pytest.approx(0.05, abs=0.002)
    long = _run(unloaded=0.2)
    assert long.strict_fail and "lifted" in long.strict_reason
    assert long.max_unloaded == pytest.approx(0.2, abs=0.002)


def test_the_dcm_check_stops_once_the_stance_changed():
    # Within the bounds the scenario's area applies: a DCM outside at the end is a fall.
    inside = _run(slip=0.02, dcm=-0.01)
    assert inside.outcome == "fell" and inside.reason == "dcm_escaped" and inside.strict_fail
    # A foot slid 5 cm: the area is not the support in contact any more; no dcm_escaped fall, but
    # the strict outcome fails.
    moved = _run(slip=0.05, dcm=-0.01)
    assert moved.outcome == "contact_broken" and moved.reason != "dcm_escaped"
    assert moved.strict_fail and moved.stance_changed is not None


def test_an_aborted_trial_never_fails_strictly():
    mon = _monitor()
    P = np.zeros((2, 3))
    P[0, 0] = 0.05
    mon.update(0.0, P, np.stack([np.eye(3)] * 2), np.array([400.0, 400.0]), 1.0, np.eye(3), 0.05)
    mon.start_disturbance(0.01)
    out = mon.finish(0.5, np.zeros(3))
    assert out.outcome == "aborted" and not out.strict_fail


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 0.08), st.floats(0.0, np.deg2rad(20.0)))
def test_strict_fail_is_exactly_beyond_a_bound(slip, tilt):
    assume(abs(slip - STRICT_BOUNDS["strict_max_slip"]) > 1e-9)
    assume(abs(tilt - STRICT_BOUNDS["strict_max_tilt"]) > 1e-9)  # arccos rounds at the bound
    out = _run(slip=slip, tilt=tilt, steps=150)
    beyond = slip > STRICT_BOUNDS["strict_max_slip"] or tilt > STRICT_BOUNDS["strict_max_tilt"]
    assert out.strict_fail == beyond
    assert out.outcome != "fell"
