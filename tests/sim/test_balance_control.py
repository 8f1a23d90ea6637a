"""Balance controller pieces on pinocchio alone: ZMP clamp, DCM feedback, IK tasks, impact task,
fall detector."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import impact_balance as ib
from impact_balance.geometry.polygon import Polygon
from impact_balance.sim.control.approach import ImpactTask
from impact_balance.sim.control.kinematic import BalanceController, retracted_stance
from impact_balance.sim.control.zmp import DcmFeedback, clamp_to_polygon, dcm
from impact_balance.sim.trials.outcomes import OutcomeCriteria, OutcomeMonitor

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
    """LIPM integrated finely with the feedback's ZMP: xi - xi_ref decays as exp(-k t) while
    unclamped."""
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
    p, _xi, clamped = fb.desired_zmp(np.array([0.0, 0.0]), np.array([1.0, 0.0]))
    assert clamped and SQUARE.margins(p)[0] >= 0.01 - 1e-7 and p[0] == pytest.approx(0.09, abs=1e-6)


@pytest.fixture(scope="module")
def analysis():
    return ib.analyze("palm_push_two_feet")


def test_ik_keeps_contacts_and_drives_the_impact_point_at_the_commanded_speed(analysis):
    """Kinematic loop (measured state = reference): contacts stay put, the palm follows the approach
    profile."""
    im = analysis.impact.model
    speed = 0.2
    task = ImpactTask(im.spec.frame, im.spec.offset, im.point, im.normal, speed, start_time=0.0)
    q0 = retracted_stance(analysis, task.standoff)
    ctl = BalanceController(analysis, q0, impact=task)
    model, data = ctl.model, ctl.model.createData()

    def point(q):
        pin.framesForwardKinematics(model, data, q)
        return (data.oMf[model.getFrameId(im.spec.frame)] * im.spec.offset).translation.copy()

    p_start = point(q0)
    assert np.linalg.norm(p_start - (im.point + task.standoff * im.normal)) < 1e-4
    q, v = q0.copy(), np.zeros(model.nv)
    steps = 100  # 0.2 s at 500 Hz: past the 10 ms ramp, at full speed
    for k in range(steps):
        out = ctl.step(k * ctl.dt, q, v)
        q, v = out.q, out.v
    travel = (p_start - point(q)) @ im.normal
    expected = (task.start_point - task.target((steps - 1) * ctl.dt)) @ im.normal
    # pink's dead-beat tasks follow the reference within a step or two.
    assert travel == pytest.approx(expected, abs=3e-3)
    pin.framesForwardKinematics(model, data, q)
    for c in analysis.stance.contacts:
        assert (
            np.linalg.norm(data.oMf[model.getFrameId(c.spec.frame)].translation - c.position) < 1e-4
        )
    com = pin.centerOfMass(model, data, q)
    assert np.linalg.norm(com[:2] - analysis.stance.com[:2]) < 5e-3


@pytest.mark.parametrize("speed", [0.2, 1.0, 3.0])
def test_approach_reaches_the_speed_before_the_surface_with_bounded_acceleration(speed):
    n = np.array([-1.0, 0.0, 0.0])
    task = ImpactTask("f", pin.SE3.Identity(), np.zeros(3), n, speed=speed, start_time=0.1)
    assert task.standoff == pytest.approx(
        max(0.05, speed**2 / (2 * task.acceleration) + task.cruise)
    )
    times = np.arange(0.0, task.arrival_time + 0.05, 1e-4)
    p, v, a = (np.array(x) for x in zip(*(task.reference(t) for t in times), strict=True))
    assert np.all(np.abs(a @ n) <= task.acceleration + 1e-9)
    # Finite differences agree with the reference's velocity and acceleration.
    assert np.allclose(np.gradient(p[:, 0], times), v[:, 0], atol=2e-3 * task.acceleration)
    at_surface = int(np.argmin(np.abs(p @ n)))
    assert times[at_surface] == pytest.approx(task.arrival_time, abs=2e-4)
    assert -v[at_surface] @ n == pytest.approx(speed)
    cruise_start = task.start_time + speed / task.acceleration
    assert (
        p[times.searchsorted(cruise_start)] @ n
    ) >= task.cruise - 1e-3  # full speed 3 cm before the surface
    # Past the surface the reference keeps going at the speed until the contact is felt.
    beyond = task.reference(task.arrival_time + 0.01)
    assert beyond[0] @ n < 0 and -beyond[1] @ n == pytest.approx(speed)


def test_impact_task_stops_pushing_and_withdraws_on_contact():
    n = np.array([-1.0, 0.0, 0.0])
    task = ImpactTask("f", pin.SE3.Identity(), np.zeros(3), n, speed=0.5, start_time=0.0)
    t_touch = task.arrival_time + 0.004
    assert task.reference(t_touch, 10.0)[0] @ n < 0  # below the 15 N threshold: still pushing
    p, v, _a = task.reference(t_touch + 0.001, 20.0)
    assert np.allclose(p, 0.0) and np.allclose(v, 0.0)  # at the surface, at rest: no more pushing
    later, v_later, _ = task.reference(t_touch + 0.02, 0.0)
    assert later @ n > 0 and v_later @ n > 0  # withdrawing along the normal
    assert np.allclose(task.reference(5.0, 0.0)[0], task.retract * n)


def _monitor():
    R = np.eye(3)
    return OutcomeMonitor(["a", "b"], np.zeros((2, 3)), np.stack([R, R]), 1.0, R, OutcomeCriteria())


def _feed(
    mon, t, P=None, R=None, forces=(400.0, 400.0), base=1.0, base_R=None, dcm=0.05, impulsive=False
):
    P = np.zeros((2, 3)) if P is None else P
    R = np.stack([np.eye(3)] * 2) if R is None else R
    mon.update(
        t,
        P,
        R,
        np.asarray(forces, dtype=float),
        base,
        np.eye(3) if base_R is None else base_R,
        dcm,
        impulsive,
    )


def test_short_unloading_is_no_event_but_a_long_one_is_lifted():
    mon = _monitor()
    mon.start_disturbance(0.0)
    for k in range(10):  # 10 ms unloaded
        _feed(mon, 0.001 * k, forces=(0.0, 400.0))
    _feed(mon, 0.011)
    assert not mon.events
    for k in range(30):
        _feed(mon, 0.02 + 0.001 * k, forces=(400.0, 0.5))
    assert [(e.contact, e.kind) for e in mon.events] == [("b", "lifted")]
    out = mon.finish(3.0, np.zeros(3))
    assert (
        out.outcome == "contact_broken"
        and out.reason == "lifted"
        and out.time == pytest.approx(0.02)
    )


@pytest.mark.parametrize("kind", ["tilted", "slipped"])
def test_contact_events_without_a_fall_are_contact_broken(kind):
    mon = _monitor()
    _feed(mon, 0.0)
    mon.start_disturbance(0.05)
    P, R = np.zeros((2, 3)), np.stack([np.eye(3)] * 2)
    if kind == "tilted":
        R[1] = pin.rpy.rpyToMatrix(0.0, np.deg2rad(6.0), 0.0)
    else:
        P[0] = [0.011, 0.0, 0.0]
    _feed(mon, 0.1, P, R)
    assert not mon.fell  # a contact event is not a fall: the trial goes on
    out = mon.finish(3.0, np.zeros(3))
    assert out.outcome == "contact_broken" and out.reason == kind and out.events[0].kind == kind
    # Just under the thresholds: balanced.
    mon2 = _monitor()
    mon2.start_disturbance(0.0)
    R2 = np.stack([np.eye(3), pin.rpy.rpyToMatrix(0.0, np.deg2rad(4.0), 0.0)])
    _feed(mon2, 0.1, np.array([[0.009, 0, 0], [0, 0, 0]]), R2, base=0.95)
    assert mon2.finish(3.0, np.zeros(3)).outcome == "balanced"


@pytest.mark.parametrize("kind", ["base_dropped", "trunk_tipped", "dcm_escaped", "not_at_rest"])
def test_falls(kind):
    mon = _monitor()
    mon.start_disturbance(0.0)
    if kind == "base_dropped":
        _feed(mon, 0.5, base=0.89)
    elif kind == "trunk_tipped":
        _feed(mon, 0.5, base_R=pin.rpy.rpyToMatrix(0.0, np.deg2rad(26.0), 0.0))
    elif kind == "dcm_escaped":
        _feed(mon, 0.5, dcm=0.01)
        _feed(mon, 0.6, dcm=-0.01)
    assert mon.fell == (kind in ("base_dropped", "trunk_tipped"))  # those stop the trial at once
    speed = 0.06 if kind == "not_at_rest" else 0.0
    out = mon.finish(3.0, np.array([speed, 0.0, 0.0]))
    assert out.outcome == "fell" and out.reason == kind
    # A DCM that comes back is no fall.
    back = _monitor()
    back.start_disturbance(0.0)
    _feed(back, 0.5, dcm=-0.01)
    _feed(back, 0.6, dcm=0.01)
    assert back.finish(3.0, np.zeros(3)).outcome == "balanced"


def test_events_or_falls_before_the_disturbance_abort():
    mon = _monitor()
    _feed(mon, 0.1, P=np.array([[0.02, 0, 0], [0, 0, 0]]))
    mon.start_disturbance(0.3)
    out = mon.finish(3.0, np.zeros(3))
    assert (
        out.outcome == "aborted"
        and out.reason == "before_disturbance"
        and "a slipped" in out.detail
    )
    never = _monitor()
    never.abort("no_contact", 2.0, "the impact point never reached the surface")
    assert never.finish(3.0, np.zeros(3)).outcome == "aborted"


def test_a_contact_that_never_carried_load_is_not_lifted():
    mon = _monitor()
    mon.start_disturbance(0.0)
    for k in range(100):  # contact "b" rests without load for 100 ms
        _feed(mon, 0.001 * k, forces=(800.0, 0.0))
    assert not mon.events
    _feed(mon, 0.2, forces=(700.0, 100.0))
    for k in range(30):  # once loaded, unloading for 30 ms is a lift
        _feed(mon, 0.201 + 0.001 * k, forces=(800.0, 0.0))
    assert mon.events[0].kind == "lifted"
