"""One recorded push rerun with the id controller, per control step: every sole's plan and MuJoCo's.

The measurement of docs/studies/torso-pushes.md §6 (after the fact, on spent sets). It reruns a
push of ``studies/held_out_results_N/pushes.csv`` (the record's impulse, direction and body, the
``id`` controller, 2.5 s after the push) and logs, every control step, per sole contact: the
QP's planned and MuJoCo's realised normal force (N), centre of pressure (m, sole axes, beside the
rectangle's half sizes), the planned contact's rate of change of the angular momentum about the
CoM (``(p - c) x f + tau``, N m, world) and the sole's tilt from its start (deg); and for the
whole robot: the root body's rotation from its start (deg), the centroidal angular momentum L
(N m s, world, about the CoM, pinocchio), the QP's target rate ``-K_L L``, the planned and
realised total rate, and whether the desired ZMP was clamped.

What-ifs (docs/studies/torso-pushes.md §7, §8): ``--angular-momentum-weight capture`` prices the L
task by the capture (``com_weight / h^2``); ``--feedback cmp`` makes the DCM feedback choose the
centroidal moment pivot (CMP) and book the removal of L at ``-K_L L``, as the criterion does
(:class:`CmpFeedback`): the desired ZMP is ``p_cmp + d``, ``d = K_L (L_y, -L_x) / (m g)``
(:func:`zmp_offset`), clamped to the area, and the CoM task pivots about the clamped ZMP minus
``d``. Under ``--feedback cmp`` the rows' ``zmp_clamped`` is the clamp of ``p_cmp + d``.

    python benchmarks/torso_tipping.py 6 g1_wide_left_palm_oblique_side torso 90 0.75 \
        --json /tmp/g1_90_075.json

One trial takes a few minutes on a 2-core machine. Nothing here is part of the library: the
controller's step is wrapped for the trial's duration.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hand_contact import _cop, _is_sole, _realised, step_replaced

from impact_balance.sim.control.gains import (
    RobotScales,
    capture_angular_momentum_weight,
    robot_id_gains,
)
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.control.zmp import DcmFeedback, clamp_to_polygon, dcm
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import (
    BalanceSetup,
    BalanceTrialOptions,
    Push,
)


def body_name(robot: str, body: str) -> str | None:
    """The MuJoCo body the protocols pushed (None: the robot's default trunk)."""
    if body == "torso":
        return "WAIST_R_S" if robot == "jvrc1" else None
    return "pelvis" if robot == "g1" else "base_link"


class SoleLog:
    """The per-step rows of one trial (see the module docstring)."""

    def __init__(self, setup: BalanceSetup) -> None:
        self.sim, self.analysis, self.rows = setup.sim, setup.analysis, []
        self.soles = [
            k for k, c in enumerate(setup.analysis.stance.contacts) if _is_sole(c.spec.frame)
        ]
        self.start: dict[int, np.ndarray] = {}
        self.base_start: np.ndarray | None = None
        self.data: Any = None

    def add(self, c: InverseDynamicsController, t: float, q: Any, v: Any, out: Any) -> None:
        """One control step, after the QP."""
        if self.data is None:
            self.data = c.model.createData()
        hg = pin.computeCentroidalMomentum(c.model, self.data, q, v)
        L = np.array(hg.angular)
        com = np.asarray(out.com, dtype=float)
        soles, rate_p, rate_r = [], np.zeros(3), np.zeros(3)
        for k, contact in enumerate(self.analysis.stance.contacts):
            frame = c.data.oMf[c.contact_frames[k]]
            placement = frame * c.contact_offsets[k]
            R, p = placement.rotation, placement.translation
            w = out.wrenches[k]
            force, moment, count = _realised(self.sim, self.sim.contact_geoms[k], p)
            planned_rate = np.cross(p - com, w[:3]) + w[3:]
            realised_rate = np.cross(p - com, force) + moment
            rate_p += planned_rate
            rate_r += realised_rate
            if k not in self.soles:
                continue
            self.start.setdefault(k, frame.rotation.copy())
            tilt = pin.log3(self.start[k].T @ frame.rotation)
            soles.append(
                {
                    "frame": contact.spec.frame,
                    "half_sizes": [c.contact_half_sizes[k][0], c.contact_half_sizes[k][1]],
                    "planned_normal_force": float(R[:, 2] @ w[:3]),
                    "realised_normal_force": float(R[:, 2] @ force),
                    "planned_cop": _cop(R.T @ w[:3], R.T @ w[3:]),
                    "realised_cop": _cop(R.T @ force, R.T @ moment),
                    "planned_rate": planned_rate.tolist(),
                    "realised_rate": realised_rate.tolist(),
                    "points": count,
                    "tilt_deg": math.degrees(float(np.linalg.norm(tilt))),
                }
            )
        if self.base_start is None:
            self.base_start = c.data.oMi[1].rotation.copy()
        base_tilt = pin.log3(self.base_start.T @ c.data.oMi[1].rotation)
        self.rows.append(
            {
                "time": t,
                "base_rotation_deg": math.degrees(float(np.linalg.norm(base_tilt))),
                "angular_momentum": L.tolist(),
                "target_rate": (-c.gains.angular_momentum_damping * L).tolist(),
                "planned_rate": rate_p.tolist(),
                "realised_rate": rate_r.tolist(),
                "zmp_clamped": bool(out.clamped),
                "torque_limited": bool(out.torque_limited),
                "com_velocity": np.asarray(out.com_velocity, dtype=float).tolist(),
                "soles": soles,
            }
        )


def zmp_offset(angular_momentum: Any, damping: float, mass: float, gravity: float) -> np.ndarray:
    """ZMP minus CMP (m, world, horizontal) while the angular momentum decays as ``-K_L L``.

    About the CoM, ``L_dot = (p - c) x f`` plus the contacts' vertical moments; with ``f_z = m g``
    its horizontal components give ``p = p_cmp - S(L_dot) / (m g)``, ``S(a) = (a_y, -a_x)``,
    ``p_cmp = c_xy - c_dd_xy / omega^2`` (docs/angular-momentum.md). With ``L_dot = -K_L L``:
    ``d = K_L (L_y, -L_x) / (m g)``.

    Args:
        angular_momentum: Centroidal angular momentum L (N m s, world axes, about the CoM).
        damping: K_L (1/s).
        mass: Total mass m (kg).
        gravity: g (m/s^2).
    """
    L = np.asarray(angular_momentum, dtype=float)
    return damping * np.array([L[1], -L[0]]) / (mass * gravity)


class CmpFeedback(DcmFeedback):
    """The DCM feedback choosing the CMP, the ZMP offset by :func:`zmp_offset` (the what-if).

    ``p_cmp = xi + (k / omega)(xi - xi_ref)``; ``p_cmp + d`` is clamped to the area (``p``);
    :meth:`desired_zmp` returns ``p - d``, the CMP the CoM task pivots about (the controller's
    ``c_dd = omega^2 (c - .)``). L is the controller's centroidal angular momentum of this
    control step (pinocchio's ``data.hg``, computed before the feedback is asked).
    """

    def __init__(self, plain: DcmFeedback, controller: InverseDynamicsController) -> None:
        super().__init__(plain.zmp_area, plain.omega, plain.dcm_reference, plain.gain, plain.margin)
        self.controller = controller

    def desired_zmp(
        self, com_xy: np.ndarray, com_velocity_xy: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """``(CMP the CoM task pivots about, DCM, p_cmp + d clamped?)`` (m, world)."""
        c = self.controller
        d = zmp_offset(c.data.hg.angular, c.gains.angular_momentum_damping, c.mass, c.gravity)
        xi = dcm(com_xy, com_velocity_xy, self.omega)
        wanted = xi + (self.gain / self.omega) * (xi - self.dcm_reference) + d
        p = clamp_to_polygon(self.zmp_area, wanted, self.margin)
        return p - d, xi, bool(np.linalg.norm(p - wanted) > 1e-9)


def logged(log: SoleLog, cmp_feedback: bool = False) -> contextlib.AbstractContextManager[None]:
    """Wrap the id controller's step for the trial's duration (and its feedback: ``--feedback``)."""

    def wrap(step: Callable[..., Any]) -> Callable[..., Any]:
        def logged_step(
            self: InverseDynamicsController, t: float, q: Any, v: Any, *args: Any
        ) -> Any:
            if cmp_feedback and not isinstance(self.feedback, CmpFeedback):
                self.feedback = CmpFeedback(self.feedback, self)
            out = step(self, t, q, v, *args)
            log.add(self, t, q, v, out)
            return out

        return logged_step

    return step_replaced(wrap)


def summary(rows: list[dict[str, Any]], push_end: float) -> dict[str, Any]:
    """Per sole: the largest tilt and when; when its realised CoP first reaches 95 % of an edge."""
    out: dict[str, Any] = {}
    for i, sole in enumerate(rows[0]["soles"]):
        hx, hy = sole["half_sizes"]
        tilts = [r["soles"][i]["tilt_deg"] for r in rows]
        k = int(np.argmax(tilts))
        edge, planned_edge = None, None
        for r in rows:
            s = r["soles"][i]
            x, y = s["realised_cop"]
            if edge is None and (
                s["realised_normal_force"] < 1.0 or abs(x) >= 0.95 * hx or abs(y) >= 0.95 * hy
            ):
                edge = r["time"] - push_end
            px, py = s["planned_cop"]
            if planned_edge is None and (abs(px) >= 0.95 * hx or abs(py) >= 0.95 * hy):
                planned_edge = r["time"] - push_end
        out[sole["frame"]] = {
            "max_tilt_deg": tilts[k],
            "at_s_after_push": rows[k]["time"] - push_end,
            "realised_cop_at_edge_s": edge,
            "planned_cop_at_edge_s": planned_edge,
        }
    return out


def with_capture_weight(options: BalanceTrialOptions, setup: BalanceSetup) -> BalanceTrialOptions:
    """``options`` with the robot's id gains, the L task weighted by the capture's cost.

    :func:`~impact_balance.sim.control.gains.capture_angular_momentum_weight` in place of the
    default rule; every other gain derived from the robot as the trial would.
    """
    scales = RobotScales.of_sim(setup.sim)
    gains = robot_id_gains(scales, options.id_gains)
    weight = capture_angular_momentum_weight(scales, gains.com_weight)
    gains = replace(gains, angular_momentum_weight=weight)
    return replace(options, id_gains=gains, robot_gains=False)


def main(argv: list[str] | None = None) -> int:
    """Rerun one recorded push, print its summary and every ``--every``-th row."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("set")
    p.add_argument("stance")
    p.add_argument("body", choices=("torso", "pelvis"))
    p.add_argument("direction", type=float, help="deg, world")
    p.add_argument("relative", type=float)
    p.add_argument("--after", type=float, default=2.5)
    p.add_argument("--every", type=int, default=50)
    p.add_argument("--json", default=None)
    p.add_argument(
        "--angular-momentum-weight",
        choices=("robot", "capture"),
        default="robot",
        help="the L task's weight: the default rule, or com_weight / h^2 (the capture's cost)",
    )
    p.add_argument(
        "--feedback",
        choices=("zmp", "cmp"),
        default="zmp",
        help="the DCM feedback chooses the ZMP (the controller's), or the CMP with the ZMP offset "
        "d = K_L (L_y, -L_x) / (m g) that removes L at K_L (the what-if of §8)",
    )
    args = p.parse_args(argv)
    records = pd.read_csv(f"studies/held_out_results_{args.set}/pushes.csv")
    r = records[
        (records.stance == args.stance)
        & (records.body == args.body)
        & (records.direction_deg == args.direction)
        & ((records.relative - args.relative).abs() < 1e-6)
    ].iloc[0]
    options = BalanceTrialOptions(controller="id", after=args.after)
    setup = BalanceSetup.create(f"studies/held_out_{args.set}/{args.stance}.yaml", "servo", options)
    if args.angular_momentum_weight == "capture":
        options = with_capture_weight(options, setup)
    push = Push(
        math.radians(args.direction),
        float(r.impulse_Ns),
        0.05,
        options.settle,
        body_name(args.stance.split("_")[0], args.body),
    )
    log = SoleLog(setup)
    with logged(log, cmp_feedback=args.feedback == "cmp"):
        result = run_balance_trial(setup, push=push, options=options)
    s = result.summary()
    head = {k: s.get(k) for k in ("outcome", "reason", "strict_fail")}
    head["record"] = {"outcome": r.outcome, "strict_reason": r.strict_reason}
    head["angular_momentum_weight"] = args.angular_momentum_weight
    head["feedback"] = args.feedback
    head["soles"] = summary(log.rows, push.start + push.duration)
    print(json.dumps(head, default=str))
    for row in log.rows[:: args.every]:
        print(json.dumps(row))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"summary": head, "rows": log.rows}, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
