"""Impact trials in MuJoCo against the impact model, and the ``simulate`` command.

Independent checks: the CoM velocity jump read from MuJoCo's own CoM velocity equals the
integrated contact impulse over the mass (momentum, for the floating rigid robot); the
impulse lies in the impact's friction cone; the log's base and CoM velocities equal the
finite differences of its poses; the impact model's composite set (computed by the analysis
pipeline from pinocchio) contains the rigid robot's measured jump.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")
pytest.importorskip("pyarrow", reason="needs the logs or sweep extra (pyarrow)")

import mujoco
import pandas as pd

from impact_balance.exceptions import ModelRepairWarning, SimulationError
from impact_balance.logs import read_log, write_log
from impact_balance.sim import SimOptions, build_model
from impact_balance.sim.trials.impact_trial import (
    TrialOptions,
    approach_joint_velocity,
    impact_limb,
    run_trial,
)
from impact_balance.sim.trials.log import log_frame
from impact_balance.sim.trials.measure import distance_to_hull, measure
from tests.helpers.cli import run_cli as run

LIGHT = SimOptions(meshes=False)


@pytest.fixture(scope="module")
def models():
    cache = {}

    def get(name: str, joints: str):
        if (name, joints) not in cache:
            with (
                warnings.catch_warnings()
            ):  # Romeo's and iCub's documented repairs (test_robots_sim checks them)
                warnings.simplefilter("ignore", ModelRepairWarning)
                cache[(name, joints)] = build_model(name, joints, LIGHT)
        return cache[(name, joints)]

    return get


@pytest.fixture(scope="module")
def rigid_push(models):
    sim = models("palm_push_two_feet", "rigid")
    record = run_trial(sim, TrialOptions(0.3, after=0.05))
    return sim, record, measure(sim, record, 0.3)


def test_distance_to_hull():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert distance_to_hull([0.5, 0.5], square) == 0.0
    assert distance_to_hull([2.0, 0.5], square) == pytest.approx(1.0)
    assert distance_to_hull([2.0, 2.0], square) == pytest.approx(np.sqrt(2))
    assert distance_to_hull([0.5, 1.0], np.array([[0, 0], [1, 0]], dtype=float)) == pytest.approx(
        1.0
    )


def test_rigid_jump_is_impulse_over_mass_and_inside_composite_set(rigid_push):
    sim, _record, result = rigid_push
    jump = result.com_velocity_jump_measured
    # Floating, gravity off: the only external force is the impact's (to the contact solver's
    # tolerance: MuJoCo's reported contact forces and the ones it integrated differ by ~1e-5).
    np.testing.assert_allclose(jump, result.impulse_measured[:2] / sim.mass, rtol=2e-4, atol=1e-9)
    assert result.approach_speed_measured == pytest.approx(0.3, rel=1e-6)
    assert 0.0 <= result.restitution_measured < 0.5
    # The impulse is in the friction cone (Coulomb, elliptic cone: exact).
    spec = sim.scenario.impact.spec()
    n = np.asarray(spec.normal) / np.linalg.norm(spec.normal)
    i_n = result.impulse_measured @ n
    assert i_n > 0
    assert np.linalg.norm(result.impulse_measured - i_n * n) <= spec.friction * i_n * (1 + 1e-6)
    # The contract (README): within 2 % of the jump's magnitude of the composite set.
    assert result.predicted["composite"].distance <= 0.02 * np.linalg.norm(jump)
    # The joint-space model (every joint free) predicts a far smaller jump for a welded robot.
    assert result.predicted["joint_space"].distance > 0.5 * np.linalg.norm(jump)
    assert result.contacts_kept is None


@pytest.mark.parametrize(
    "name,speed", [("kick_one_foot", 0.6), ("g1_two_feet", 0.1), ("palm_push_ramp", 0.6)]
)
def test_rigid_trial_other_scenarios(models, name, speed):
    sim = models(name, "rigid")
    result = measure(sim, run_trial(sim, TrialOptions(speed, after=0.05)), speed)
    jump = result.com_velocity_jump_measured
    assert np.linalg.norm(jump) > 0
    assert result.predicted["composite"].distance <= 0.02 * np.linalg.norm(jump)


def test_servo_trial_falls_near_the_joint_space_model(models):
    sim = models("palm_push_two_feet", "servo")
    assert impact_limb(sim) == [f"arm_right_{i}_joint" for i in range(1, 8)]
    result = measure(sim, run_trial(sim, TrialOptions(0.3, after=0.05)), 0.3)
    jump = np.linalg.norm(result.com_velocity_jump_measured)
    composite = np.linalg.norm(result.predicted["composite"].com_velocity_jumps, axis=1).min()
    assert result.contacts_kept is True
    assert result.approach_speed_measured == pytest.approx(0.3, rel=0.15)
    assert 0 < jump < 0.25 * composite  # the servo-held arm gives way: far below the rigid body
    assert result.predicted["joint_space"].distance < result.predicted["composite"].distance


@pytest.mark.parametrize(
    "name,speed", [("g1_two_feet", 0.75), ("romeo_two_feet", 0.75), ("palm_push_two_feet", 0.5)]
)
def test_servo_approach_starts_within_joint_limits_and_hits_after_it_begins(models, name, speed):
    """The retracted start pose is within the joints' ranges (G1's right wrist yaw and Romeo's right
    elbow yaw left them with the Jacobian's pseudo-inverse alone), and the impact is the commanded
    approach's: after the settling, near the commanded speed. A start pose beyond a limit is snapped
    back while the robot settles."""
    sim = models(name, "servo")
    spec = sim.scenario.impact.spec()
    n = np.asarray(spec.normal, dtype=float) / np.linalg.norm(spec.normal)
    limb = impact_limb(sim)
    options = TrialOptions(speed, after=0.02, rigid_impact=True)
    dq = approach_joint_velocity(sim, limb, n, options.resolved_gap())
    _, J6 = sim.stance.point(spec.frame, spec.offset)
    assert J6[:3] @ dq == pytest.approx(-n, abs=1e-9)  # unit approach speed along -n at the stance
    start = pin.integrate(
        sim.stance.model, sim.stance.q, -options.resolved_gap() * dq
    )  # the trial's start pose
    ids = [sim.model.joint(j).id for j in limb]
    q_index = [sim.q_index[sim.joint_names.index(j)] for j in limb]
    low, high = sim.model.jnt_range[ids].T
    assert np.all((start[q_index] >= low - 1e-9) & (start[q_index] <= high + 1e-9))
    record = run_trial(sim, options)
    result = measure(sim, record, speed)
    assert result.impact_time[0] > record.approach_start + 0.5 * options.resolved_gap() / speed
    assert result.approach_speed_measured == pytest.approx(speed, rel=0.2)


def test_servo_approach_beyond_joint_limits_is_refused(models):
    """iCub's right hand hangs at a near-singular pose (the point Jacobian's smallest singular value
    0.017 m/rad) with the shoulder pitch 0.085 rad from its limit: no straight joint path retracts
    the hand 5 cm along the wall's normal within the limits. The trial used to start the shoulder
    0.42 rad beyond its limit; MuJoCo snapped it back and the hand hit the wall at 1.09 m/s during
    the settling, 0.15 s before the commanded 0.5 m/s approach began."""
    sim = models("icub_two_feet", "servo")
    with pytest.raises(SimulationError, match="r_shoulder_pitch"):
        run_trial(sim, TrialOptions(0.5, after=0.02, rigid_impact=True))


def test_log_frame_matches_finite_differences(rigid_push, tmp_path):
    sim, record, _ = rigid_push
    frame = log_frame(sim, record)
    dt = sim.model.opt.timestep
    # Base linear velocity (world) and CoM velocity against the differences of the positions.
    for pos, vel in (
        (("base_x", "base_y", "base_z"), ("base_vx", "base_vy", "base_vz")),
        (("com_x", "com_y", "com_z"), ("comd_x", "comd_y", "comd_z")),
    ):
        p, v = frame[list(pos)].to_numpy(), frame[list(vel)].to_numpy()
        np.testing.assert_allclose(np.diff(p, axis=0) / dt, v[1:], atol=2e-3)
    # Base angular velocity (world axes): R_{k+1} = exp([w dt]) R_k after the impact (the robot
    # spins).
    q = frame[["base_qw", "base_qx", "base_qy", "base_qz"]].to_numpy()
    w = frame[["base_wx", "base_wy", "base_wz"]].to_numpy()
    k = len(frame) - 2
    assert np.linalg.norm(w[k + 1]) > 1e-3
    dq = np.empty(4)
    inv = np.empty(4)
    mujoco.mju_negQuat(inv, q[k])
    mujoco.mju_mulQuat(dq, q[k + 1], inv)  # world-frame rotation over one step
    axis_angle = np.empty(3)
    mujoco.mju_quat2Vel(axis_angle, dq, dt)
    np.testing.assert_allclose(axis_angle, w[k + 1], rtol=1e-3, atol=1e-6)
    assert frame["force_impact_x"].abs().max() > 0
    for joint in sim.robot.joint_names:
        assert f"q_{joint}" in frame and f"v_{joint}" in frame
    path = write_log(frame, tmp_path / "trial.csv")
    back = read_log(path)
    pd.testing.assert_frame_equal(back, frame, check_exact=False, rtol=1e-12)


def test_cli_json_single_and_list(capsys):
    rc, out, err = run(
        capsys, "simulate", "kick_one_foot", "--speed", "0.3", "--duration", "0.03", "--json"
    )
    assert rc == 0, err
    doc = json.loads(out, parse_constant=lambda c: pytest.fail(c))
    assert doc["joints"] == "rigid" and doc["approach_speed"] == 0.3
    for model in ("composite", "joint_space"):
        jumps = np.asarray(doc["predicted"][model]["com_velocity_jumps"])
        assert jumps.shape == (32, 2)
    assert len(doc["impulse_measured"]) == 3 and len(doc["com_velocity_jump_measured"]) == 2
    assert doc["contacts_kept"] is None and doc["sim_time_ratio"] > 0
    rc, out, _ = run(
        capsys, "simulate", "kick_one_foot", "--speed", "0.1,0.2", "--duration", "0.03", "--json"
    )
    docs = json.loads(out)
    assert [d["approach_speed"] for d in docs] == [0.1, 0.2]


def test_cli_text_plots_and_log(capsys, tmp_path):
    rc, out, err = run(
        capsys,
        "simulate",
        "palm_push_two_feet",
        "--duration",
        "0.03",
        "--plots",
        str(tmp_path),
        "--log",
        str(tmp_path / "log.parquet"),
    )
    assert rc == 0, err
    assert "composite (predicted)" in out and "joint_space (predicted)" in out
    pngs = sorted(tmp_path.glob("*.png"))
    assert len(pngs) == 2 and all(p.read_bytes()[:4] == b"\x89PNG" for p in pngs)
    assert "force_impact_z" in read_log(tmp_path / "log.parquet")


@pytest.mark.parametrize(
    "argv,needles",
    [
        (["--speed", "0"], ["--speed", "approach speed"]),
        (["--speed", "-1"], ["--speed"]),
        (["--speed", "100"], ["--speed"]),
        (["--speed", "fast"], ["--speed", "not a number"]),
        (["--joints", "springy"], ["--joints", "rigid, servo"]),
        (["--duration", "0"], ["--duration"]),
        (["--log", "x.txt"], ["--log"]),
        (["--video", "x.avi"], ["--video"]),
    ],
)
def test_cli_bad_input_is_one_line(capsys, argv, needles):
    rc, _out, err = run(capsys, "simulate", "palm_push_two_feet", *argv)
    assert rc == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    for needle in needles:
        assert needle in err


def test_cli_scenario_without_impact(capsys, tmp_path):
    path = tmp_path / "no_impact.yaml"
    path.write_text("extends: palm_push_two_feet\nimpact: null\n")
    rc, _, err = run(capsys, "simulate", str(path))
    assert rc == 2 and "no impact" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_cli_video(tmp_path):
    """Offscreen MP4 in a fresh process (MUJOCO_GL must be set before MuJoCo is imported)."""
    from tests.helpers.cli import run_process

    video = tmp_path / "trial.mp4"
    proc = run_process(
        "simulate", "kick_one_foot", "--speed", "0.6", "--duration", "0.01", "--video", str(video)
    )
    if proc.returncode != 0:
        # Without a GL backend: one clear line, no traceback.
        assert proc.returncode == 2 and "Traceback" not in proc.stderr and "--video" in proc.stderr
        pytest.skip(f"no offscreen GL here: {proc.stderr.strip()}")
    import imageio.v2 as imageio

    reader = imageio.get_reader(video)
    frame = reader.get_data(0)
    assert frame.shape[2] == 3 and frame.std() > 5  # a picture, not a blank frame


def test_armature_enters_gains_and_joint_space_prediction():
    import pinocchio as pin

    from impact_balance.robot.robot import load_robot
    from impact_balance.sim import ServoOptions
    from impact_balance.sim.trials.measure import _stance_with_armature

    shared = load_robot("talos").model.armature.copy()
    sim = build_model(
        "kick_one_foot", "servo", SimOptions(meshes=False, servo=ServoOptions(armature=0.3))
    )
    bare = pin.Model(sim.stance.model)
    bare.armature[:] = 0.0
    M = pin.crba(bare, bare.createData(), sim.stance.q)
    w = sim.options.servo.bandwidth
    np.testing.assert_allclose(sim.kp, (M[sim.v_index, sim.v_index] + 0.3) * w**2, rtol=1e-9)
    np.testing.assert_allclose(sim.model.dof_armature[sim.dof_adr], 0.3)
    assert sim.armature_source.startswith("--armature 0.3")
    stance = _stance_with_armature(sim)
    M2 = pin.crba(stance.model, stance.model.createData(), stance.q)
    np.testing.assert_allclose(np.diag(M2 - M)[sim.v_index], 0.3, atol=1e-12)
    np.testing.assert_array_equal(
        sim.robot.model.armature, shared
    )  # the shared robot model keeps its own


def test_declared_rotor_inertia_is_the_default_armature():
    """Talos's SRDF declares rotor_params (rotor inertia 1e-5 kg m^2, gear ratio 100): 0.1 kg m^2
    per joint."""
    import xml.etree.ElementTree as ET

    sim = build_model("palm_push_two_feet", "servo", SimOptions(meshes=False))
    root = ET.parse(sim.robot.srdf_path).getroot()
    declared = {
        j.get("name"): float(j.get("gear_ratio")) ** 2 * float(j.get("mass"))
        for j in root.iter("joint")
        if j.get("gear_ratio") is not None
    }
    expected = [declared.get(name, 0.0) for name in sim.joint_names]
    np.testing.assert_allclose(sim.model.dof_armature[sim.dof_adr], expected, rtol=1e-12)
    np.testing.assert_allclose(sim.armature, expected, rtol=1e-12)
    assert "rotor_params" in sim.armature_source and sim.robot.armature_source is not None
    g1 = build_model("g1_two_feet", "servo", SimOptions(meshes=False))
    assert not g1.armature.any() and "none declared" in g1.armature_source


def test_cli_unusable_gl_backend_is_one_line(tmp_path):
    import os
    import subprocess
    import sys

    env = dict(os.environ, MUJOCO_GL="no-such-backend")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "impact_balance",
            "simulate",
            "kick_one_foot",
            "--duration",
            "0.01",
            "--video",
            str(tmp_path / "v.mp4"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()] and "MUJOCO_GL" in proc.stderr
    assert "Traceback" not in proc.stderr
