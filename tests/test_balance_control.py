"""Balance controller pieces on pinocchio alone: ZMP clamp, DCM feedback, IK tasks, impact task, fall detector."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.polygon import Polygon
from impact_balance.sim.balance import BalanceController, ImpactTask
from impact_balance.sim.falls import FallCriteria, FallDetector
from impact_balance.sim.zmp import DcmFeedback, clamp_to_polygon, dcm

SQUARE = Polygon(np.array([[-0.1, -0.05], [0.1, -0.05], [0.1, 0.05], [-0.1, 0.05]]))


def _boundary_samples(poly: Polygon, margin: float, n: int = 4000) -> np.ndarray:
    """Dense points of the polygon shrunk by ``margin`` (brute force, independent of the QP)."""
    lo, hi = poly.vertices.min(axis=0), poly.vertices.max(axis=0)
    xs = np.linspace(lo[0], hi[0], n // 20)
    ys = np.linspace(lo[1], hi[1], n // 20)
    grid = np.array(np.meshgrid(xs, ys)).reshape(2, -1).T
    return grid[poly.margins(grid) >= margin - 1e-12]


@pytest.mark.parametrize("point", [(0.3, 0.0), (0.3, 0.2), (-0.05, -0.4), (0.0, 0.0), (0.05, 0.02)])
@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_clamp_is_the_nearest_point_of_the_shrunk_polygon(point, margin):
    p = np.array(point)
    x = clamp_to_polygon(SQUARE, p, margin)
    assert SQUARE.margins(x)[0] >= margin - 1e-7
    brute = _boundary_samples(SQUARE, margin)
    best = np.min(np.linalg.norm(brute - p, axis=1))
    assert np.linalg.norm(x - p) <= best + 1e-3  # grid spacing 1 mm
    if SQUARE.margins(p)[0] >= margin:
        assert np.array_equal(x, p)


def test_clamp_drops_a_margin_larger_than_the_polygon():
    x = clamp_to_polygon(SQUARE, np.array([0.5, 0.0]), margin=0.2)
    assert np.allclose(x, [0.1, 0.0], atol=1e-7)


def test_dcm_feedback_makes_the_dcm_error_decay_at_its_gain():
    """LIPM integrated finely with the feedback's ZMP: xi - xi_ref decays as exp(-k t) while unclamped."""
    omega, k = 3.3, 2.0
    big = Polygon(np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]))
    fb = DcmFeedback(big, omega, np.zeros(2), gain=k, margin=0.0)
    c, cd = np.array([0.02, -0.01]), np.array([0.05, 0.03])
    xi0 = dcm(c, cd, omega)
    dt, T = 1e-4, 1.0
    for _ in range(int(T / dt)):
        p, _, clamped = fb.desired_zmp(c, cd)
        assert not clamped
        acc = omega**2 * (c - p)
        c, cd = c + dt * cd + 0.5 * dt * dt * acc, cd + dt * acc
    assert np.allclose(dcm(c, cd, omega), xi0 * np.exp(-k * T), atol=2e-4)


def test_clamped_zmp_stays_in_the_area_for_a_falling_dcm():
    omega = 3.3
    fb = DcmFeedback(SQUARE, omega, np.zeros(2), gain=3.0, margin=0.01)
    p, xi, clamped = fb.desired_zmp(np.array([0.0, 0.0]), np.array([1.0, 0.0]))
    assert clamped and SQUARE.margins(p)[0] >= 0.01 - 1e-7 and p[0] == pytest.approx(0.09, abs=1e-6)


@pytest.fixture(scope="module")
def analysis():
    return ib.analyze("palm_push_two_feet")


def test_ik_keeps_contacts_and_drives_the_impact_point_at_the_commanded_speed(analysis):
    """Kinematic loop (measured state = reference): contacts stay put, the palm moves at the speed."""
    im = analysis.impact.model
    speed = 0.2
    task = ImpactTask(im.spec.frame, im.spec.offset, im.point, im.normal, speed, start_time=0.0, standoff=0.05)
    from impact_balance.sim.balance import retracted_stance

    q0 = retracted_stance(analysis, 0.05)
    ctl = BalanceController(analysis, q0, impact=task)
    model, data = ctl.model, ctl.model.createData()

    def point(q):
        pin.framesForwardKinematics(model, data, q)
        return (data.oMf[model.getFrameId(im.spec.frame)] * im.spec.offset).translation.copy()

    p_start = point(q0)
    assert np.linalg.norm(p_start - (im.point + 0.05 * im.normal)) < 1e-4
    q, v = q0.copy(), np.zeros(model.nv)
    steps = 100  # 0.2 s at 500 Hz
    for k in range(steps):
        out = ctl.step(k * ctl.dt, q, v)
        q, v = out.q, out.v
    travel = (p_start - point(q)) @ im.normal
    # The target moves at `speed`; pink's dead-beat tasks follow within a step or two.
    assert travel == pytest.approx(speed * (steps - 1) * ctl.dt, abs=3e-3)
    pin.framesForwardKinematics(model, data, q)
    for c in analysis.stance.contacts:
        assert np.linalg.norm(data.oMf[model.getFrameId(c.spec.frame)].translation - c.position) < 1e-4
    com = pin.centerOfMass(model, data, q)
    assert np.linalg.norm(com[:2] - analysis.stance.com[:2]) < 5e-3


