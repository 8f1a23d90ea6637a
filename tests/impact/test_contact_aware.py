"""The contact-aware impact model (experimental): closed-form rigid-box impacts, the floating
limit, the Coulomb/restitution complementarity and linearity in the approach speed."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.exceptions import ImpactModelError
from impact_balance.geometry.spatial import skew
from impact_balance.impact.contact_aware import contact_impact, corner_contacts
from impact_balance.impact.model import ImpactSpec, impact_model
from impact_balance.robot.robot import Robot

MASS = 10.0
LENGTH, WIDTH, HEIGHT = 0.4, 0.3, 1.0  # box extents along x, y, z, m
HALF = HEIGHT / 2  # the CoM's height above the ground
INERTIA_Y = MASS * (LENGTH**2 + HEIGHT**2) / 12  # about the CoM, around y


def _box(arm: tuple[float, float, float]) -> Robot:
    """A free-floating homogeneous box, CoM at its root; frame "sole" at its bottom face's centre,
    "left" and "right" 0.1 m to either side of it, and frame "hit" at ``arm`` from the CoM."""
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    inertia = (
        MASS / 12 * np.diag([WIDTH**2 + HEIGHT**2, LENGTH**2 + HEIGHT**2, LENGTH**2 + WIDTH**2])
    )
    model.appendBodyToJoint(joint, pin.Inertia(MASS, np.zeros(3), inertia), pin.SE3.Identity())
    body = model.addBodyFrame("box", joint, pin.SE3.Identity(), 0)
    frames = (
        ("sole", (0.0, 0.0, -HALF)),
        ("left", (0.0, 0.1, -HALF)),
        ("right", (0.0, -0.1, -HALF)),
        ("hit", arm),
    )
    for name, position in frames:
        model.addFrame(
            pin.Frame(
                name, joint, body, pin.SE3(np.eye(3), np.array(position)), pin.FrameType.OP_FRAME
            )
        )
    q = pin.neutral(model)
    q[2] = HALF  # the sole on z = 0
    return Robot("box", model, {"neutral": q}, "neutral", Path("box.urdf"))


def _stance(arm, ground_friction: float | None) -> Stance:
    """The box on flat ground (``ground_friction``), or floating (None)."""
    robot = _box(arm)
    contacts = (
        [] if ground_friction is None else [ContactSpec("sole", ground_friction, (LENGTH, WIDTH))]
    )
    return Stance(robot, robot.reference_configurations["neutral"], contacts)


def _push(
    friction: float = 0.0, restitution: tuple[float, float] = (0.0, 0.0), normal=(-1.0, 0.0, 0.0)
) -> ImpactSpec:
    """A wall at +x pushes the box along -x at frame "hit"."""
    return ImpactSpec("hit", normal, friction=friction, restitution=restitution)


def test_floating_frictionless_equals_the_floating_composite_model():
    stance = _stance((LENGTH / 2, 0.05, 0.3), None)
    spec = _push(0.0, (0.15, 0.15), normal=(-0.9, 0.2, 0.3))
    jump = contact_impact(stance, spec, 0.7).com_velocity_jump_3d
    floating = impact_model(stance, spec).com_velocity_jumps(0.7)  # every vertex is the same
    np.testing.assert_allclose(floating, np.tile(jump, (len(floating), 1)), atol=1e-9)


@pytest.mark.sim
@pytest.mark.parametrize("scenario", ["g1_two_feet", "palm_push_two_feet"])
def test_floating_robot_lies_in_the_floating_composite_set(scenario):
    """Without sustained contacts the robot is the floating composite body: its Coulomb impulse
    is one of the floating model's (in the cone, on the restitution plane)."""
    pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
    from impact_balance.scenario import load_scenario
    from impact_balance.sim.trials.measure import distance_to_hull

    full = load_scenario(scenario).build_stance()
    stance = Stance(full.robot, full.q, [])
    spec = dataclasses.replace(load_scenario(scenario).impact.spec(), restitution=(0.1, 0.1))
    result = contact_impact(stance, spec, 0.5)
    assert result.converged
    assert result.contact_impulses.shape == (0, 3)
    model = impact_model(stance, spec)
    assert distance_to_hull(result.com_velocity_jump, model.com_velocity_jumps(0.5)[:, :2]) < 1e-8
    normal_velocity = -0.5 + model.normal @ model.W @ result.impact_impulse
    assert normal_velocity == pytest.approx(0.1 * 0.5, abs=1e-8)  # Newton's restitution
    np.testing.assert_allclose(
        result.com_velocity_jump_3d, result.impact_impulse / stance.mass, atol=1e-12
    )


