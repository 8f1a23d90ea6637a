"""The inertia MuJoCo's integrator adds to a damped joint: ``h * dof_damping``, or nothing.

Checked against MuJoCo's own step: a torque planned with ``M + h D`` (plus the bias forces and the
damping's compensation, as the ``id`` controller's motors add) realises the planned acceleration
in one step of every integrator that integrates the damping implicitly; planned with ``M`` alone
it does not. With an explicit integrator the term is zero and ``M`` alone is exact.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import mujoco

from impact_balance.sim.model.integrator import damping_is_implicit, implicit_damping_inertia

IMPLICIT = ("implicitfast", "implicit", "Euler") + (
    ("discrete",) if hasattr(mujoco.mjtIntegrator, "mjINT_DISCRETE") else ()
)


def _chain(integrator: str, timestep: float, damping: tuple[float, float, float]) -> str:
    """Three hinges (light links, the last a wrist), each with its own damping (N m s/rad)."""
    d1, d2, d3 = damping
    return f"""
<mujoco>
  <option timestep="{timestep}" integrator="{integrator}" gravity="0 0 -9.81"/>
  <worldbody>
    <body name="upper">
      <joint name="shoulder" type="hinge" axis="0 1 0" damping="{d1}"/>
      <geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.02" mass="0.8"/>
      <body name="lower" pos="0.25 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0" damping="{d2}"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.015" mass="0.4"/>
        <body name="hand" pos="0.2 0 0">
          <joint name="wrist" type="hinge" axis="1 0 0" damping="{d3}"/>
          <geom type="box" size="0.03 0.02 0.005" mass="0.3"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _model(integrator: str, timestep: float = 1e-3, damping=(1.0, 1.0, 1.0), eulerdamp=True):
    model = mujoco.MjModel.from_xml_string(_chain(integrator, timestep, damping))
    if not eulerdamp:
        model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)
    return model


def _realised(model, qvel0: np.ndarray, planned: np.ndarray, added: np.ndarray) -> np.ndarray:
    """One MuJoCo step under ``(M + diag(added)) a + bias + D qdot``: the realised acceleration."""
    data = mujoco.MjData(model)
    data.qpos[:] = (0.3, -0.6, 0.4)
    data.qvel[:] = qvel0
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    tau = (M + np.diag(added)) @ planned + data.qfrc_bias + model.dof_damping * data.qvel
    data.qfrc_applied[:] = tau
    mujoco.mj_step(model, data)
    return np.asarray((data.qvel - qvel0) / model.opt.timestep)


@settings(max_examples=40, deadline=None)
@given(
    integrator=st.sampled_from(IMPLICIT),
    timestep=st.floats(1e-4, 5e-3),
    damping=st.tuples(*[st.floats(0.0, 5.0)] * 3),
)
def test_the_term_is_the_step_times_the_damping(integrator, timestep, damping):
    model = _model(integrator, timestep, damping)
    assert damping_is_implicit(model)
    np.testing.assert_allclose(
        implicit_damping_inertia(model), timestep * np.asarray(damping), rtol=1e-12, atol=0
    )


@pytest.mark.parametrize(("integrator", "eulerdamp"), [("RK4", True), ("Euler", False)])
def test_an_explicit_damping_adds_nothing(integrator, eulerdamp):
    model = _model(integrator, eulerdamp=eulerdamp)
    assert not damping_is_implicit(model)
    np.testing.assert_array_equal(implicit_damping_inertia(model), np.zeros(model.nv))


@settings(max_examples=30, deadline=None)
@given(
    integrator=st.sampled_from(IMPLICIT),
    planned=st.lists(st.floats(-50.0, 50.0), min_size=3, max_size=3).filter(
        lambda a: abs(a[2]) > 1.0
    ),
    speed=st.floats(-0.5, 0.5),
)
def test_planned_with_the_term_the_step_realises_the_plan(integrator, planned, speed):
    """The wrist (M_ii 1.3e-4 kg m^2 against h D = 1e-3) realises its plan only with the term."""
    model = _model(integrator)
    # The full implicit integrator also linearises the Coriolis forces: start at rest there.
    qvel0 = np.array([speed, -speed, 2 * speed]) if integrator != "implicit" else np.zeros(3)
    a = np.asarray(planned)
    added = implicit_damping_inertia(model)
    np.testing.assert_allclose(_realised(model, qvel0, a, added), a, rtol=1e-6, atol=1e-6)
    without = _realised(model, qvel0, a, np.zeros(3))
    # The wrist, lightest and damped: a small share of its plan without the term.
    assert abs(without[2]) < 0.2 * abs(a[2])


def test_with_an_explicit_integrator_the_mass_matrix_alone_is_exact():
    model = _model("Euler", eulerdamp=False)
    a = np.array([3.0, -8.0, 20.0])
    qvel0 = np.array([0.2, -0.1, 0.3])
    realised = _realised(model, qvel0, a, implicit_damping_inertia(model))
    np.testing.assert_allclose(realised, a, rtol=1e-9, atol=1e-9)
