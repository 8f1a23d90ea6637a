"""kappa, the DCM's growth over a push of finite duration, against a LIPM integrated by scipy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from impact_balance.balance.lipm import finite_push_factor
from impact_balance.exceptions import ScenarioError
from tests.helpers.lipm import captured_after_push, pushed_state

OMEGAS = st.floats(1.0, 8.0)
DURATIONS = st.floats(0.0, 0.2)


@settings(max_examples=60, deadline=None)
@given(omega=OMEGAS, duration=DURATIONS, impulse_per_mass=st.floats(0.01, 1.0))
def test_the_integrated_dcm_at_the_push_end_is_kappa_times_the_impulsive_one(
    omega, duration, impulse_per_mass
):
    assume(duration > 1e-4)
    accel = impulse_per_mass / duration  # F / m for the push's duration: J / m in all
    c, v = pushed_state(accel, duration, omega)
    dcm = c + v / omega
    expected = finite_push_factor(omega, duration) * impulse_per_mass / omega
    assert dcm == pytest.approx(expected, rel=1e-7)


@settings(max_examples=60, deadline=None)
@given(
    omega=OMEGAS,
    duration=st.floats(1e-3, 0.2),
    extent=st.floats(0.02, 0.3),
    level=st.floats(0.5, 1.5),
)
def test_a_push_is_captured_iff_kappa_times_its_velocity_is_in_the_area(
    omega, duration, extent, level
):
    # The CoM velocity area along the push: speeds up to omega e. The kappa condition
    # kappa J / m <= omega e against the LIPM pushed for T (ZMP at the start), then braked with
    # the ZMP at the extent.
    kappa = finite_push_factor(omega, duration)
    impulse_per_mass = level * omega * extent / kappa
    assume(abs(level - 1.0) > 1e-3)  # on the boundary itself the CoM stops only at infinity
    called = kappa * impulse_per_mass <= omega * extent
    assert called == (level < 1.0)
    assert captured_after_push(impulse_per_mass / duration, duration, extent, omega) == called


@settings(max_examples=40, deadline=None)
@given(omega=OMEGAS, duration=st.floats(1e-3, 0.2), extent=st.floats(0.02, 0.3))
def test_the_impulsive_criterion_calls_safe_pushes_the_lipm_does_not_capture(
    omega, duration, extent
):
    # Between 1/kappa and 1 of the paper's boundary the impulsive prediction is optimistic.
    kappa = finite_push_factor(omega, duration)
    assume(kappa - 1.0 > 1e-3)
    impulse_per_mass = 0.5 * (1.0 / kappa + 1.0) * omega * extent
    assert impulse_per_mass <= omega * extent  # the paper: safe
    assert not captured_after_push(impulse_per_mass / duration, duration, extent, omega)


def test_kappa_is_one_at_no_duration_and_tends_to_it():
    assert finite_push_factor(3.3, 0.0) == 1.0
    for t in (1e-3, 1e-6, 1e-9, 1e-12):
        k = finite_push_factor(3.3, t)
        assert k - 1.0 == pytest.approx(3.3 * t / 2, rel=1e-2, abs=1e-15)


@settings(max_examples=60, deadline=None)
@given(a=st.floats(0.0, 20.0), b=st.floats(0.0, 20.0), omega=OMEGAS)
def test_kappa_increases_with_omega_t_and_depends_on_it_alone(a, b, omega):
    assume(abs(a - b) > 1e-9)
    lo, hi = sorted((a, b))
    assert finite_push_factor(1.0, lo) < finite_push_factor(1.0, hi)
    assert finite_push_factor(omega, hi / omega) == pytest.approx(
        finite_push_factor(1.0, hi), rel=1e-12
    )
    x = hi
    closed = 1.0 if x == 0 else (math.exp(x) - 1.0) / x
    assert finite_push_factor(1.0, x) == pytest.approx(closed, rel=1e-9)


def test_jvrc1s_kappa():
    # omega 3.33 /s, 50 ms: the DCM overshoots the impulsive one by 8.7 %.
    assert finite_push_factor(3.33, 0.05) == pytest.approx(
        np.expm1(3.33 * 0.05) / (3.33 * 0.05), rel=1e-12
    )
    assert 1.08 < finite_push_factor(3.33, 0.05) < 1.09


@pytest.mark.parametrize(
    ("omega", "duration", "field"),
    [
        (0.0, 0.05, "omega"),
        (-3.0, 0.05, "omega"),
        (float("nan"), 0.05, "omega"),
        (3.0, -0.01, "duration"),
        (3.0, float("inf"), "duration"),
        (3.0, 100.0, "duration"),
        (True, 0.05, "omega"),
        (3.0, "0.05", "duration"),
    ],
)
def test_bad_inputs_are_refused_by_name(omega, duration, field):
    with pytest.raises(ScenarioError) as err:
        finite_push_factor(omega, duration)
    assert err.value.field == field
    assert field in str(err.value)
