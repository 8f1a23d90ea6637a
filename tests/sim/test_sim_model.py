"""The MuJoCo model of a scenario is the same robot as pinocchio's, at the same stance.

Independent checks: MuJoCo reads the URDF itself (its own parser, its own inertia handling,
its own kinematics), so equal masses, CoM, composite inertia, contact placements and CoM
velocities at random states mean that the model, the state conversion and the geometry agree.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import mujoco

from impact_balance.exceptions import SimulationError
from impact_balance.sim import SimOptions, build_model
from tests.helpers.sim import mujoco_composite_inertia

SCENARIOS = ["palm_push_two_feet", "palm_push_ramp", "talos_three_contacts", "g1_two_feet"]
LIGHT = SimOptions(meshes=False)


@pytest.fixture(scope="module")
def models():
    cache = {}

    def get(name: str, joints: str):
        key = (name, joints)
        if key not in cache:
            cache[key] = build_model(name, joints, LIGHT)
        return cache[key]

    return get


@pytest.mark.parametrize("joints", ["servo", "rigid"])
@pytest.mark.parametrize("name", SCENARIOS)
def test_mass_com_inertia_match_pinocchio(models, name, joints):
    sim = models(name, joints)
    stance = sim.stance
    mass, com, inertia = mujoco_composite_inertia(sim)
    assert mass == pytest.approx(stance.mass, rel=1e-12)
    np.testing.assert_allclose(com, stance.com, atol=1e-12)
    np.testing.assert_allclose(sim.com(), stance.com, atol=1e-12)
    np.testing.assert_allclose(
        inertia, stance.com_inertia, atol=1e-10 * np.abs(stance.com_inertia).max()
    )
    if joints == "rigid":
        assert sim.model.nv == 6 and sim.model.nu == 0
    else:
        assert sim.model.nu == len(sim.joint_names) == stance.model.nv - 6


@pytest.mark.parametrize("name", ["palm_push_two_feet", "g1_two_feet"])
def test_body_masses_match_pinocchio_joints(models, name):
    """Each MuJoCo body (fixed links fused) carries the inertia pinocchio lumps on its joint."""
    sim = models(name, "servo")
    pmodel = sim.stance.model
    for jid in range(1, pmodel.njoints):
        body = sim.root_body if jid == 1 else sim.model.joint(pmodel.names[jid]).bodyid[0]
        assert sim.model.body_mass[body] == pytest.approx(pmodel.inertias[jid].mass, rel=1e-12), (
            pmodel.names[jid]
        )


@pytest.mark.parametrize("joints", ["servo", "rigid"])
@pytest.mark.parametrize("name", SCENARIOS)
def test_contact_boxes_and_impact_sphere_at_the_stance(models, name, joints):
    sim = models(name, joints)
    d = sim.data
    t = sim.options.contact.box_half_thickness
    for contact, geom in zip(sim.stance.contacts, sim.contact_geoms, strict=True):
        R = d.geom_xmat[geom].reshape(3, 3)
        face_centre = d.geom_xpos[geom] - t * R[:, 2]
        np.testing.assert_allclose(face_centre, contact.position, atol=1e-12)
        np.testing.assert_allclose(R, contact.rotation, atol=1e-12)
        np.testing.assert_allclose(
            sim.model.geom_size[geom][:2], [contact.half_length, contact.half_width]
        )
        assert sim.model.geom_friction[geom][0] == contact.spec.friction
    # Explicit pairs only: each box with its support (and the ground), the sphere with the surface.
    m = sim.model
    pairs = {
        (int(a), int(b)): float(mu)
        for a, b, mu in zip(m.pair_geom1, m.pair_geom2, m.pair_friction[:, 0], strict=True)
    }
    for contact, geom, support in zip(
        sim.stance.contacts, sim.contact_geoms, sim.support_geoms, strict=True
    ):
        assert pairs[(support, geom)] == contact.spec.friction
        assert pairs[(sim.ground_geom, geom)] == contact.spec.friction
    assert pairs[(sim.surface_geom, sim.impact_geom)] == sim.scenario.impact.friction
    assert not m.geom_contype.any() and not m.geom_conaffinity.any()
    # Each contact's support touches it: its face is the contact plane, normals opposed.
    for contact, geom in zip(sim.stance.contacts, sim.support_geoms, strict=True):
        R = d.geom_xmat[geom].reshape(3, 3)
        if sim.model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_PLANE:
            assert contact.position[2] == pytest.approx(d.geom_xpos[geom][2], abs=1e-3)
        else:
            face = d.geom_xpos[geom] + sim.model.geom_size[geom][2] * R[:, 2]
            np.testing.assert_allclose(face, contact.position, atol=1e-12)
            np.testing.assert_allclose(R[:, 2], contact.normal, atol=1e-12)
    spec = sim.scenario.impact.spec()
    point = sim.stance.point(spec.frame, spec.offset)[0].translation
    n = np.asarray(spec.normal) / np.linalg.norm(spec.normal)
    r = sim.model.geom_size[sim.impact_geom][0]
    np.testing.assert_allclose(d.geom_xpos[sim.impact_geom] - r * n, point, atol=1e-12)
    R = d.geom_xmat[sim.surface_geom].reshape(3, 3)
    np.testing.assert_allclose(R[:, 2], n, atol=1e-12)
    assert (point - d.geom_xpos[sim.surface_geom]) @ n == pytest.approx(
        sim.model.geom_size[sim.surface_geom][2]
    )
    assert sim.model.geom_friction[sim.impact_geom][0] == spec.friction


def test_mesh_geoms_do_not_collide():
    sim = build_model("kick_one_foot", "servo")  # with meshes
    meshes = np.flatnonzero(sim.model.geom_type == mujoco.mjtGeom.mjGEOM_MESH)
    assert meshes.size > 10
    assert not sim.model.geom_contype[meshes].any() and not sim.model.geom_conaffinity[meshes].any()


@pytest.mark.parametrize("name", ["palm_push_two_feet", "g1_two_feet"])
def test_state_round_trip_and_com_velocity_against_pinocchio(models, name):
    """Random q, v: MuJoCo's CoM and CoM velocity equal pinocchio's (checks the free-joint
    conventions)."""
    sim = models(name, "servo")
    pmodel = sim.stance.model
    pdata = pmodel.createData()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = pin.randomConfiguration(
            pmodel,
            np.maximum(pmodel.lowerPositionLimit, -3),
            np.minimum(pmodel.upperPositionLimit, 3),
        )
        v = rng.normal(size=pmodel.nv)
        sim.set_state(q, v)
        np.testing.assert_allclose(sim.configuration(), q, atol=1e-14)
        np.testing.assert_allclose(sim.velocity(), v, atol=1e-12)
        pin.centerOfMass(pmodel, pdata, q, v)
        np.testing.assert_allclose(sim.com(), pdata.com[0], atol=1e-12)
        np.testing.assert_allclose(sim.com_velocity(), pdata.vcom[0], atol=1e-12)
        # The base's world-axes velocities, as the log stores them.
        linear, angular = sim.base_velocity_world()
        R = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()
        np.testing.assert_allclose(linear, R @ v[:3], atol=1e-12)
        np.testing.assert_allclose(angular, R @ v[3:6], atol=1e-12)
    sim.set_state(sim.stance.q)


@pytest.mark.parametrize(
    "name", ["palm_push_two_feet", "talos_three_contacts", "palm_push_ramp", "kick_one_foot"]
)
def test_servo_holds_the_stance_under_gravity(name):
    sim = build_model(name, "servo", LIGHT)
    com0 = sim.com()
    for _ in range(int(1.0 / sim.model.opt.timestep)):
        mujoco.mj_step(sim.model, sim.data)
    weight = sim.mass * sim.scenario.gravity
    total = sum(sim.contact_force(g) for g in sim.contact_geoms)
    np.testing.assert_allclose(total, [0.0, 0.0, weight], atol=0.01 * weight)
    assert np.linalg.norm(sim.com() - com0) < 2e-3
    assert np.linalg.norm(sim.com_velocity()) < 1e-2


def test_servo_gain_rule(models):
    """kp = I omega^2, kd = 2 zeta I omega on the joint's diagonal mass-matrix entry (pinocchio's
    crba)."""
    sim = models("palm_push_two_feet", "servo")
    M = pin.crba(sim.stance.model, sim.stance.model.createData(), sim.stance.q)
    inertia = M[sim.v_index, sim.v_index]
    w = sim.options.servo.bandwidth
    np.testing.assert_allclose(sim.kp, inertia * w**2, rtol=1e-9)
    np.testing.assert_allclose(sim.kd, 2 * inertia * w, rtol=1e-9)
    # Effort limits: the actuator force range is the URDF effort.
    idx, lim = sim.robot.effort_limits
    limits = dict(zip(idx.tolist(), lim.tolist(), strict=True))
    for k, a in enumerate(sim.actuator_ids):
        assert sim.model.actuator_forcerange[a][1] == pytest.approx(limits[sim.v_index[k]])


def test_unknown_joint_model_is_refused():
    with pytest.raises(SimulationError, match="joints"):
        build_model("palm_push_two_feet", "springy")
