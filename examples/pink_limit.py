"""The governor's cap as a constraint of pink's IK QP: the palm sent at a wall, too fast.

The paper's Algorithm 1 ends with "track the maximum contact velocity with a whole-body QP".
Here the QP is pink's differential IK: the palm's frame task is given a target that runs at
the wall at ``--reference`` m/s (far above what the robot can take), the feet are held and the
CoM kept over them. :class:`~impact_balance.governor.pink_limit.PinkApproachLimit` puts the
governor's cap in the QP as one inequality, ``-n . J Δq <= cap * dt``: the task asks for the
reference, the QP gives the cap. Without a simulator, the state is the IK's own (``q``
integrated, ``v`` the IK's velocity); ``impact-balance approach`` runs a simulated robot.

    python examples/pink_limit.py [--scenario palm_push_two_feet] [--reference 1.5]
        [--wall 0.1] [--steps 200]
"""

from __future__ import annotations

import argparse

import numpy as np
import pink
import pinocchio as pin
from pink.tasks import ComTask, FrameTask, PostureTask

from impact_balance.governor import Governor
from impact_balance.governor.pink_limit import PinkApproachLimit


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
    model = governor.robot.model
    configuration = pink.Configuration(model, model.createData(), governor.configuration)
    limit = PinkApproachLimit(governor, model)
    limits = [model.configuration_limit, model.velocity_limit] + ([limit] if limited else [])
    impact = governor.scenario.impact.spec()
    held = [
        FrameTask(c.frame, position_cost=10.0, orientation_cost=10.0) for c in governor.contacts
    ]
    for task in held:
        task.set_target_from_configuration(configuration)
    com = ComTask(cost=10.0)
    com.set_target(pin.centerOfMass(model, configuration.data, configuration.q))
    posture = PostureTask(cost=0.1)
    posture.set_target(configuration.q)
    hand = FrameTask(impact.frame, position_cost=1.0, orientation_cost=0.1)
    target = configuration.get_transform_frame_to_world(impact.frame)
    hand.set_target(target)

    dt = 1.0 / rate
    first = governor.limit(configuration.q, np.zeros(model.nv))
    n, surface = first.normal, float(first.normal @ first.point) - wall  # n . x = surface: the wall
    v = np.zeros(model.nv)
    out: dict[str, list[float]] = {"commanded": [], "cap": [], "distance": [], "measured": []}
    distance = wall
    for _ in range(steps):
        target = pin.SE3(target.rotation, target.translation - reference * dt * n)  # uncapped
        hand.set_target(target)
        limit.velocity = v  # the state the governor reads: the IK's last velocity
        if not limited:  # the cap, recorded only
            limit.compute_qp_inequalities(configuration, dt)
        v = pink.solve_ik(
            configuration, [hand, com, posture, *held], dt, solver="daqp", limits=limits,
            safety_break=False,
        )  # fmt: skip
        row = limit.last
        out["commanded"].append(float(row.G[0] @ v))
        out["cap"].append(row.limit.ceiling)
        q = pin.integrate(model, configuration.q, v * dt)
        q[7:] = np.clip(q[7:], model.lowerPositionLimit[7:], model.upperPositionLimit[7:])
        configuration.update(q)
        out["distance"].append(float(n @ limit.point.position(configuration.data)) - surface)
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
    print(f"{args.scenario}: reference {args.reference:g} m/s, pink IK with the cap as a limit")
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
