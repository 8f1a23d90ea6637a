"""One validate-like impact trial, per control step: the id QP's plan beside MuJoCo.

The measurement of "iCub's wall hold (set 11), after the fact" in docs/studies/hand-contacts.md.
``validate``'s trial (``run_balance_trial(setup, impact_speed=v)``, the ``id`` controller, the
:class:`~impact_balance.sim.control.approach.ImpactTask` approach from the retracted start) at one
commanded speed, logged every control step with ``benchmarks/hand_contact.py``'s rows (every
contact's planned and realised normal force, CoP and tangential force, the desired ZMP and whether
it is clamped, the CoM velocity's margin in the scenario's area, the base's rotation, the joints at
their effort limit) and, added here:

- ``com``, ``dcm`` and the desired ZMP's margins (m) in the controller's own clamp area
  (``controller.feedback.zmp_area``: the QP's contact model on this tree, the scenario's
  full-friction area on set 10's) and in the scenario's ZMP support area;
- the impact task: its phase (``approach``, ``withdraw``), whether the touching point is a
  contact of the QP (``touching``) and its planned force (``touch_force_planned``, N, world;
  zero outside the contact, None without ``--touch-contact``), the measured normal force at the
  impact point (N), the point's tracking error to the task's reference (m, world) and its
  velocity along the normal (m/s, positive towards the surface);
- the joints within ``--limit-tol`` rad of a position limit;
- the planned and realised moment of the contact forces about the CoM (``hand_contact``'s
  ``angular_momentum_rate_*``, N m, world).

    nice -n 5 python benchmarks/approach_log.py \
        studies/held_out_11/icub_right_hand_wall_left_palm_oblique_side.yaml --speed 0.02
    # the id controller's touch contact (the touching point a contact of its QP):
    nice -n 5 python benchmarks/approach_log.py ... --speed 0.02 --touch-contact
    # set 10's controller (before the clamp change), the same script:
    PYTHONPATH=/work/wt/frozen10/src python benchmarks/approach_log.py ... --speed 0.02

It prints the trial's outcome, the start's margins, the first time each watched quantity crosses
its threshold (``firsts``), then every ``--every``-th row. Nothing here is part of the library:
the controller's ``step`` is wrapped for the trial's duration.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

# Run as a file, only the script's folder is on sys.path: put the repository root first,
# for the ``benchmarks`` package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.hand_contact import _Log, _realised, step_replaced
from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions


def _margin(polygon: Any, point: np.ndarray) -> float:
    """Signed distance (m) of ``point`` inside ``polygon`` (negative outside)."""
    return float(np.min(polygon.margins(np.asarray(point, dtype=float)[None, :2])))


class _ApproachLog(_Log):
    """``hand_contact``'s rows plus the approach's own (see the module docstring)."""

    def __init__(self, sim: Any, contact: int, analysis: Any, limit_tol: float) -> None:
        super().__init__(sim, contact, analysis)
        self.limit_tol = limit_tol

    def add_step(
        self, c: InverseDynamicsController, t: float, q: np.ndarray, v: np.ndarray, fn: float
    ) -> None:
        """One control step, after the QP: ``_Log.add`` and the approach's fields."""
        out = c.last
        assert out is not None
        self.add(c, t, v, out)
        row = self.rows[-1]
        clamp, scenario = c.feedback.zmp_area, self.analysis.areas.zmp_area
        if not hasattr(self, "clamp_vertices"):
            self.clamp_vertices = np.asarray(clamp.vertices).round(4).tolist()
        com = np.asarray(out.com)
        row["com"] = com.tolist()
        row["com_margin_clamp"] = _margin(clamp, com)
        row["dcm_margin_clamp"] = _margin(clamp, out.dcm)
        row["desired_zmp_margin_clamp"] = _margin(clamp, out.zmp)
        row["desired_zmp_margin_scenario"] = _margin(scenario, out.zmp)
        row.update(self._impact(c, t, v, fn))
        row["at_position_limit"] = self._limits(c, q)
        R0 = pin.XYZQUATToSE3(c.q0[:7]).rotation
        row["base_rotation_world"] = (R0 @ pin.log3(R0.T @ c.data.oMi[1].rotation)).tolist()
        # The motors add D qdot (the joints' viscous damping, cancelled) to the QP's torque: at
        # |D qdot| >= effort the motor has nothing left for the QP (iCub's wrists: D = 1 N m s/rad,
        # effort 0.45 to 0.65 N m).
        damping = c._damping_rows * np.abs(np.asarray(v)[6:])
        row["damping_saturated"] = [
            c.model.names[j.id]
            for j in c.model.joints[2:]
            if j.nv == 1 and damping[j.idx_v - 6] >= c.effort[j.idx_v - 6]
        ]
        row["q"] = np.asarray(q).tolist()
        row["v"] = np.asarray(v).tolist()

    def _impact(
        self, c: InverseDynamicsController, t: float, v: np.ndarray, fn: float
    ) -> dict[str, Any]:
        task = c.impact
        if task is None:
            return {}
        placement = c.data.oMf[c._impact_frame] * task.offset
        J = pin.getFrameJacobian(c.model, c.data, c._impact_frame, pin.LOCAL_WORLD_ALIGNED)
        r = placement.translation - c.data.oMf[c._impact_frame].translation
        vel = J[:3] @ v + np.cross(J[3:] @ v, r)
        target = task.reference(t, 0.0)[0]  # 0 N: never marks the contact itself
        n = np.asarray(task.normal, dtype=float)
        sim = self.sim
        planned = c.last.touch_force if c.last is not None else None
        return {
            "impact_phase": "approach" if task.contact_time is None else "withdraw",
            "touching": c.touching,
            "touch_force_planned": None if planned is None else np.asarray(planned).tolist(),
            "impact_normal_force": float(fn),
            "impact_tracking_error": float(np.linalg.norm(target - placement.translation)),
            "impact_error_along_normal": float(n @ (placement.translation - target)),
            "impact_speed_to_surface": float(-n @ vel),
            "impact_geom_force": float(
                np.linalg.norm(_realised(sim, sim.impact_geom, placement.translation)[0])
            ),
        }

    def _limits(self, c: InverseDynamicsController, q: np.ndarray) -> list[str]:
        m = c.model
        names = []
        for j in m.joints[2:]:
            if j.nq != 1:
                continue
            lo, hi = m.lowerPositionLimit[j.idx_q], m.upperPositionLimit[j.idx_q]
            if min(q[j.idx_q] - lo, hi - q[j.idx_q]) < self.limit_tol:
                names.append(m.names[j.id])
        return names


