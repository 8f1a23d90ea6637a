"""SimModel.impact_point_velocity against MuJoCo's own point Jacobian, and the joint models."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("mujoco")

import mujoco

from impact_balance.exceptions import SimulationError
from impact_balance.sim.model.build import SimOptions, build_model
from impact_balance.sim.model.joints import JOINT_MODELS, check_joint_model


@pytest.fixture(scope="module")
def sim():
    return build_model("palm_push_two_feet", "servo", SimOptions(meshes=False))


def test_matches_the_point_jacobian_at_random_velocities(sim):
    m, d = sim.model, sim.data
    n = np.asarray(sim.scenario.impact.normal, dtype=float)
    n /= np.linalg.norm(n)
    rng = np.random.default_rng(7)
    radius = m.geom_size[sim.impact_geom][0]
    body = m.geom_bodyid[sim.impact_geom]
    for _ in range(5):
        v = 0.5 * rng.standard_normal(sim.stance.model.nv)
        sim.set_state(sim.stance.q, v)
        point = d.geom_xpos[sim.impact_geom] - radius * n
        jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jac(m, d, jacp, jacr, point, body)
        np.testing.assert_allclose(sim.impact_point_velocity(n), jacp @ d.qvel, atol=1e-10)
    sim.set_state(sim.stance.q)


def test_refused_without_an_impact_sphere(sim):
    with pytest.raises(SimulationError):
        dataclasses.replace(sim, impact_geom=None).impact_point_velocity(np.array([1.0, 0, 0]))


def test_joint_models_are_checked():
    assert JOINT_MODELS == ("rigid", "servo")
    assert [check_joint_model(j) for j in JOINT_MODELS] == ["rigid", "servo"]
    with pytest.raises(SimulationError, match="valid: rigid, servo"):
        check_joint_model("elastic")