@pytest.mark.parametrize("restitution", [0.0, 0.2])
def test_frictionless_pivot_about_the_rear_edge(restitution):
    """Frictionless ground and impact, push a above the CoM: the box pivots on its rear edge,
    which can only push up. Closed form: with k = L/2, the CoM velocity jumps by
    dv_x = -(1 + e) v_n / (1 + m a^2 / (I + m k^2)) (floating: I instead of I + m k^2)."""
    a, v_n, e, k = 0.3, 0.6, restitution, LENGTH / 2
    result = contact_impact(_stance((LENGTH / 2, 0.0, a), 0.0), _push(0.0, (e, e)), v_n)
    expected = -(1 + e) * v_n / (1 + MASS * a**2 / (INERTIA_Y + MASS * k**2))
    assert result.com_velocity_jump[0] == pytest.approx(expected, rel=1e-7)
    assert result.com_velocity_jump[1] == pytest.approx(0.0, abs=1e-10)
    P = -MASS * expected  # the wall's impulse; the ground's is N = a k P / (I / m + k^2), vertical
    N = a * k * P / (INERTIA_Y / MASS + k**2)
    np.testing.assert_allclose(result.impact_impulse, [-P, 0.0, 0.0], atol=1e-7 * P)
    np.testing.assert_allclose(result.contact_impulses[0], [0.0, 0.0, N], atol=1e-7 * P)
    # Corners in cwc_span's order (+X,+Y), (+X,-Y), (-X,+Y), (-X,-Y): the rear ones (-X: the box
    # moves to -x) take it, the front ones lift off.
    np.testing.assert_allclose(result.corner_impulses[0, :2], 0.0, atol=1e-9)
    floating = -(1 + e) * v_n / (1 + MASS * a**2 / INERTIA_Y)
    assert abs(result.com_velocity_jump[0]) > abs(floating) + 0.05


def test_two_symmetric_feet_share_the_impulse():
    """Two frictionless feet side by side, pushed in the symmetry plane: the same pivot as one
    sole (the jump does not depend on how the rear edge is split), and the statically
    indeterminate rear corners get the least-norm impulses, equal."""
    a, v_n, k = 0.3, 0.6, LENGTH / 2
    robot = _box((LENGTH / 2, 0.0, a))
    feet = [ContactSpec(name, 0.0, (LENGTH, 0.1)) for name in ("left", "right")]
    result = contact_impact(
        Stance(robot, robot.reference_configurations["neutral"], feet), _push(0.0), v_n
    )
    expected = -v_n / (1 + MASS * a**2 / (INERTIA_Y + MASS * k**2))
    assert result.com_velocity_jump[0] == pytest.approx(expected, rel=1e-7)
    rear = result.corner_impulses[:, 2:, 2]  # (-X, +-Y) corners of both feet, vertical impulse
    np.testing.assert_allclose(rear, rear.mean(), rtol=1e-6)
    np.testing.assert_allclose(result.corner_impulses[:, :2], 0.0, atol=1e-9)


def test_sticking_pivot_about_the_rear_edge():
    """High ground friction: the rear edge is a hinge. The impact point at height z_p above it
    must stop (plastic), so the rotation rate is -v_n / z_p and the CoM, at height H, moves
    by dv_x = -v_n H / z_p, dv_z = v_n (L / 2) / z_p."""
    a, v_n = 0.3, 0.5
    zp = HALF + a
    result = contact_impact(_stance((LENGTH / 2, 0.0, a), 5.0), _push(0.0), v_n)
    np.testing.assert_allclose(
        result.com_velocity_jump_3d, [-v_n * HALF / zp, 0.0, v_n * (LENGTH / 2) / zp], atol=1e-8
    )
    assert result.angular_velocity_jump[1] == pytest.approx(-v_n / zp, rel=1e-7)
    impulse = result.contact_impulses[0]
    assert abs(impulse[0]) <= 5.0 * impulse[2] and impulse[2] > 0  # inside the friction cone
    assert abs(impulse[0]) > 0.01  # the ground's friction acts: not the frictionless answer


def test_push_through_the_com_slides_with_no_ground_impulse():
    """Pushed at the CoM's height, the box slides: nothing loads the ground, so Coulomb friction
    gives no impulse and the jump is the floating one, -(1 + e) v_n (Anitescu's relaxation, the
    fixed point's first step, would lift the box instead)."""
    result = contact_impact(_stance((LENGTH / 2, 0.0, 0.0), 0.8), _push(0.24, (0.1, 0.1)), 0.4)
    assert result.converged and result.iterations > 1
    np.testing.assert_allclose(result.com_velocity_jump_3d, [-1.1 * 0.4, 0.0, 0.0], atol=1e-8)
    np.testing.assert_allclose(result.contact_impulses, 0.0, atol=1e-8)


