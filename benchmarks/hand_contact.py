"""One push on a stance with a hand contact, per control step: the id QP's plan beside MuJoCo.

The measurement of docs/studies/hand-contacts.md. Every control step of the ``id`` controller, for
one contact of the stance (default: the first that is not a sole): the QP's planned wrench
(``TorqueOutput.wrenches``: normal force, centre of pressure in the contact's face) beside what
MuJoCo realises on that contact's geom (the sum of its contact points' forces and their moment
about the contact point: normal force, centre of pressure, number of points), the contact
frame's tilt from its start (deg), its angular velocity (contact axes, rad/s) and the QP's planned
angular acceleration (rad/s^2), whether the QP dropped a constraint (``torque_limited``), which
actuated joints sit at their effort limit, and the joint whose realised acceleration (MuJoCo's
``qacc`` after the step) departs most from the plan.

    python benchmarks/hand_contact.py \
        studies/held_out_8/talos_right_foot_right_hand_hold_left_toe_front.yaml \
        --relative 0.75 --direction 0 --body base_link
    # what-ifs: --cop-margin 0.01 (the QP's faces inset, m), --no-joint-friction (MuJoCo's
    # frictionloss zeroed), --effort-scale 10 --effort-joints arm_right_5_joint ... (limits raised)

One trial takes about a minute on a 2-core machine (``--after`` 1 s of simulated time after the
push). Nothing here is part of the library: the controller is wrapped for the trial's duration.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin

from impact_balance.geometry.polygon import Polygon
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.studies.push import START_COM_VELOCITY, boundary_impulse
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions, Push

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _cop(force: np.ndarray, moment: np.ndarray) -> list[float]:
    """Centre of pressure (m, contact axes) of a wrench at the contact point; NaN when unloaded."""
    if force[2] <= 1e-6:
        return [math.nan, math.nan]
    return [float(-moment[1] / force[2]), float(moment[0] / force[2])]


def _realised(sim: Any, geom: int, point: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """MuJoCo's force and moment about ``point`` on ``geom`` (N, N m, world), and its points."""
    m, d = sim.model, sim.data
    force, moment, local, count = np.zeros(3), np.zeros(3), np.zeros(6), 0
    for i in range(d.ncon):
        contact = d.contact[i]
        if geom not in (contact.geom1, contact.geom2):
            continue
        mujoco.mj_contactForce(m, d, i, local)
        f = contact.frame.reshape(3, 3).T @ local[:3]
        if contact.geom1 == geom:  # the force acts on geom2
            f = -f
        force += f
        moment += np.cross(contact.pos - point, f)
        count += 1
    return force, moment, count


