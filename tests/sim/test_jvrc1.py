"""JVRC-1 in MuJoCo: its model is pinocchio's, and one short trial runs."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.cli import main
from impact_balance.sim import SimOptions, build_model
from tests.helpers.sim import mujoco_composite_inertia


def test_jvrc1_model_is_pinocchios_robot():
    sim = build_model("jvrc1_palm_push_two_feet", "servo", SimOptions(timestep=0.001))
    mass, com, _ = mujoco_composite_inertia(sim)
    assert abs(mass / sim.stance.mass - 1.0) < 1e-6
    assert np.linalg.norm(com - sim.stance.com) < 1e-6 * np.linalg.norm(sim.stance.com)


def test_jvrc1_rigid_impact_matches_the_composite_model(capsys):
    argv = ["simulate", "jvrc1_palm_push_two_feet", "--speed", "0.3", "--duration", "0.05"]
    assert main([*argv, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    jump = np.asarray(result["com_velocity_jump_measured"])
    assert np.linalg.norm(jump) > 1e-3
    assert result["predicted"]["composite"]["distance"] < 0.02 * np.linalg.norm(jump)
