"""The id controller's ``touch_contact``: the touching point as a contact of the QP.

The rows it adds (docs/simulation.md, "The touching point as a contact"): from the first touch
until the withdrawal the impact point's force lies in the impact's friction pyramid at the
controller's scale and presses with the task's force threshold, the point's acceleration is the
contacts' (zero up to the contact damping), and the force enters the equations of motion; before
the touch the QP's answer is the one without the option. Cross-checked with pinocchio directly:
the point's acceleration by finite differences, the torques by the recursive Newton-Euler
algorithm.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import pinocchio as pin

from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import SimulationError
from impact_balance.scenario import load_scenario
from impact_balance.sim.control.approach import ImpactTask
from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.torque import InverseDynamicsController, touch_faces
from tests.helpers.extras import needs_extra

STANCE = (
    Path(__file__).parents[3]
    / "studies/held_out_11/icub_right_hand_wall_left_palm_oblique_side.yaml"
)
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@pytest.fixture(scope="module")
def analysis():
    return analyze(load_scenario(str(STANCE)))


def _task(analysis) -> ImpactTask:
    im = analysis.impact.model
    return ImpactTask(im.spec.frame, im.spec.offset, im.point, im.normal, 0.1, start_time=0.0)


def _controller(analysis, touch: bool) -> InverseDynamicsController:
    gains = InverseDynamicsGains(touch_contact=touch)
    return InverseDynamicsController(
        analysis, gains=gains, impact=_task(analysis), effort_limits=False
    )


def _state(analysis, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The stance's posture and a small velocity (rad/s, m/s)."""
    model = analysis.stance.robot.model
    rng = np.random.default_rng(seed)
    return analysis.stance.q.copy(), 0.05 * rng.standard_normal(model.nv)


def _point_velocity(model, data, fid, offset, q, v) -> np.ndarray:
    """The impact point's world velocity, straight from pinocchio."""
    pin.forwardKinematics(model, data, q, v)
    pin.updateFramePlacements(model, data)
    frame = data.oMf[fid]
    r = (frame * offset).translation - frame.translation
    vel = pin.getFrameVelocity(model, data, fid, LWA)
    return np.asarray(vel.linear + np.cross(vel.angular, r))


def test_touching_point_force_in_its_cone_and_at_the_threshold(analysis):
    controller = _controller(analysis, touch=True)
    q, v = _state(analysis)
    out = controller.step(0.0, q, v, None, impact_force=3.0)  # the first touch: 3 N
    assert controller.touching and controller.touch_time == 0.0
    f = out.touch_force
    n = np.asarray(analysis.impact.model.normal, dtype=float)
    mu = controller.gains.friction_scale * analysis.impact.model.spec.friction
    f_n = float(n @ f)
    tangential = float(np.linalg.norm(f - f_n * n))
    assert f_n >= controller.touch_force - 1e-6
    assert controller.touch_force == 15.0  # the task's withdrawal threshold
    # The pyramid lies inside the cone of sqrt(2) mu (its corners).
    assert tangential <= np.sqrt(2.0) * mu * f_n + 1e-6


def test_touching_point_does_not_accelerate_into_the_surface(analysis):
    controller = _controller(analysis, touch=True)
    model = controller.model
    data = model.createData()
    q, v = _state(analysis, seed=1)
    out = controller.step(0.0, q, v, None, impact_force=3.0)
    fid, offset = model.getFrameId(controller.impact.frame), controller.impact.offset
    dt = 1e-7
    before = _point_velocity(model, data, fid, offset, q, v)
    after = _point_velocity(
        model, data, fid, offset, pin.integrate(model, q, v * dt), v + out.a * dt
    )
    acceleration = (after - before) / dt
    # The stance's contacts' rule, J a + J_dot v = -K_c J v: all three axes, the normal's too.
    expected = -controller.gains.contact_damping * before
    np.testing.assert_allclose(acceleration, expected, atol=2e-3 * (1 + np.abs(expected).max()))


def test_touching_force_enters_the_equations_of_motion(analysis):
    controller = _controller(analysis, touch=True)
    model = controller.model
    data = model.createData()
    q, v = _state(analysis, seed=2)
    out = controller.step(0.0, q, v, None, impact_force=3.0)
    generalised = pin.rnea(model, data, q, v, out.a).copy()  # M a + h
    generalised[6:] -= out.tau
    contacts = controller._Jw.T @ out.wrenches.reshape(-1)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    fid, offset = model.getFrameId(controller.impact.frame), controller.impact.offset
    J = pin.getFrameJacobian(model, data, fid, LWA)
    frame = data.oMf[fid]
    r = (frame * offset).translation - frame.translation
    J_point = J[:3] - pin.skew(r) @ J[3:]
    np.testing.assert_allclose(
        generalised - contacts, J_point.T @ out.touch_force, atol=1e-6 * np.abs(generalised).max()
    )
    assert np.linalg.norm(out.touch_force) > 10.0  # the check is not of a zero force


def test_before_the_touch_the_answer_is_the_one_without_the_option(analysis):
    q, v = _state(analysis, seed=3)
    with_option = _controller(analysis, touch=True).step(0.0, q, v, None, impact_force=0.0)
    without = _controller(analysis, touch=False).step(0.0, q, v, None, impact_force=0.0)
    np.testing.assert_allclose(with_option.touch_force, np.zeros(3), atol=1e-9)
    assert without.touch_force is None
    np.testing.assert_allclose(with_option.a, without.a, atol=1e-6)
    np.testing.assert_allclose(with_option.tau, without.tau, atol=1e-5)
    np.testing.assert_allclose(with_option.wrenches, without.wrenches, atol=1e-4)