def test_impact_task_stops_pushing_and_pulls_back_on_contact():
    n = np.array([-1.0, 0.0, 0.0])
    task = ImpactTask("f", pin.SE3.Identity(), np.zeros(3), n, speed=0.5, start_time=0.0, standoff=0.05)
    # n points from the surface into the robot: the start is 5 cm along n, the approach goes along -n.
    assert np.allclose(task.target(0.05, 0.0), [-0.05 + 0.025, 0, 0])
    assert np.allclose(task.target(0.1, 10.0), [0.0, 0, 0])  # below the 15 N threshold: still approaching
    at_contact = task.target(0.12, 20.0)
    assert np.allclose(at_contact, [0.01, 0, 0]) and task.overshoot == pytest.approx(0.01)
    later = task.target(0.2, 0.0)
    assert (later - at_contact) @ n > 0  # moving back along the normal, away from the surface
    assert np.allclose(task.target(5.0, 0.0), at_contact + (0.05 + task.overshoot) * n)


def _detector():
    R = np.eye(3)
    return FallDetector(["a", "b"], np.zeros((2, 3)), np.stack([R, R]), 1.0, FallCriteria())


def test_fall_detector_tolerates_a_short_unloading_but_not_a_long_one():
    det = _detector()
    P, R = np.zeros((2, 3)), np.stack([np.eye(3)] * 2)
    for k in range(10):  # 10 ms unloaded
        det.update(0.001 * k, P, R, np.array([0.0, 400.0]), 1.0)
    det.update(0.011, P, R, np.array([300.0, 400.0]), 1.0)
    assert not det.fell
    for k in range(30):
        det.update(0.02 + 0.001 * k, P, R, np.array([400.0, 0.5]), 1.0)
    assert det.fell and det.verdict.reason == "contact_lost" and "b" in det.verdict.detail


@pytest.mark.parametrize("kind", ["tilt", "slip", "drop"])
def test_fall_detector_reasons(kind):
    det = _detector()
    P, R = np.zeros((2, 3)), np.stack([np.eye(3)] * 2)
    forces, base = np.array([400.0, 400.0]), 1.0
    det.update(0.0, P, R, forces, base)
    if kind == "tilt":
        R[1] = pin.rpy.rpyToMatrix(0.0, np.deg2rad(6.0), 0.0)
    elif kind == "slip":
        P[0] = [0.011, 0.0, 0.0]
    else:
        base = 0.85
    det.update(0.1, P, R, forces, base)
    assert det.verdict.reason == {"tilt": "contact_tilted", "slip": "contact_slipped", "drop": "base_dropped"}[kind]
    # Just under the thresholds nothing fires.
    det2 = _detector()
    R2 = np.stack([np.eye(3), pin.rpy.rpyToMatrix(0.0, np.deg2rad(4.0), 0.0)])
    det2.update(0.1, np.array([[0.009, 0, 0], [0, 0, 0]]), R2, forces, 0.95)
    assert not det2.fell
    assert det2.finish(3.0, np.array([0.06, 0.0, 0.0])).reason == "not_at_rest"


def test_a_contact_that_never_carried_load_is_not_lost():
    det = _detector()
    P, R = np.zeros((2, 3)), np.stack([np.eye(3)] * 2)
    for k in range(100):  # contact "b" rests without load for 100 ms
        det.update(0.001 * k, P, R, np.array([800.0, 0.0]), 1.0)
    assert not det.fell
    det.update(0.2, P, R, np.array([700.0, 100.0]), 1.0)
    for k in range(30):  # once loaded, unloading for 30 ms is a loss
        det.update(0.201 + 0.001 * k, P, R, np.array([800.0, 0.0]), 1.0)
    assert det.verdict.reason == "contact_lost"
