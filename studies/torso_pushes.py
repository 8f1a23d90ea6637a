"""Torso pushes after the fact: the angular momentum term's calls re-made on spent records.

Usage (from the repository root, with impact-balance and its ``sim`` extra installed)::

    python studies/torso_pushes.py 6 7 8 9 10 --cache=/tmp/torso_pushes.pkl

(``--cache=FILE``: the rebuilt table is written there, and read from there when it exists.)

For every push of ``studies/held_out_results_N/pushes.csv`` it rebuilds the push's prediction
from the stance ``studies/held_out_N/<stance>.yaml`` (the library's ``predict_push`` with the
push's duration and the trial controller's K_L, no trial run), checks that it reproduces the
record's default margin and call, and re-makes the call with the removal share of the angular
momentum's cost ``s`` replaced by each candidate's (the default: ``1 / (1 + omega tau)``, tau =
1/K_L). A horizontal push J u at height d above the CoM then calls safe when ``(kappa + s d / h)
J / m`` and ``kappa J / m`` lie in the CoM velocity area inset by ``omega M`` along u and within
the CoM's reach. It prints P(failed strictly | safe) with its Wilson interval and the standing
pushes called safe on the band (0.75 to 1.05), per body and robot, ordinary supports and hand
holds apart (docs/studies/torso-pushes.md). Beside the shares, two checks of the robot's turn
with the term off (§6 of that page): the locked robot's turn ``|L| t / I`` over the whole capture
(``turn_during_capture``) and over the time the capture holds the ZMP on one sole alone
(``turn_on_one_sole``), each against a bound on the angle. It writes nothing (but the cache).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pinocchio as pin

from impact_balance.analysis.result import Analysis
from impact_balance.cli.angular_momentum import for_trials
from impact_balance.geometry.polygon import Polygon
from impact_balance.scenario import load_scenario
from impact_balance.sim.studies.push import _body_position, predict_push
from impact_balance.sim.studies.scores import wilson
from impact_balance.sim.trials.balance_trial import BalanceTrialOptions, Push
from impact_balance.sim.trials.setup import BalanceSetup, push_body

BAND = (0.749, 1.051)
HAND = "hand_(?:wall|table|rail|hold)"


def _body_name(robot: str, body: str) -> str | None:
    """The MuJoCo body the protocols pushed (None: the robot's default trunk)."""
    if body == "torso":
        return "WAIST_R_S" if robot == "jvrc1" else None
    return "pelvis" if robot == "g1" else "base_link"


def _is_sole(frame: str) -> bool:
    return any(w in frame for w in ("sole", "foot", "ankle"))


def _sole_alone(a: Analysis, u: np.ndarray, margin: float) -> tuple[float, float]:
    """The capture's ZMP extent e along u, and where the ray enters the sole that holds it alone.

    ``e`` (m): from the CoM to the edge of the ZMP area inset by ``margin`` along u. When that
    edge point lies in exactly one sole's rectangle of a stance of several soles, the capture
    holds the ZMP on that sole alone while the ZMP is beyond ``e_in`` (m, the distance along u
    at which the ray from the CoM enters that rectangle); otherwise ``e_in`` is NaN.
    """
    com = np.asarray(a.stance.com, dtype=float)[:2]
    G, h = a.areas.zmp_area.inset(margin).halfplanes
    rate = G @ u
    ahead = rate > 1e-12
    e = float(np.min((h[ahead] - G[ahead] @ com) / rate[ahead]))
    soles = [c for c in a.stance.contacts if _is_sole(c.spec.frame)]
    rects = [Polygon.from_points(c.corners()[:, :2]) for c in soles]
    holding = [p for p in rects if bool(np.all(p.contains((com + e * u)[None, :], tol=1e-6)))]
    if len(soles) < 2 or len(holding) != 1:
        return e, float("nan")
    Gr, hr = holding[0].halfplanes
    rr = Gr @ u
    behind = rr < -1e-12
    entry = float(np.max((hr[behind] - Gr[behind] @ com) / rr[behind])) if behind.any() else 0.0
    return e, max(0.0, entry)


def _stance_rows(set_id: str, stance: str, records: pd.DataFrame) -> list[dict[str, object]]:
    options = BalanceTrialOptions(controller="id")
    scenario = for_trials(
        load_scenario(f"studies/held_out_{set_id}/{stance}.yaml"), "controller", options
    )
    setup = BalanceSetup.create(scenario, "servo", options)
    a = setup.analysis
    omega, tau = float(a.areas.omega), float(scenario.angular_momentum_damping_time or 0.0)
    com = np.asarray(a.stance.com, dtype=float)
    data = a.stance.robot.model.createData()
    pin.ccrba(a.stance.robot.model, data, a.stance.q, np.zeros(a.stance.robot.model.nv))
    inertia = np.array(data.Ig.inertia)
    halfplanes, offsets = a.areas.com_velocity_area.halfplanes
    rows = []
    for body in ("pelvis", "torso"):
        name = _body_name(stance.split("_")[0], body)
        position = _body_position(setup, push_body(setup.sim, name))
        for _, r in records[(records.stance == stance) & (records.body == body)].iterrows():
            angle = np.deg2rad(r.direction_deg)
            push = Push(angle, r.impulse_Ns, 0.05, options.settle, name)
            p = predict_push(setup, push, float(position[2]), position, None, True)
            u = np.array([np.cos(angle), np.sin(angle)])
            rate = halfplanes @ u
            ahead = rate > 1e-12
            boundary = float(np.min(offsets[ahead] / rate[ahead]))  # m/s along u, margin 0
            inset = float(np.min((offsets[ahead] - omega * r.zmp_margin) / rate[ahead]))
            axis = np.array([*p.angular_momentum[:2], 0.0])
            norm = float(np.linalg.norm(axis))
            kappa = float(p.finite_push_factor or 1.0)
            speed = r.relative * boundary
            e, e_in = _sole_alone(a, u, float(r.zmp_margin))
            rows.append(
                {
                    **r.to_dict(),
                    "set": set_id,
                    "omega": omega,
                    "tau": tau,
                    "h": a.areas.gravity / omega**2,
                    "d": float(position[2] - com[2]),
                    "kappa": kappa,
                    "rho": inset / boundary,
                    "boundary": boundary,
                    "angular_momentum": norm,
                    "inertia": float(axis @ inertia @ axis) / norm**2 if norm else np.nan,
                    "zmp_extent": e,
                    "sole_entry": e_in,
                    "margin_check": float(p.finite_push_margin or 0.0) - r.default_margin_mps,
                    # the reach's speed limit along u: the record's margin plus the larger speed
                    "reach_limit": r.com_reach_margin_mps
                    + speed * max(kappa, float(np.linalg.norm(p.default_velocities[1])) / speed),
                }
            )
    return rows


def _calls(table: pd.DataFrame, share: pd.Series) -> pd.Series:
    """The call with removal share ``share`` (both ends, the reach on the larger speed)."""
    larger = np.maximum(table.kappa, table.kappa + share * table.d / table.h)
    inside = larger * table.relative <= table.rho + 1e-12
    reach = table.reach_limit - larger * table.relative * table.boundary >= -1e-12
    return inside & reach


def _held_share(table: pd.DataFrame, degrees: float) -> pd.Series:
    """L kept (the body turning) until it has turned ``degrees``, then removed at 1/K_L."""
    hold = np.maximum(0.0, np.deg2rad(degrees) * table.inertia / table.angular_momentum - table.tau)
    return np.exp(-table.omega * hold) / (1 + table.omega * table.tau)


def turn_during_capture(table: pd.DataFrame) -> pd.Series:
    """The angle (rad) the robot turns while the capture holds the ZMP at the area's edge.

    Along u the CoM moves at ``kappa J / m`` toward an edge ``e`` away (the inset area's extent
    over omega); the ZMP held at the edge stops it after ``atanh(kappa J / (m omega e)) /
    omega``. With the ZMP at the edge no moment is left to remove L, so the locked robot turns
    at ``|L| / I`` meanwhile (I: its centroidal inertia about L's axis). Infinite when the
    CoM is not captured.
    """
    ratio = (table.kappa * table.relative / table.rho).clip(upper=1.0)
    stop = np.arctanh(ratio.where(ratio < 1.0, np.nan)) / table.omega
    rate = (table.angular_momentum / table.inertia).fillna(0.0)
    return (rate * stop).fillna(np.inf)


def turn_on_one_sole(table: pd.DataFrame) -> pd.Series:
    """The angle (rad) the robot turns while the capture holds the ZMP on one sole alone.

    With the ZMP held at the edge ``e`` along u, the DCM ``xi`` (from the CoM, along u) moves
    as ``e - xi(t) = (e - xi0) exp(omega t)``, ``xi0 = kappa J / (m omega)``; the ZMP may
    leave the sole that holds it alone once ``xi <= e_in``, after ``ln((e - e_in) / (e -
    xi0)) / omega``. Meanwhile the other soles carry nothing and no moment is left to remove L:
    the locked robot turns at ``|L| / I`` about L's axis, and the unloaded soles with it. Zero
    when no sole holds the capture alone; infinite when the CoM is not captured.
    """
    ratio = table.kappa * table.relative / table.rho  # xi0 / e
    xi0 = ratio * table.zmp_extent
    alone = np.log(((table.zmp_extent - table.sole_entry) / (table.zmp_extent - xi0)).clip(lower=1))
    time = (alone / table.omega).where(ratio < 1.0, np.inf).fillna(0.0)
    return (table.angular_momentum / table.inertia).fillna(0.0) * time


def _cell(called: pd.Series, rows: pd.Series, table: pd.DataFrame) -> str:
    failed = int((called & rows & (table.strict_fail == 1)).sum())
    safe = int((called & rows).sum())
    standing = int((rows & (table.strict_fail == 0)).sum())
    kept = int((called & rows & (table.strict_fail == 0)).sum())
    interval = wilson(failed, safe)
    rate = (
        "– (0/0)"
        if interval is None
        else f"{100 * failed / safe:.0f} % [{100 * interval[0]:.0f}, "
        f"{100 * interval[1]:.0f}] ({failed}/{safe})"
    )
    return f"{rate} | {kept}/{standing}"


def main(sets: list[str]) -> int:
    """Print the candidates' scores on the band of ``sets``; 0."""
    warnings.simplefilter("ignore")
    cache = next((a.split("=", 1)[1] for a in sets if a.startswith("--cache=")), None)
    sets = [a for a in sets if not a.startswith("--cache=")]
    if cache is not None and Path(cache).exists():
        table = pd.read_pickle(cache)
    else:
        rows: list[dict[str, object]] = []
        for set_id in sets:
            records = pd.read_csv(f"studies/held_out_results_{set_id}/pushes.csv")
            records = records[records.outcome != "aborted"]
            for stance in records.stance.unique():
                rows += _stance_rows(set_id, stance, records)
        table = pd.DataFrame(rows)
        if cache is not None:
            table.to_pickle(cache)
    default = 1 / (1 + table.omega * table.tau)
    print(
        f"margin check: {table.margin_check.abs().max():.1e} m/s; default call reproduced:",
        bool((_calls(table, default) == table.default_safe.astype(bool)).all()),
    )
    candidates = {
        "default (1/K_L)": default,
        "no removal (tau = inf)": 0.0 * default,
        "removal at tau = 0.52 s": 1 / (1 + table.omega * 0.52),
        "turn 10 deg, then 1/K_L": _held_share(table, 10.0),
        "turn 25 deg, then 1/K_L": _held_share(table, 25.0),
    }
    turn = turn_during_capture(table)
    no_removal = _calls(table, 0.0 * default)
    tilt_checks = {
        f"no removal, turn during the capture <= {deg} deg": no_removal & (turn <= np.deg2rad(deg))
        for deg in (10.0, 25.0)
    }
    tilt_checks["no removal, unloaded soles turn <= 10 deg"] = no_removal & (
        turn_on_one_sole(table) <= np.deg2rad(10.0)
    )
    band = table.relative.between(*BAND)
    hand = table.stance.str.contains(HAND)
    robot = table.stance.str.split("_").str[0]
    for body in ("torso", "pelvis"):
        for label, support in (("ordinary supports", ~hand), ("hand holds", hand)):
            print(f"\n{body}, {label}: P(failed strictly | safe) | standing called safe")
            calls = {name: _calls(table, share) for name, share in candidates.items()}
            for name, called in {**calls, **tilt_checks}.items():
                cells = [_cell(called, band & support & (table.body == body), table)]
                cells += [
                    f"{r}: "
                    + _cell(called, band & support & (table.body == body) & (robot == r), table)
                    for r in sorted(robot[support].unique())
                ]
                print(f"| {name} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or ["6", "7", "8", "9"]))
