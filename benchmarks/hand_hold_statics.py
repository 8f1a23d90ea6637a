"""Can a stance's contacts hold its start posture still, under the id controller's own limits?

One LP per stance (HiGHS through scipy): the contact wrenches (world axes, at each contact point)
that carry the robot's weight with no CoM acceleration, inside each contact's wrench cone
(friction ``scale`` x the scenario's, the centre of pressure in the face), each contact's normal
force at least ``f_min``; it minimises the largest component of the moment about the CoM
(N m), the angular momentum rate the contacts cannot avoid. 0 means the posture can be held with
no angular momentum; > 0 means the controller (which keeps the CoM still first) must spin the
body. The arm's torque limits are not in the LP (see docs/studies/hand-contacts.md).

    python benchmarks/hand_hold_statics.py studies/held_out_9/*.yaml
    # the criterion's cones: --scale 1 --min-normal-force 0
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

import numpy as np
from scipy.optimize import linprog

from impact_balance.analysis.analyze import analyze
from impact_balance.constants import GRAVITY
from impact_balance.contacts.cwc import cwc_faces_world
from impact_balance.scenario.load import load_scenario


def residual_moment(
    stance: Any,
    scale: float,
    min_normal_force: float,
    torque_limits: bool = True,
    com_acceleration: tuple[float, float] = (0.0, 0.0),
) -> dict[str, Any]:
    """The smallest max-norm moment about the CoM (N m) and the wrenches that reach it.

    ``com_acceleration``: the CoM's horizontal acceleration (m/s^2, world) the contacts must give,
    the LIPM's ``omega^2 (c - z)`` for a desired ZMP ``z``.
    ``torque_limits``: the actuated joints' quasi-static torques ``g_a(q) - (sum J_i^T w_i)_a``
    within the URDF's effort limits (the criterion's ``torque_limits: true`` rows).
    """
    contacts, com, mass = stance.contacts, np.asarray(stance.com, float), float(stance.mass)
    nc = len(contacts)
    n = 6 * nc + 1  # wrenches, then the bound t on |moment|
    A_ub, b_ub, A_eq, b_eq = [], [], [], []
    force_rows, moment_rows = np.zeros((3, n)), np.zeros((3, n))
    for i, ct in enumerate(contacts):
        faces = cwc_faces_world(
            scale * ct.spec.friction, ct.half_length, ct.half_width, ct.rotation
        )
        block = np.zeros((16, n))
        block[:, 6 * i : 6 * i + 6] = faces
        A_ub.extend(block)
        b_ub.extend(np.zeros(16))
        row = np.zeros(n)
        row[6 * i : 6 * i + 3] = -ct.normal
        A_ub.append(row)
        b_ub.append(-min_normal_force)
        r = np.asarray(ct.position, float) - com
        skew = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        force_rows[:, 6 * i : 6 * i + 3] = np.eye(3)
        moment_rows[:, 6 * i : 6 * i + 3] = skew
        moment_rows[:, 6 * i + 3 : 6 * i + 6] = np.eye(3)
    if torque_limits:
        idx, effort = stance.robot.actuated_effort_limits()
        jt = np.zeros((idx.size, n))
        for i, ct in enumerate(contacts):
            jt[:, 6 * i : 6 * i + 6] = -np.asarray(ct.jacobian)[:, idx].T
        g = np.asarray(stance.gravity_torques)[idx]
        A_ub.extend(jt)
        b_ub.extend(effort - g)
        A_ub.extend(-jt)
        b_ub.extend(effort + g)
    A_eq.extend(force_rows)
    b_eq.extend([mass * com_acceleration[0], mass * com_acceleration[1], mass * GRAVITY])
    for sign in (1.0, -1.0):
        block = sign * moment_rows.copy()
        block[:, -1] = -1.0
        A_ub.extend(block)
        b_ub.extend(np.zeros(3))
    cost = np.zeros(n)
    cost[-1] = 1.0
    res = linprog(
        cost,
        np.array(A_ub),
        np.array(b_ub),
        np.array(A_eq),
        np.array(b_eq),
        bounds=[(None, None)] * n,
        method="highs",
    )
    if res.status != 0:
        return {"feasible": False, "status": res.message}
    w = res.x[:-1].reshape(nc, 6)
    return {
        "feasible": True,
        "max_moment": float(res.x[-1]),
        "moment": (moment_rows[:, :-1] @ res.x[:-1]).round(3).tolist(),
        "normal_forces": {
            ct.spec.frame: float(ct.normal @ w[i, :3]) for i, ct in enumerate(contacts)
        },
    }


def main(argv: list[str] | None = None) -> int:
    """Print one line per scenario."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenarios", nargs="+")
    p.add_argument("--no-torque-limits", action="store_true")
    p.add_argument("--com-acceleration", nargs=2, type=float, default=(0.0, 0.0))
    p.add_argument("--scale", type=float, default=0.65, help="friction scale (id: 0.65)")
    p.add_argument(
        "--min-normal-force",
        type=float,
        default=None,
        help="N (default: the id controller's, max(0.0225 m g, 2 N))",
    )
    args = p.parse_args(argv)
    for path in args.scenarios:
        stance = analyze(load_scenario(path)).stance
        f_min = args.min_normal_force
        if f_min is None:
            f_min = max(0.0225 * float(stance.mass) * GRAVITY, 2.0)
        out = residual_moment(
            stance, args.scale, f_min, not args.no_torque_limits, tuple(args.com_acceleration)
        )
        print(path.split("/")[-1], f"f_min {f_min:.1f} N", out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
