"""The governor's cap as a constraint of mink's IK QP, on MuJoCo: the palm sent at a wall, too fast.

mink solves differential IK on a MuJoCo model (here impact-balance's MuJoCo reading of the
scenario's URDF, as ``simulate`` builds it). The palm's frame task is given a target that runs
at the wall at ``--reference`` m/s, the feet are held and the CoM kept over them.
:class:`~impact_balance.governor.mink_limit.MinkApproachLimit` puts the governor's cap in the
QP as one inequality, ``-n . J Δq <= cap * dt``: the task asks for the reference, the QP gives
the cap. The state the governor reads is the configuration's (``data.qvel``, written with the
IK's velocity each step). Needs the ``mink`` and ``sim`` extras.

    python examples/mink_limit.py [--scenario palm_push_two_feet] [--reference 1.5]
        [--wall 0.1] [--steps 200]
"""

from __future__ import annotations

import argparse

import mink
import mujoco
import numpy as np
import pinocchio as pin

from impact_balance.governor import Governor
from impact_balance.governor.mink_limit import MinkApproachLimit
from impact_balance.sim.model.urdf import robot_spec


def mujoco_model(governor: Governor, frames: list[str]) -> mujoco.MjModel:
    """The governor's robot in MuJoCo (no meshes), with a site on each of ``frames``."""
    model = governor.robot.model
    spec, _ = robot_spec(governor.robot, meshes=False)
    for name in frames:
        frame = model.frames[model.getFrameId(name)]
        joint = frame.parentJoint  # 1: the free flyer, whose body is the URDF's root link
        body = spec.worldbody.first_body() if joint == 1 else spec.joint(model.names[joint]).parent
        x, y, z, w = pin.Quaternion(frame.placement.rotation).coeffs()
        body.add_site(name=name, pos=frame.placement.translation, quat=[w, x, y, z])
    return spec.compile()


def run(
    scenario: str = "palm_push_two_feet",
    reference: float = 1.5,
    wall: float = 0.1,
    steps: int = 200,
    rate: float = 500.0,
    limited: bool = True,
) -> dict[str, np.ndarray]:
    """Send the impact point at a wall ``wall`` m ahead at ``reference`` m/s, for ``steps`` ticks.

    Returns per-tick arrays: ``commanded`` (the QP's approach speed ``-n . J v``, m/s), ``cap``
    (the governor's ceiling, m/s), ``distance`` (the point to the wall after the tick, m) and
    ``measured`` (the point's approach speed over the tick, from its positions, m/s); the loop
    stops at the tick the point reaches the wall. ``limited=False`` leaves the cap out of the QP
    (for comparison: the point then goes at the reference)."""
    governor = Governor(scenario)
    impact = governor.scenario.impact.spec()
    feet = [c.frame for c in governor.contacts]
    mj_model = mujoco_model(governor, [*feet, impact.frame])
    limit = MinkApproachLimit(governor, mj_model)
    configuration = mink.Configuration(mj_model)
    configuration.update(limit.state.qpos(governor.configuration, configuration.data.qpos))
    limits = [mink.ConfigurationLimit(mj_model)] + ([limit] if limited else [])
    held = [mink.FrameTask(f, "site", position_cost=10.0, orientation_cost=10.0) for f in feet]
    com = mink.ComTask(cost=10.0)
    posture = mink.PostureTask(mj_model, cost=0.1)
    hand = mink.FrameTask(impact.frame, "site", position_cost=1.0, orientation_cost=0.1)
    for task in [*held, com, posture, hand]:
        task.set_target_from_configuration(configuration)
    target = configuration.get_transform_frame_to_world(impact.frame, "site")

    data = governor.robot.model.createData()
    dt = 1.0 / rate
    first = governor.limit(governor.configuration, np.zeros(governor.nv))
    n, surface = first.normal, float(first.normal @ first.point) - wall  # n . x = surface: the wall
    out: dict[str, list[float]] = {"commanded": [], "cap": [], "distance": [], "measured": []}
    distance = wall
    for _ in range(steps):
        target = mink.SE3.from_rotation_and_translation(
            target.rotation(), target.translation() - reference * dt * n
        )  # uncapped: the reference runs ahead
        hand.set_target(target)
        if not limited:  # the cap, recorded only
            limit.compute_qp_inequalities(configuration, dt)
        velocity = mink.solve_ik(
            configuration, [*held, com, posture, hand], dt, "daqp", limits=limits
        )
        G = limit.state.columns(configuration.data.qpos, limit.last.G)
        out["commanded"].append(float(G[0] @ velocity))
        out["cap"].append(limit.last.limit.ceiling)
        configuration.integrate_inplace(velocity, dt)
        configuration.data.qvel[:] = velocity  # the state the governor reads next step
        pin.forwardKinematics(governor.robot.model, data, limit.state.q(configuration.data.qpos))
        point = limit.point.position(data)
        out["distance"].append(float(n @ point) - surface)
        out["measured"].append((distance - out["distance"][-1]) / dt)
        distance = out["distance"][-1]
        if distance <= 0.0:
            break
    return {k: np.asarray(x) for k, x in out.items()}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="palm_push_two_feet")
    p.add_argument("--reference", type=float, default=1.5, help="reference approach speed, m/s")
    p.add_argument("--wall", type=float, default=0.1, help="the wall's distance ahead, m")
    p.add_argument("--steps", type=int, default=200, help="IK steps at 500 Hz (at most)")
    args = p.parse_args(argv)
    if args.steps < 1:
        p.error(f"--steps = {args.steps}: must be at least 1")
    for name in ("reference", "wall"):
        value = getattr(args, name)
        if not (np.isfinite(value) and 0.0 < value <= 100.0):
            p.error(f"--{name} = {value:g}: must be a number in (0, 100]")
    r = run(args.scenario, args.reference, args.wall, args.steps)
    ratio = r["commanded"] / r["cap"]
    hit = r["distance"][-1] <= 0.0
    print(
        f"{args.scenario}: reference {args.reference:g} m/s, "
        "mink IK (MuJoCo) with the cap as a limit"
    )
    print(
        f"  {len(ratio)} steps; commanded / cap: max {ratio.max():.4f}; "
        + (
            f"at the wall {r['commanded'][-1]:.3f} m/s commanded, {r['measured'][-1]:.3f} "
            f"travelled, cap {r['cap'][-1]:.3f} m/s"
            if hit
            else f"the wall not reached ({r['distance'][-1]:.3f} m left)"
        )
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
