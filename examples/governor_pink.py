"""An impact-speed governor in a pink IK loop: the palm sent at a wall, its speed capped every tick.

The paper's Algorithm 1 ends with "track the maximum contact velocity with a whole-body QP".
Here the whole-body controller is pink's differential IK (the kinematic robot of the paper):
at every tick (500 Hz) it is given a frame task that moves the impacting frame towards the
wall at the reference speed, the contacts held and the CoM kept over the feet. Before the IK
step, :class:`impact_balance.governor.Governor` reads the state ``(q, v)`` and caps the
reference velocity so that an impact at the commanded speed keeps the robot balanced; the
frame task follows the capped velocity. Without a simulator, the state is the IK's own
(``q`` integrated, ``v`` the IK's velocity), so this shows the API and the cost, not a fall:
``impact-balance approach`` runs the same loop on a simulated robot.

    python examples/governor_pink.py [--scenario palm_push_two_feet] [--reference 0.8] [--ticks 150]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pink
import pinocchio as pin
from pink.tasks import ComTask, FrameTask, PostureTask

from impact_balance.governor import Governor
from impact_balance.scenario import load_scenario


def run(
    scenario_name: str = "palm_push_two_feet",
    reference: float = 0.8,
    ticks: int = 150,
    rate: float = 500.0,
    criterion: str = "com",
) -> dict:
    """Drive the impact frame at ``reference`` m/s towards the scenario's wall for ``ticks`` ticks.

    Returns the per-tick arrays: ``commanded`` and ``cap`` (approach speeds, m/s), ``measured``
    (the impact point's approach speed from the IK's velocity, m/s) and ``tick_us`` (the
    governor's time)."""
    scenario = load_scenario(scenario_name)
    governor = Governor(scenario, criterion=criterion)  # once: robot, contacts, impact, margin
    robot = governor.robot
    model = robot.model
    q = governor.configuration.copy()  # the scenario's posture (a controller gives its own)
    configuration = pink.Configuration(model, model.createData(), q)
    impact = scenario.impact.spec()
    n = np.asarray(impact.normal, dtype=float) / np.linalg.norm(impact.normal)
    offset = impact.offset

    contacts = []
    for c in scenario.contacts:  # hold every sustained contact where it is
        task = FrameTask(c.frame, position_cost=10.0, orientation_cost=10.0)
        task.set_target(configuration.get_transform_frame_to_world(c.frame))
        contacts.append(task)
    com = ComTask(cost=10.0)
    com.set_target(pin.centerOfMass(model, configuration.data, q))
    posture = PostureTask(cost=1e-2)
    posture.set_target(q)
    hand = FrameTask(impact.frame, position_cost=1.0, orientation_cost=0.1)
    pose = configuration.get_transform_frame_to_world(impact.frame)

    dt = 1.0 / rate
    v = np.zeros(model.nv)
    out = {"commanded": [], "cap": [], "measured": [], "tick_us": []}
    u_ref = -reference * n  # the reference end-effector velocity (world): straight at the wall
    for _ in range(ticks):
        t0 = time.perf_counter()
        limit = governor.limit(
            configuration.q, v
        )  # the state: pinocchio q, v (base velocity in the base frame)
        u = limit.cap(u_ref)  # the reference, its approach speed within the safe interval
        out["tick_us"].append(1e6 * (time.perf_counter() - t0))
        out["commanded"].append(float(-u @ n))
        out["cap"].append(limit.ceiling)
        # The frame task follows the capped velocity: its target moves by u dt each tick.
        pose = pin.SE3(pose.rotation, pose.translation + u * dt)
        hand.set_target(pose)
        v = pink.solve_ik(
            configuration, [hand, com, posture, *contacts], dt, solver="daqp", safety_break=False
        )
        q_next = pin.integrate(model, configuration.q, v * dt)
        # pink's limits keep the step inside up to round-off: clip that round-off away.
        q_next[7:] = np.clip(q_next[7:], model.lowerPositionLimit[7:], model.upperPositionLimit[7:])
        configuration.update(q_next)
        pin.forwardKinematics(model, configuration.data, configuration.q, v)
        frame_velocity = pin.getFrameVelocity(
            model,
            configuration.data,
            model.getFrameId(impact.frame),
            pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
        )
        arm = configuration.get_transform_frame_to_world(impact.frame).rotation @ offset.translation
        point_velocity = frame_velocity.linear + np.cross(frame_velocity.angular, arm)
        out["measured"].append(float(-point_velocity @ n))
    return {k: np.asarray(x) for k, x in out.items()}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="palm_push_two_feet")
    p.add_argument("--reference", type=float, default=0.8, help="reference approach speed, m/s")
    p.add_argument("--ticks", type=int, default=150)
    p.add_argument("--criterion", default="com", choices=("com", "zmp"))
    args = p.parse_args(argv)
    r = run(args.scenario, args.reference, args.ticks, criterion=args.criterion)
    late = slice(len(r["measured"]) // 2, None)
    print(f"{args.scenario}: reference {args.reference:g} m/s, {args.criterion} governor")
    print(
        f"  cap {r['cap'][-1]:.3f} m/s; commanded {r['commanded'][-1]:.3f} m/s; "
        f"the IK's approach speed {np.median(r['measured'][late]):.3f} m/s (median, second half)"
    )
    print(
        f"  governor: {np.median(r['tick_us']):.0f} us per tick (median), "
        f"{np.percentile(r['tick_us'], 99):.0f} (p99)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