def _complementarity(stance: Stance, spec: ImpactSpec, v_n: float, e: float) -> None:
    result = contact_impact(stance, spec, v_n, restitution=e)
    assert result.converged
    dxi = np.concatenate([result.com_velocity_jump_3d, result.angular_velocity_jump])
    scale = v_n * stance.mass
    tol = 1e-6 * scale
    # Momentum: the jump is the resultant impulse, the rotation its moment about the CoM.
    resultant = result.impact_impulse + result.contact_impulses.sum(axis=0)
    np.testing.assert_allclose(stance.mass * dxi[:3], resultant, atol=tol)
    model = impact_model(stance, spec)
    arm = model.point - stance.com
    moment = np.cross(arm, result.impact_impulse)
    for contact, corners, impulses in zip(
        stance.contacts, corner_contacts(stance), result.corner_impulses, strict=True
    ):
        for corner, impulse in zip(corners, impulses, strict=True):
            moment += np.cross(corner.arm, impulse)
            local = contact.rotation.T @ impulse  # in the contact frame: z normal
            mu = contact.spec.friction
            assert (
                local[2] >= -tol
                and abs(local[0]) <= mu * local[2] + tol
                and abs(local[1]) <= mu * local[2] + tol
            )
            velocity = dxi[:3] + np.cross(dxi[3:], corner.arm)
            assert velocity @ corner.normal >= -1e-7 * v_n  # no penetration
            assert local[2] * (velocity @ corner.normal) == pytest.approx(
                0.0, abs=1e-6 * v_n * scale
            )
    np.testing.assert_allclose(stance.com_inertia @ dxi[3:], moment, atol=tol)
    n, iota = model.normal, result.impact_impulse
    after = -v_n * n + dxi[:3] + np.cross(dxi[3:], arm)
    assert n @ iota >= -tol and after @ n >= e * v_n - 1e-7 * v_n
    assert (n @ iota) * (after @ n - e * v_n) == pytest.approx(0.0, abs=1e-6 * v_n * scale)
    tangential = iota - (n @ iota) * n
    assert np.linalg.norm(tangential) <= spec.friction * (n @ iota) + tol


def test_complementarity_on_a_box():
    stance = _stance((LENGTH / 2, 0.08, 0.35), 0.6)
    _complementarity(stance, _push(0.3, normal=(-0.95, 0.25, -0.1)), 0.8, 0.1)


@pytest.mark.parametrize("scenario", ["g1_two_feet", "palm_push_ramp", "talos_three_contacts"])
def test_complementarity_on_bundled_stances(scenario):
    from impact_balance.scenario import load_scenario

    loaded = load_scenario(scenario)
    _complementarity(loaded.build_stance(), loaded.impact.spec(), 0.5, 0.1)


def test_linear_in_the_approach_speed_and_added_to_the_com_velocity():
    stance = _stance((LENGTH / 2, 0.05, 0.3), 0.5)
    spec = _push(0.24, (0.0, 0.2))
    one = contact_impact(stance, spec, 0.3, com_velocity=(0.1, -0.2))
    two = contact_impact(stance, spec, 0.6)
    np.testing.assert_allclose(two.com_velocity_jump, 2 * one.com_velocity_jump, atol=1e-9)
    np.testing.assert_allclose(two.contact_impulses, 2 * one.contact_impulses, atol=1e-7)
    np.testing.assert_allclose(
        one.post_impact_com_velocity, np.array([0.1, -0.2]) + one.com_velocity_jump, atol=1e-15
    )
    assert one.restitution == 0.2  # the upper end by default
    np.testing.assert_allclose(contact_impact(stance, spec, 0.0).com_velocity_jump, 0.0, atol=1e-15)


def test_refuses_the_joint_space_model_and_bad_speeds():
    stance = _stance((LENGTH / 2, 0.0, 0.3), 0.5)
    with pytest.raises(ImpactModelError):
        contact_impact(stance, dataclasses.replace(_push(), inertia="joint_space"), 0.5)
    with pytest.raises(ImpactModelError):
        contact_impact(stance, _push(), -0.1)
    with pytest.raises(ImpactModelError):
        contact_impact(stance, _push(), 0.5, restitution=1.5)


def test_skew_convention():
    """The Jacobian J_p = [I, -[r]x] assumes [r]x u = r x u."""
    r, u = np.array([0.1, -0.2, 0.3]), np.array([-1.0, 0.5, 2.0])
    np.testing.assert_allclose(skew(r) @ u, np.cross(r, u))