def _logged(log: _ApproachLog) -> contextlib.AbstractContextManager[None]:
    """Wrap the id controller's step for the trial's duration."""

    def wrap(step: Callable[..., Any]) -> Callable[..., Any]:
        def logged_step(
            self: InverseDynamicsController,
            t: float,
            q: Any,
            v: Any,
            zmp: Any = None,
            impact_force: float = 0.0,
        ) -> Any:
            out = step(self, t, q, v, zmp, impact_force)
            self.last = out
            log.add_step(self, t, q, v, impact_force)
            return out

        return logged_step

    return step_replaced(wrap)


def _firsts(rows: list[dict[str, Any]], min_normal: float) -> dict[str, Any]:
    """The first time (s) each watched quantity crosses its threshold, and its row's value."""
    tests: dict[str, Any] = {
        "zmp_clamped": lambda r: r["zmp_clamped"],
        "impact_force_over_1N": lambda r: r.get("impact_normal_force", 0.0) > 1.0,
        "withdraw": lambda r: r.get("impact_phase") == "withdraw",
        "touch_contact": lambda r: bool(r.get("touching")),
        "com_outside_clamp": lambda r: r["com_margin_clamp"] < 0.0,
        "dcm_outside_clamp": lambda r: r["dcm_margin_clamp"] < 0.0,
        "base_rotation_over_2deg": lambda r: r["base_rotation_deg"] > 2.0,
        "base_rotation_over_5deg": lambda r: r["base_rotation_deg"] > 5.0,
        "effort_limit": lambda r: bool(r["at_effort_limit"]),
        "position_limit": lambda r: bool(r["at_position_limit"]),
        "torque_limited_qp": lambda r: r["torque_limited"],
        "damping_saturated": lambda r: bool(r["damping_saturated"]),
    }
    for k in range(len(rows[0]["contacts"])):
        name = rows[0]["contacts"][k]["frame"]
        tests[f"{name}_planned_at_min_normal"] = lambda r, k=k: (
            r["contacts"][k]["planned_normal_force"] < min_normal + 0.5
        )
        tests[f"{name}_realised_under_min_normal"] = lambda r, k=k: (
            r["contacts"][k]["realised_normal_force"] < min_normal
        )
    answer: dict[str, Any] = {}
    for key, test in tests.items():
        hit = next((r for r in rows[1:] if test(r)), None)  # row 0: MuJoCo's forces not yet
        answer[key] = None if hit is None else round(hit["time"], 3)
        if key == "damping_saturated" and hit is not None:
            answer["damping_saturated_joints"] = hit["damping_saturated"]
    return answer


