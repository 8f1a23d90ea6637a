"""The balance controllers as one family: registry by CLI name, each member's gains and hooks."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

pytest.importorskip("mujoco")
pytest.importorskip("pink")

import pinocchio as pin

from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import SimulationError
from impact_balance.scenario import load_scenario
from impact_balance.sim.control.controller import Controller
from impact_balance.sim.control.gains import BalanceGains, InverseDynamicsGains, trial_gains
from impact_balance.sim.control.kinematic import BalanceController
from impact_balance.sim.control.registry import CONTROLLERS, controller_class
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.model.build import SimOptions, build_model
from impact_balance.sim.trials.setup import BalanceTrialOptions, controller_margin

SCENARIO = "palm_push_two_feet"


@pytest.fixture(scope="module")
def analysis():
    return analyze(load_scenario(SCENARIO))


@pytest.fixture(scope="module")
def sim():
    return build_model(SCENARIO, "servo", SimOptions(meshes=False))


def test_registry_maps_the_cli_names_to_the_members_in_order():
    assert list(CONTROLLERS) == ["ik", "id"]
    assert controller_class("ik") is BalanceController
    assert controller_class("id") is InverseDynamicsController
    assert all(issubclass(cls, Controller) for cls in CONTROLLERS.values())


@pytest.mark.parametrize("name", ["", "IK", "qp", "ik "])
def test_an_unknown_name_is_refused_with_the_valid_ones(name):
    with pytest.raises(SimulationError) as info:
        controller_class(name)
    assert info.value.field == "--controller"
    assert "ik, id" in str(info.value)


def test_each_member_reads_its_own_gains_margin():
    options = BalanceTrialOptions(
        gains=BalanceGains(zmp_margin=0.021), id_gains=InverseDynamicsGains(zmp_margin=0.034)
    )
    assert BalanceController.zmp_margin(options) == 0.021
    assert InverseDynamicsController.zmp_margin(options) == 0.034
    assert controller_margin(options) == 0.021
    assert controller_margin(dataclasses.replace(options, controller="id")) == 0.034


@pytest.mark.parametrize("cls", [BalanceController, InverseDynamicsController])
def test_omega_is_the_lipm_omega_of_the_start_com(analysis, cls):
    controller = cls(analysis)
    model = analysis.stance.robot.model
    com = pin.centerOfMass(model, model.createData(), analysis.stance.q)
    areas = analysis.areas
    expected = math.sqrt(areas.gravity / (float(com[2]) - areas.plane_height))
    assert controller.omega == expected  # to the last bit: one formula
    assert controller.rate == 500.0


@pytest.mark.parametrize("robot_gains", [True, False])
def test_trial_descriptions_keep_the_json_objects(sim, robot_gains):
    options = BalanceTrialOptions(robot_gains=robot_gains)
    ik_gains, id_gains = trial_gains(options, sim)
    if not robot_gains:
        assert (ik_gains, id_gains) == (options.gains, options.id_gains)
    ik = BalanceController.trial_description(options, sim, True)
    assert ik["name"] == BalanceController.name
    assert ik["gains"] == dataclasses.asdict(ik_gains)
    assert ik["control_rate_hz"] == ik_gains.rate
    assert ik["sim_timestep"] == sim.model.opt.timestep
    assert ik["servo"] == {
        "kp": sim.kp.tolist(),
        "kd": sim.kd.tolist(),
        "joints": list(sim.joint_names),
    }
    # push-test's object for ik: name and gains only
    assert BalanceController.trial_summary(options, sim, True) == {
        "name": BalanceController.name,
        "gains": dataclasses.asdict(ik_gains),
    }
    idd = InverseDynamicsController.trial_description(options, sim, False)
    assert idd["gains"] == dataclasses.asdict(id_gains)
    assert idd["effort_limits"] is False
    assert InverseDynamicsController.trial_summary(options, sim, False) == idd


def test_for_trial_builds_each_member_for_its_actuators(analysis):
    options = BalanceTrialOptions(robot_gains=False)
    support = np.array([6, 7], dtype=int)
    q = analysis.stance.q
    servo = build_model(SCENARIO, "servo", SimOptions(meshes=False))
    ik = BalanceController.for_trial(analysis, q, options, None, servo, support)
    assert isinstance(ik, BalanceController) and ik.gains is options.gains
    assert np.array_equal(ik.support_v_index, support)

    motors = build_model(SCENARIO, "servo", SimOptions(meshes=False))
    InverseDynamicsController.prepare_model(motors, analysis)
    assert np.all(motors.model.actuator_gainprm[motors.actuator_ids, 0] == 1.0)
    assert np.all(motors.model.actuator_biasprm[motors.actuator_ids, :3] == 0.0)
    idc = InverseDynamicsController.for_trial(analysis, q, options, None, motors, support)
    assert idc.gains is options.id_gains
    assert np.array_equal(idc.joint_damping, motors.model.dof_damping[motors.dof_adr])
    # At rest the motors start on the holding torques.
    idc.hold(motors, q)
    assert np.array_equal(motors.data.ctrl[motors.actuator_ids], motors.tau_hold)
