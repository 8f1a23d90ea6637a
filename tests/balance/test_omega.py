"""One omega: the LIPM natural frequency and its validation, shared by the areas and the LIPM."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from impact_balance.balance.lipm import com_velocity_bounds, lipm_omega
from impact_balance.exceptions import ScenarioError


@given(st.floats(0.05, 3.0), st.floats(-1.0, 1.0), st.floats(0.1, 100.0))
def test_omega_is_the_pendulum_frequency(com_height, plane_height, gravity):
    depth = com_height - plane_height
    if depth <= 1e-9:
        return
    w = lipm_omega(com_height, plane_height, gravity)
    # the pendulum equation: c'' = omega^2 (c - z), so omega^2 (c_z - h) = g
    assert w * w * depth == pytest.approx(gravity, rel=1e-12)


@pytest.mark.parametrize("com_height", [0.0, -0.5, float("nan"), float("inf")])
def test_a_com_not_above_the_plane_names_the_com_height(com_height):
    with pytest.raises(ScenarioError) as info:
        lipm_omega(com_height)
    assert info.value.field == "com_height" and "above the plane height" in info.value.reason


@pytest.mark.parametrize("plane_height", [0.9, 0.8, float("nan")])
def test_a_plane_not_below_the_com_names_the_plane_height(plane_height):
    with pytest.raises(ScenarioError) as info:
        lipm_omega(0.8, plane_height, field="plane_height")
    assert info.value.field == "plane_height" and "below the CoM height 0.8 m" in info.value.reason


@pytest.mark.parametrize("gravity", [0.0, -9.81, float("nan"), 1e3])
def test_gravity_out_of_range_is_refused(gravity):
    with pytest.raises(ScenarioError) as info:
        lipm_omega(0.8, 0.0, gravity)
    assert info.value.field == "gravity"


def test_a_plane_far_below_is_a_small_omega_and_the_one_axis_lipm_refuses_a_far_com():
    assert lipm_omega(0.8, -1e160, 9.81) == pytest.approx(math.sqrt(9.81 / 1e160))
    with pytest.raises(ScenarioError, match="at most 20000 m above"):
        com_velocity_bounds(3e4, (-0.1, 0.1))


def test_the_areas_use_this_omega():
    from impact_balance.analysis.analyze import analyze

    analysis = analyze("palm_push_two_feet")
    a = analysis.areas
    assert a.omega == lipm_omega(float(analysis.stance.com[2]), a.plane_height, a.gravity)
    # the CoM velocity area is the ZMP area scaled by omega about the CoM
    np.testing.assert_allclose(
        a.com_velocity_area.vertices,
        a.omega * (a.zmp_area.vertices - analysis.stance.com[:2]),
        atol=1e-12,
    )