def main(argv: list[str] | None = None) -> int:
    """Run one impact trial and print its summary, its firsts and every ``--every``-th row."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenario")
    p.add_argument("--speed", type=float, default=0.02, help="commanded approach speed, m/s")
    p.add_argument("--rigid-impact", action="store_true")
    p.add_argument("--contact", default=None, help="contact frame (default: first non-sole)")
    p.add_argument("--limit-tol", type=float, default=0.02, help="rad from a position limit")
    p.add_argument("--effort-scale", type=float, default=1.0, help="what-if: raise limits")
    p.add_argument("--effort-joints", nargs="*", default=[], help="joints --effort-scale raises")
    p.add_argument("--withdraw-speed", type=float, default=None, help="what-if: m/s (0.3)")
    p.add_argument(
        "--force-threshold", type=float, default=None, help="what-if: N (15; inf: no withdrawal)"
    )
    p.add_argument(
        "--touch-contact",
        action="store_true",
        help="the id controller's touch_contact: the touching point a contact of the QP",
    )
    p.add_argument("--every", type=int, default=25)
    p.add_argument("--json", default=None, help="write every row to this file")
    args = p.parse_args(argv)
    options = BalanceTrialOptions(
        controller="id",
        rigid_impact=args.rigid_impact,
        id_gains=InverseDynamicsGains(touch_contact=args.touch_contact),
    )
    setup = BalanceSetup.create(args.scenario, "servo", options)
    a = setup.analysis
    contacts = [c.spec.frame for c in a.stance.contacts]
    index = (
        contacts.index(args.contact)
        if args.contact
        else next(i for i, f in enumerate(contacts) if "sole" not in f and "foot" not in f)
    )
    log = _ApproachLog(setup.sim, index, a, args.limit_tol)
    _what_ifs(setup, args)
    with _logged(log):
        result = run_balance_trial(setup, impact_speed=args.speed, options=options)
    summary = result.summary()
    keys = ("outcome", "reason", "detail", "events", "disturbance_time", "outcome_time")
    print(json.dumps({k: summary.get(k) for k in keys}))
    print(json.dumps(_start(setup, log)))
    min_normal = float(getattr(_gains(setup, options), "min_normal_force", 0.0))
    print(json.dumps({"firsts": _firsts(log.rows, min_normal), "min_normal_force": min_normal}))
    for row in log.rows[:: args.every]:
        print(json.dumps(row, allow_nan=True))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(log.rows, f)
    return 0


def _what_ifs(setup: BalanceSetup, args: argparse.Namespace) -> None:
    """The what-ifs: effort limits raised (MuJoCo's and the QP's), the task's withdrawal."""
    import mujoco

    import impact_balance.sim.trials.balance_trial as bt

    m = setup.sim.model
    for name in args.effort_joints:
        m.actuator_forcerange[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)] *= (
            args.effort_scale
        )
    if args.effort_joints:
        init = InverseDynamicsController.__init__

        def raised(self: Any, *a: Any, **k: Any) -> None:
            init(self, *a, **k)
            self.effort = self.effort.copy()
            for name in args.effort_joints:
                self.effort[self.model.joints[self.model.getJointId(name)].idx_v - 6] *= (
                    args.effort_scale
                )

        InverseDynamicsController.__init__ = raised  # type: ignore[method-assign]
    commanded = bt._commanded_task

    def task(*a: Any) -> Any:
        t, standoff = commanded(*a)
        if args.withdraw_speed is not None:
            t.withdraw_speed = args.withdraw_speed
        if args.force_threshold is not None:
            t.force_threshold = args.force_threshold
        return t, standoff

    bt._commanded_task = task  # type: ignore[assignment]


def _gains(setup: BalanceSetup, options: BalanceTrialOptions) -> Any:
    from impact_balance.sim.control.gains import trial_gains

    return trial_gains(options, setup.sim)[1]


def _start(setup: BalanceSetup, log: _ApproachLog) -> dict[str, Any]:
    """Where the trial starts: the CoMs and their margins in both areas (m, world)."""
    a = setup.analysis
    model = a.stance.robot.model
    data = model.createData()
    q_start = setup.start_configuration(0.05)
    com_start = np.array(pin.centerOfMass(model, data, q_start))
    com_stance = np.array(pin.centerOfMass(model, data, a.stance.q))
    first = log.rows[0]
    return {
        "com_stance": com_stance.tolist(),
        "com_start_retracted_5cm": com_start.tolist(),
        "first_row_com_margin_clamp": first["com_margin_clamp"],
        "stance_com_margin_scenario_area": _margin(a.areas.zmp_area, com_stance),
        "start_com_margin_scenario_area": _margin(a.areas.zmp_area, com_start),
        "clamp_area_vertices": log.clamp_vertices,
        "scenario_area_vertices": np.asarray(a.areas.zmp_area.vertices).round(4).tolist(),
    }


if __name__ == "__main__":
    sys.exit(main())
