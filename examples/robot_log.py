"""Check a robot's recorded motion against the balance criteria (as ``impact-balance check-log``).

A real robot records its base pose and velocity (from its state estimator) and its joint
encoders. This example turns such arrays into a log with the column names of
``impact_balance.logs.schema``, writes it as Parquet, and checks it against the areas of the
stance. The motion here is synthetic, so that the answer is known: Talos, standing on two feet,
is given a growing forward speed until its CoM velocity leaves the CoM velocity area. Replace
:func:`record` with your robot's arrays.

    python examples/robot_log.py [--out sway.parquet] [--scenario palm_push_two_feet]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import impact_balance as ib
from impact_balance.logs import (
    LogColumns,
    check_log,
    joint_position_column,
    joint_velocity_column,
    read_log,
    write_log,
)


def record(scenario: ib.Scenario, duration: float = 2.0, rate: float = 200.0, peak: float = 0.5):
    """Synthetic arrays: the robot at its stance while its forward speed grows from 0 to ``peak``
    (m/s) over ``duration`` (s), as the first instants after a push would log it (the robot has
    not moved yet, its CoM velocity has). The whole body moves as one: every joint still.

    Returns ``(time (T,), q (T, nq), v (T, nv))``: ``q`` in pinocchio's convention (free-flyer
    base ``[x, y, z, qx, qy, qz, qw]``, then the joints), ``v`` with the base's linear and
    angular velocity in WORLD axes (what most state estimators give; rotate a base-frame
    velocity by the base orientation first), then the joint velocities."""
    stance = scenario.build_stance()
    time = np.arange(0.0, duration, 1.0 / rate)
    q = np.tile(stance.q, (time.size, 1))
    v = np.zeros((time.size, stance.robot.model.nv))
    v[:, 0] = peak * time / duration
    return time, q, v


def to_log(robot: ib.Robot, time: np.ndarray, q: np.ndarray, v: np.ndarray) -> pd.DataFrame:
    """A log table (columns of ``impact_balance.logs.schema``) from the arrays of :func:`record`."""
    cols = LogColumns()
    data = {cols.time: time}
    for k, name in enumerate(cols.base_position + cols.base_quaternion):
        data[name] = q[:, k]
    for k, name in enumerate(cols.base_linear_velocity + cols.base_angular_velocity):
        data[name] = v[:, k]
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        data[joint_position_column(name)] = q[:, slot.idx_q]
        data[joint_velocity_column(name)] = v[:, robot.model.joints[slot.id].idx_v]
    return pd.DataFrame(data)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="sway.parquet", help="the log to write (.parquet or .csv)")
    parser.add_argument(
        "--scenario", default="palm_push_two_feet", help="the stance (bundled name or YAML file)"
    )
    args = parser.parse_args(argv)

    scenario = ib.load_scenario(args.scenario)
    robot = scenario.load_robot()
    time, q, v = record(scenario)
    path = write_log(to_log(robot, time, q, v), Path(args.out), {"scenario": scenario.name})
    check = check_log(read_log(path), scenario)
    print(f"{path}: {len(time)} samples over {time[-1]:.2f} s")
    for violation in check.violations:
        unit = "m/s" if violation.kind == "com_velocity" else "m"
        print(
            f"  {violation.kind} outside its area from {violation.start:.3f} s to "
            f"{violation.end:.3f} s, worst margin {violation.worst_margin:.3f} {unit}"
        )
    if not check.violations:
        print("  the CoM velocity stayed inside the CoM velocity area")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
