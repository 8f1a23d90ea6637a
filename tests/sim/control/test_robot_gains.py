"""Gains derived from the robot: on Talos they are the defaults, elsewhere they follow the rules."""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.scenario import load_scenario
from impact_balance.scenario.validate import scenario_from_dict
from impact_balance.sim.control.gains import (
    BalanceGains,
    InverseDynamicsGains,
    RobotScales,
    capture_angular_momentum_weight,
    robot_gains,
    robot_id_gains,
)
from tests.helpers.quadrupeds import four_point_feet


def _scales(name: str, timestep: float = 0.001) -> RobotScales:
    scenario = scenario_from_dict(four_point_feet("go2")) if name == "go2" else load_scenario(name)
    return RobotScales.of(
        scenario.build_stance(), scenario.plane_height, scenario.gravity, timestep
    )


def _changed(derived, base):
    a, b = dataclasses.asdict(derived), dataclasses.asdict(base)
    return {k: (a[k], b[k]) for k in a if a[k] != b[k]}


def test_on_talos_the_rules_give_the_defaults_within_a_few_percent():
    scales = _scales("palm_push_two_feet")
    assert scales.mass == pytest.approx(90.27, abs=0.01)
    assert scales.omega == pytest.approx(math.sqrt(9.81 / scales.com_height))
    for derived, base in (
        (robot_id_gains(scales), InverseDynamicsGains()),
        (robot_gains(scales), BalanceGains()),
    ):
        changed = _changed(derived, base)
        assert changed, "nothing derived"
        for field, (new, old) in changed.items():
            tolerance = 0.04 if field == "angular_momentum_weight" else 0.025
            assert new == pytest.approx(old, rel=tolerance), field


SCALES = st.builds(
    RobotScales,
    mass=st.floats(1.0, 200.0),
    com_height=st.floats(0.1, 1.5),
    omega=st.floats(2.0, 12.0),
    gyration=st.floats(0.05, 0.8),
    gravity=st.just(9.81),
    timestep=st.sampled_from([0.0005, 0.001, 0.002]),
)


@given(scales=SCALES)
@settings(max_examples=50, deadline=None)
def test_the_rules(scales):
    g = robot_id_gains(scales)
    base = InverseDynamicsGains()
    assert g.rate == pytest.approx(0.5 / scales.timestep)
    wc = min(3 * scales.omega, g.rate / 20)
    for k, d in (
        (g.com_height_stiffness, g.com_height_damping),
        (g.posture_stiffness, g.posture_damping),
        (g.base_orientation_stiffness, g.base_orientation_damping),
        (g.impact_stiffness, g.impact_damping),
    ):
        assert d**2 == pytest.approx(4 * k)  # critically damped
    assert math.sqrt(g.com_height_stiffness) == pytest.approx(wc)
    assert math.sqrt(g.impact_stiffness) == pytest.approx(2 * wc)
    assert g.angular_momentum_damping == pytest.approx(wc)
    assert g.dcm_gain == pytest.approx(0.6 * scales.omega)
    weight = scales.mass * scales.gravity
    assert g.min_normal_force == pytest.approx(max(0.0225 * weight, 2.0))
    assert g.wrench_regularization * weight**2 == pytest.approx(0.08)
    for field in (
        "zmp_margin",
        "friction_scale",
        "cop_margin",
        "joint_limit_horizon",
        "com_weight",
    ):
        assert getattr(g, field) == getattr(base, field)
    ik = robot_gains(scales)
    assert ik.dcm_gain == pytest.approx(0.3 * scales.omega) == pytest.approx(ik.zmp_admittance)
    assert ik.max_com_speed == pytest.approx(0.1 * scales.omega * scales.com_height)
    assert ik.zmp_filter * ik.rate == pytest.approx(5.0)
    assert (ik.com_cost, ik.solver) == (BalanceGains().com_cost, BalanceGains().solver)


def test_a_small_robot_gets_stiffer_faster_gains_and_a_lighter_force_floor():
    talos, go2 = (
        robot_id_gains(_scales("palm_push_two_feet")),
        robot_id_gains(_scales("go2")),
    )
    assert go2.dcm_gain > talos.dcm_gain and go2.com_height_stiffness > talos.com_height_stiffness
    assert go2.min_normal_force < 0.2 * talos.min_normal_force  # 16 kg against 90 kg


def test_the_given_gains_are_kept_outside_the_rules():
    base = InverseDynamicsGains(zmp_margin=0.02, friction_scale=0.5)
    g = robot_id_gains(_scales("go2"), base)
    assert (g.zmp_margin, g.friction_scale) == (0.02, 0.5)
    with pytest.raises(ValueError, match="timestep"):
        _scales("go2", 0.0)


CONSISTENT_SCALES = st.builds(
    lambda mass, height, gyration: RobotScales(
        mass, height, math.sqrt(9.81 / height), gyration, 9.81, 0.001
    ),
    mass=st.floats(1.0, 200.0),
    height=st.floats(0.1, 1.5),
    gyration=st.floats(0.05, 0.8),
)


@given(
    scales=CONSISTENT_SCALES,
    com_weight=st.floats(1.0, 1e4),
    displacement=st.floats(1e-4, 0.2),
)
@settings(max_examples=50, deadline=None)
def test_the_capture_weight_prices_a_metre_of_cmp_as_the_com_task_does(
    scales, com_weight, displacement
):
    # Independently of the rule's h: a CoM acceleration error moves the CMP by e_c / omega^2;
    # a moment error tau about the CoM moves the ZMP off the CMP by tau / (m g), and the QP's
    # L rows are per unit mass (e_L = tau / m).
    weight = capture_angular_momentum_weight(scales, com_weight)
    com_error = displacement * scales.omega**2
    moment = displacement * scales.mass * scales.gravity
    com_cost = com_weight * com_error**2
    angular_cost = weight * (moment / scales.mass) ** 2
    assert angular_cost == pytest.approx(com_cost, rel=1e-9)


def test_the_capture_weight_on_talos_and_its_bad_input():
    scales = _scales("palm_push_two_feet")
    weight = capture_angular_momentum_weight(scales, InverseDynamicsGains().com_weight)
    assert weight == pytest.approx(1000.0 / scales.com_height**2)
    assert weight > 1e4 * InverseDynamicsGains().angular_momentum_weight
    with pytest.raises(ValueError, match="com_weight"):
        capture_angular_momentum_weight(scales, 0.0)
    with pytest.raises(ValueError, match="com_height"):
        capture_angular_momentum_weight(dataclasses.replace(scales, com_height=-0.1), 1000.0)
