"""The controller's realised removal of the angular momentum a push left: the measurement."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.sim.studies.calibrate import (
    AXIS_SHARE,
    angular_momentum_removal,
    calibrate,
)
from impact_balance.sim.trials.angular_momentum_removal import (
    AngularMomentumRemoval,
    equivalent_damping_time,
)
from tests.helpers.calibration import push_test_document


def _exponential(L0, tau, omega, dt=1e-4, horizon=None):
    """The meter fed with L(t) = L0 exp(-t / tau) every dt, to the horizon."""
    horizon = horizon or 12.0 * max(tau, 1.0 / omega)
    meter = AngularMomentumRemoval(omega, 0.0, np.asarray(L0, dtype=float))
    for k in range(1, int(horizon / dt) + 1):
        t = k * dt
        meter.add(t, np.asarray(L0) * math.exp(-t / tau))
    return meter


@settings(max_examples=25, deadline=None)
@given(tau=st.floats(0.02, 0.8), omega=st.floats(2.5, 4.5), L=st.floats(0.5, 20.0))
def test_an_exponential_removal_gives_back_its_time_constant(tau, omega, L):
    meter = _exponential([L, -0.5 * L, 0.0], tau, omega)
    # The share of the immediate removal's cost: the integral of omega-weighted decrements,
    # 1 / (1 + omega tau) in closed form (to the sampling's first order).
    for i, at_end in enumerate((L, -0.5 * L)):
        share = meter.removed[i] / at_end
        assert share == pytest.approx(1.0 / (1.0 + omega * tau), rel=2e-3)
        measured = equivalent_damping_time(meter.removed[i], at_end, omega)
        assert measured == pytest.approx(tau, rel=1e-2, abs=1e-3)


def test_immediate_never_and_overshooting_removals():
    omega = 3.3
    assert equivalent_damping_time(5.0, 5.0, omega) == 0.0  # removed at once
    assert equivalent_damping_time(6.0, 5.0, omega) == 0.0  # overshoot: no slower than at once
    assert equivalent_damping_time(0.0, 5.0, omega) is None  # never removed: the paper's case
    assert equivalent_damping_time(-1.0, 5.0, omega) is None  # grew instead
    assert equivalent_damping_time(1.0, 0.0, omega) is None
    # A removal in two steps, by hand: half at t = 0.1 s, the rest at t = 0.5 s.
    meter = AngularMomentumRemoval(omega, 1.0, np.array([0.0, 4.0, 0.0]))
    meter.add(1.1, [0.0, 2.0, 0.0])
    meter.add(1.5, [0.0, 0.0, 0.0])
    expected = 2.0 * math.exp(-omega * 0.1) + 2.0 * math.exp(-omega * 0.5)
    assert meter.removed[1] == pytest.approx(expected, rel=1e-12)
    assert meter.samples == 2


def _push(L0, removed, strict=False):
    return {"L0": L0, "removed": removed, "strict": strict}


def _document(pushes, omega=3.3, controller_gain=9.9):
    rows = [(0.1, False, p["strict"]) for p in pushes]
    doc = push_test_document(rows, omega=omega)
    doc["controller"]["gains"]["angular_momentum_damping"] = controller_gain
    for p, out in zip(pushes, doc["pushes"], strict=True):
        out["trial"] = {
            "angular_momentum_at_end": p["L0"],
            "angular_momentum_removed": p["removed"],
        }
    return doc


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(-10, 10),
            st.floats(-10, 10),
            st.floats(0.0, 1.2),
            st.floats(0.0, 1.2),
            st.booleans(),
        ),
        min_size=1,
        max_size=20,
    )
)
def test_the_pooled_removal_is_counted_per_axis(rows):
    pushes = [_push([x, y, 0.3], [rx * x, ry * y, 0.0], strict) for x, y, rx, ry, strict in rows]
    result = calibrate([_document(pushes)], floor=0.0).to_dict()["angular_momentum_removal"]
    for i, axis in enumerate(("x", "y")):
        kept = [
            (p["L0"][i], p["removed"][i])
            for p in pushes
            if not p["strict"]
            and p["L0"][i] != 0.0
            and abs(p["L0"][i]) >= AXIS_SHARE * float(np.linalg.norm(p["L0"]))
        ]
        got = result[axis]
        assert got["pushes"] == len(kept)
        if not kept:
            assert got["share"] is None and got["damping_time"] is None
            continue
        share = sum(math.copysign(1.0, a) * r for a, r in kept) / sum(abs(a) for a, _ in kept)
        assert got["share"] == pytest.approx(share, rel=1e-9, abs=1e-12)
        tau = None if share <= 0 else max(0.0, (1 / share - 1) / 3.3)
        if tau is None:
            assert got["damping_time"] is None
        else:
            assert got["damping_time"] == pytest.approx(tau, rel=1e-9, abs=1e-12)


def test_files_without_the_measurement_report_nothing():
    result = calibrate([push_test_document([(0.1, False, False)] * 3)]).to_dict()
    assert result["angular_momentum_removal"] == {
        "x": {"pushes": 0, "share": None, "damping_time": None},
        "y": {"pushes": 0, "share": None, "damping_time": None},
    }


def test_the_pooled_removal_uses_only_pushes_that_did_not_fail():
    sets = [_push([0.0, 5.0, 0.0], [0.0, 2.5, 0.0]), _push([0.0, 5.0, 0.0], [0.0, -9.0, 0.0], True)]
    y = angular_momentum_removal(calibrate([_document(sets)]).sets[0].pushes)["y"]
    assert (y["pushes"], y["share"]) == (1, 0.5)
    assert y["damping_time"] == pytest.approx((1 / 0.5 - 1) / 3.3)


@pytest.mark.slow
def test_a_real_push_records_its_removal():
    from impact_balance.sim.studies.push import push_test
    from impact_balance.sim.trials.setup import BalanceTrialOptions

    result = push_test(
        "palm_push_two_feet",
        directions=2,
        relative=[0.5],
        options=BalanceTrialOptions(controller="id"),
    )
    for outcome in result.outcomes:
        s = outcome.summary
        L0, removed = s["angular_momentum_at_end"], s["angular_momentum_removed"]
        assert L0 is not None and removed is not None
        i = int(np.argmax(np.abs(L0[:2])))
        share = removed[i] / L0[i]
        # A torso push at half the boundary that stands: the controller removes the momentum,
        # no faster than at once and not never.
        assert s["outcome"] == "balanced"
        assert 0.05 < share < 1.05