class _Log:
    """The per-step rows of one trial (see the module docstring)."""

    def __init__(self, sim: Any, contact: int, analysis: Any = None) -> None:
        self.sim, self.contact, self.rows = sim, contact, []
        self.analysis = analysis
        self.base_start: np.ndarray | None = None
        self.start: np.ndarray | None = None
        self.planned: np.ndarray | None = None

    def add(self, c: InverseDynamicsController, t: float, v: np.ndarray, out: Any) -> None:
        """One control step, after the QP."""
        sim, k = self.sim, self.contact
        frame = c.data.oMf[c.contact_frames[k]]
        placement = frame * c.contact_offsets[k]
        R, p = placement.rotation, placement.translation
        planned = out.wrenches[k]
        force, moment, count = _realised(sim, sim.contact_geoms[k], p)
        if self.start is None:
            self.start = frame.rotation.copy()
        J = pin.getFrameJacobian(c.model, c.data, c.contact_frames[k], _LWA)
        names = {j.idx_v: c.model.names[j.id] for j in c.model.joints[2:]}
        qacc = sim.data.qacc[sim.dof_adr]
        worst = None
        if self.planned is not None:
            err = qacc - self.planned
            i = int(np.argmax(np.abs(err)))
            worst = [names[int(sim.v_index[i])], float(self.planned[i]), float(qacc[i])]
        self.planned = out.a[sim.v_index].copy()
        at_limit = np.flatnonzero(np.abs(out.tau) >= 0.999 * c.effort)
        self.rows.append(
            {
                "time": t,
                "planned_normal_force": float(R[:, 2] @ planned[:3]),
                "planned_cop": _cop(R.T @ planned[:3], R.T @ planned[3:]),
                "realised_normal_force": float(R[:, 2] @ force),
                "realised_cop": _cop(R.T @ force, R.T @ moment),
                "contact_points": count,
                "tilt_deg": math.degrees(
                    float(np.linalg.norm(pin.log3(self.start.T @ frame.rotation)))
                ),
                "angular_velocity": (R.T @ (J[3:] @ v)).tolist(),
                "planned_angular_acceleration": (R.T @ (J[3:] @ out.a)).tolist(),
                "torque_limited": bool(out.torque_limited),
                "at_effort_limit": [names[int(i) + 6] for i in at_limit],
                "worst_joint_plan_realised": worst,
                **self._balance(c, out),
            }
        )

    def _balance(self, c: InverseDynamicsController, out: Any) -> dict[str, Any]:
        """Every contact's plan and MuJoCo's, the CoM velocity in its area, the ZMPs (m, world).

        ``zmp_lipm_planned``/``zmp_lipm_realised``: the CoM minus the contacts' horizontal force
        over m omega^2 (the LIPM's ZMP of the planned / realised total contact force);
        ``hand_zmp_shift_*``: the non-sole contacts' part of it (-f_xy / (m omega^2)), the capture
        the hand makes; ``desired_zmp_in_feet``: whether the controller's (clamped) desired ZMP
        lies in the convex hull of the sole contacts' corners (the feet alone at zero hand force).
        """
        sim, a = self.sim, self.analysis
        mass, omega = float(a.stance.mass), float(c.omega)
        rows, planned_xy, realised_xy = [], np.zeros(2), np.zeros(2)
        hand_p, hand_r = np.zeros(2), np.zeros(2)
        com3 = np.asarray(out.com, dtype=float)
        moment_p, moment_r, total_p, total_r = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
        for k, contact in enumerate(a.stance.contacts):
            placement = c.data.oMf[c.contact_frames[k]] * c.contact_offsets[k]
            R, p = placement.rotation, placement.translation
            force, moment, count = _realised(sim, sim.contact_geoms[k], p)
            w = out.wrenches[k]
            rows.append(
                {
                    "frame": contact.spec.frame,
                    "planned_normal_force": float(R[:, 2] @ w[:3]),
                    "realised_normal_force": float(R[:, 2] @ force),
                    "planned_cop": _cop(R.T @ w[:3], R.T @ w[3:]),
                    "realised_cop": _cop(R.T @ force, R.T @ moment),
                    "planned_tangential_force": float(np.linalg.norm(R[:, :2].T @ w[:3])),
                    "realised_tangential_force": float(np.linalg.norm(R[:, :2].T @ force)),
                    "points": count,
                }
            )
            planned_xy += w[:2]
            realised_xy += force[:2]
            total_p += w[:3]
            total_r += force
            moment_p += np.cross(p - com3, w[:3]) + w[3:]
            moment_r += np.cross(p - com3, force) + moment
            if not _is_sole(contact.spec.frame):
                hand_p += w[:2]
                hand_r += force[:2]
        k2 = mass * omega**2
        com, vel = np.asarray(out.com)[:2], np.asarray(out.com_velocity)[:2]
        area = a.areas.com_velocity_area
        feet = np.vstack(
            [ct.corners()[:, :2] for ct in a.stance.contacts if _is_sole(ct.spec.frame)]
        )
        hull = Polygon.from_points(feet)
        if self.base_start is None:
            self.base_start = c.data.oMi[1].rotation.copy()
        base_tilt = pin.log3(self.base_start.T @ c.data.oMi[1].rotation)
        return {
            "base_rotation_deg": float(np.degrees(np.linalg.norm(base_tilt))),
            "com_acceleration_demanded": (omega**2 * (com - np.asarray(out.zmp)[:2])).tolist(),
            "com_acceleration_planned": (total_p[:2] / mass).tolist(),
            "com_acceleration_realised": (total_r[:2] / mass).tolist(),
            "angular_momentum_rate_planned": moment_p.tolist(),
            "angular_momentum_rate_realised": moment_r.tolist(),
            "contacts": rows,
            "com_velocity_xy": vel.tolist(),
            "com_velocity_margin": float(np.min(area.margins(vel[None, :]))),
            "desired_zmp": np.asarray(out.zmp)[:2].tolist(),
            "zmp_clamped": bool(out.clamped),
            "dcm": np.asarray(out.dcm)[:2].tolist(),
            "zmp_lipm_planned": (com - planned_xy / k2).tolist(),
            "zmp_lipm_realised": (com - realised_xy / k2).tolist(),
            "hand_zmp_shift_planned": (-hand_p / k2).tolist(),
            "hand_zmp_shift_realised": (-hand_r / k2).tolist(),
            "desired_zmp_feet_margin": float(np.min(hull.margins(np.asarray(out.zmp)[None, :2]))),
            "effort_use": float(np.max(np.abs(out.tau) / np.maximum(c.effort, 1e-9))),
        }


@contextlib.contextmanager
def step_replaced(wrap: Callable[[Callable[..., Any]], Callable[..., Any]]) -> Iterator[None]:
    """The id controller's ``step`` replaced by ``wrap(step)`` inside the block, then restored."""
    step = InverseDynamicsController.step
    InverseDynamicsController.step = wrap(step)  # type: ignore[method-assign]
    try:
        yield
    finally:
        InverseDynamicsController.step = step  # type: ignore[method-assign]


