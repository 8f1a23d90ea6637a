"""LIPM phase portrait and the paper's sec. III-B numbers."""

import math

import pytest

from impact_balance import ScenarioError
from impact_balance.balance.lipm import com_velocity_bounds, lipm_omega, phase_portrait


def test_paper_bounds():
    # The paper's +-0.4608 m/s is sqrt(g / 0.78) * 0.13 with g = 9.8; with 9.81 it is 0.4610.
    lo, hi = com_velocity_bounds(0.78, (-0.13, 0.13), gravity=9.8)
    assert hi == pytest.approx(0.4608, abs=5e-5) and lo == pytest.approx(-0.4608, abs=5e-5)
    lo, hi = com_velocity_bounds(0.78, (-0.13, 0.13))
    assert hi == pytest.approx(math.sqrt(9.81 / 0.78) * 0.13, rel=1e-12)
    assert hi == pytest.approx(0.4608, abs=1e-3)


def test_bounds_follow_the_com_offset():
    w = lipm_omega(0.8)
    lo, hi = com_velocity_bounds(0.8, (-0.1, 0.15), com_position=0.05)
    assert (lo, hi) == pytest.approx((w * -0.15, w * 0.10))


def test_trajectories_converge_inside_and_diverge_outside():
    p = phase_portrait(0.78, (-0.13, 0.13))
    for traj in p.trajectories:
        c0, v0 = traj[0]
        end = traj[-1]
        if p.is_capturable(c0, v0):
            assert abs(end[0]) < 1e-2 and abs(end[1]) < 5e-2
        else:
            assert abs(end[0]) > 0.3
    assert any(p.is_capturable(*t[0]) for t in p.trajectories)
    assert any(not p.is_capturable(*t[0]) for t in p.trajectories)


@pytest.mark.parametrize("args", [(0.0, (-0.1, 0.1)), (-1.0, (-0.1, 0.1)), (0.8, (0.1, -0.1))])
def test_bad_arguments(args):
    with pytest.raises(ScenarioError):
        com_velocity_bounds(*args)