def test_the_withdrawal_releases_the_contact(analysis):
    controller = _controller(analysis, touch=True)
    q, v = _state(analysis, seed=4)
    controller.step(0.0, q, v, None, impact_force=3.0)
    assert controller.touching
    out = controller.step(0.002, q, v, None, impact_force=20.0)  # over the task's 15 N
    assert controller.impact.contact_time == 0.002
    assert not controller.touching
    np.testing.assert_allclose(out.touch_force, np.zeros(3), atol=1e-9)


def test_a_task_without_a_finite_threshold_presses_with_none(analysis):
    task = replace(_task(analysis), force_threshold=np.inf)
    gains = InverseDynamicsGains(touch_contact=True)
    controller = InverseDynamicsController(analysis, gains=gains, impact=task)
    assert controller.touch_force == 0.0


def test_touch_contact_needs_an_impact(analysis):
    no_impact = analyze(load_scenario(str(STANCE)).replace(impact=None))
    with pytest.raises(SimulationError, match="touch_contact"):
        InverseDynamicsController(
            no_impact, gains=InverseDynamicsGains(touch_contact=True), impact=_task(analysis)
        )


@settings(max_examples=60, deadline=None)
@given(
    normal=st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(
        lambda x: np.linalg.norm(x) > 0.1
    ),
    mu=st.floats(0.0, 1.5),
    tangent=st.lists(st.floats(-1, 1), min_size=3, max_size=3),
    ratio=st.floats(0.0, 2.0),
)
def test_touch_faces_sit_between_the_inscribed_and_the_circumscribed_cones(
    normal, mu, tangent, ratio
):
    n = np.asarray(normal) / np.linalg.norm(normal)
    t = np.asarray(tangent) - (np.asarray(tangent) @ n) * n
    if np.linalg.norm(t) < 1e-3:
        return
    t /= np.linalg.norm(t)
    faces = touch_faces(normal, mu)
    f = n + ratio * mu * t  # tangential / normal = ratio mu
    inside = bool(np.all(faces @ f <= 1e-9))
    if ratio <= 1.0:  # in the cone of mu: in the pyramid
        assert inside
    if ratio > np.sqrt(2.0) + 1e-6 and mu > 1e-3:  # outside the cone of sqrt(2) mu: outside
        assert not inside
    assert np.all(faces @ n <= 1e-12)  # a pure push is in it
    if mu > 1e-6:
        assert np.all(faces @ (-n) > 0)  # a pull is in none of its half-spaces


@pytest.mark.parametrize("normal, mu", [((0, 0, 0), 0.5), ((0, 0, 1), -0.1), ((1, 0, 0), np.nan)])
def test_touch_faces_refuse_bad_input(normal, mu):
    with pytest.raises(ValueError, match=r"normal|friction"):
        touch_faces(normal, mu)


@pytest.mark.slow
@needs_extra("sim")
def test_icub_wall_touch_becomes_a_contact_and_withdraws_at_once():
    """iCub's wall hold at 0.02 m/s: the palm is a contact from the first touch, presses its
    15 N and the withdrawal starts within a few milliseconds (without the option the palm
    pivots on the wall for tens of milliseconds before the force reaches 15 N). The QP with
    ``M`` alone (``implicit_damping_inertia=False``): with the plant's inertia the palm, without
    the option, no longer pivots and stays under 15 N (tested in test_implicit_damping_inertia)."""
    from impact_balance.sim.trials.balance_trial import run_balance_trial
    from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions

    seen: dict[bool, dict[str, float | None]] = {}
    step = InverseDynamicsController.step
    for touch in (False, True):
        record: dict[str, float | None] = {"touching_steps": 0.0, "min_planned": np.inf}

        def kept(self, t, q, v, zmp=None, impact_force=0.0, record=record):
            out = step(self, t, q, v, zmp, impact_force)
            if self.touching:
                record["touching_steps"] += 1
                record["min_planned"] = min(
                    record["min_planned"], float(self.impact.normal @ out.touch_force)
                )
            record["contact_time"] = self.impact.contact_time
            return out

        options = BalanceTrialOptions(
            controller="id",
            after=0.3,
            id_gains=InverseDynamicsGains(touch_contact=touch, implicit_damping_inertia=False),
        )
        setup = BalanceSetup.create(str(STANCE), options=options)
        InverseDynamicsController.step = kept
        try:
            result = run_balance_trial(setup, impact_speed=0.02, options=options)
        finally:
            InverseDynamicsController.step = step
        record["touch"] = result.impact.contact_time if result.impact is not None else None
        seen[touch] = record
    for touch, record in seen.items():
        assert record["touch"] is not None and record["contact_time"] is not None, (touch, record)
    off, on = seen[False], seen[True]
    assert off["touching_steps"] == 0
    assert on["touching_steps"] >= 1
    assert on["min_planned"] >= 15.0 - 1e-6
    assert on["contact_time"] - on["touch"] < 0.01
    assert off["contact_time"] - off["touch"] > 0.03