def _logged(log: _Log) -> contextlib.AbstractContextManager[None]:
    """Wrap the id controller's step for the trial's duration."""

    def wrap(step: Callable[..., Any]) -> Callable[..., Any]:
        def logged_step(
            self: InverseDynamicsController, t: float, q: Any, v: Any, *args: Any
        ) -> Any:
            out = step(self, t, q, v, *args)
            log.add(self, t, v, out)
            return out

        return logged_step

    return step_replaced(wrap)


def _is_sole(frame: str) -> bool:
    """Whether a contact frame is a foot's (the study's convention: ``sole``/``foot``/``ankle``)."""
    return any(w in frame for w in ("sole", "foot", "ankle"))


def _contact_index(setup: BalanceSetup, name: str | None) -> int:
    contacts = [c.spec.frame for c in setup.analysis.stance.contacts]
    if name is not None:
        return contacts.index(name)
    return next(i for i, f in enumerate(contacts) if not _is_sole(f))


def _what_ifs(setup: BalanceSetup, args: argparse.Namespace) -> None:
    m = setup.sim.model
    if args.no_joint_friction:
        m.dof_frictionloss[:] = 0.0
    for name in args.effort_joints:
        a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        m.actuator_forcerange[a] *= args.effort_scale


def _scale_gains(pairs: list[list[str]]) -> None:
    """Scale the controller's gains once built (``for_trial`` wrapped for the trial)."""
    original = InverseDynamicsController.__init__

    def init(self: Any, *a: Any, **k: Any) -> None:
        original(self, *a, **k)
        for name, factor in pairs:
            self.gains = replace(self.gains, **{name: getattr(self.gains, name) * float(factor)})

    InverseDynamicsController.__init__ = init  # type: ignore[method-assign]


def main(argv: list[str] | None = None) -> int:
    """Run one push and print its rows every ``--every`` control steps, then the summary."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenario")
    p.add_argument("--relative", type=float, default=0.75)
    p.add_argument("--direction", type=float, default=0.0, help="deg from world x")
    p.add_argument("--body", default="base_link")
    p.add_argument("--duration", type=float, default=0.05)
    p.add_argument("--after", type=float, default=1.0)
    p.add_argument("--contact", default=None, help="contact frame (default: first non-sole)")
    p.add_argument("--cop-margin", type=float, default=None)
    p.add_argument("--no-joint-friction", action="store_true")
    p.add_argument(
        "--id-gain-scale",
        nargs=2,
        action="append",
        default=[],
        metavar=("NAME", "FACTOR"),
        help="what-if: multiply one InverseDynamicsGains field (after the robot's scaling)",
    )
    p.add_argument("--effort-scale", type=float, default=1.0)
    p.add_argument("--effort-joints", nargs="*", default=[])
    p.add_argument("--every", type=int, default=10)
    p.add_argument("--json", default=None, help="write every row to this file")
    args = p.parse_args(argv)
    options = BalanceTrialOptions(controller="id", after=args.after)
    if args.cop_margin is not None:
        options = replace(options, id_gains=replace(options.id_gains, cop_margin=args.cop_margin))
    setup = BalanceSetup.create(args.scenario, "servo", options)
    if args.id_gain_scale:
        _scale_gains(args.id_gain_scale)
    _what_ifs(setup, args)
    if args.effort_joints:  # the QP's own limits follow MuJoCo's
        original = InverseDynamicsController.for_trial.__func__  # type: ignore[attr-defined]

        def for_trial(cls: Any, *a: Any) -> Any:
            c = original(cls, *a)
            c.effort = c.effort.copy()
            for name in args.effort_joints:
                c.effort[c.model.joints[c.model.getJointId(name)].idx_v - 6] *= args.effort_scale
            return c

        InverseDynamicsController.for_trial = classmethod(for_trial)  # type: ignore[method-assign,assignment]
    angle = math.radians(args.direction)
    a = setup.analysis
    impulse = args.relative * boundary_impulse(
        a.areas.com_velocity_area, a.stance.mass, angle, START_COM_VELOCITY
    )
    log = _Log(setup.sim, _contact_index(setup, args.contact), a)
    with _logged(log):
        result = run_balance_trial(
            setup,
            push=Push(angle, impulse, args.duration, options.settle, args.body),
            options=options,
        )
    summary = result.summary()
    print(json.dumps({k: summary.get(k) for k in ("outcome", "reason", "strict_fail", "events")}))
    print(f"impulse {impulse:.3f} N s")
    for row in log.rows[:: args.every]:
        print(json.dumps(row, allow_nan=True))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(log.rows, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
