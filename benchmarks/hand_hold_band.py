"""Rerun a held-out set's pushes the default criterion called safe, with the tree's controller.

Reads a set's ``pushes.csv`` (``studies/held_out_results_9/``), keeps one stance's pelvis pushes
with ``default_safe`` 1 and ``relative`` in the band (or all with ``--all``), runs each as
``push-test --controller id`` runs it (``hand_contact.py``'s trial: the push's 0.05 s at 0.3 s,
2.5 s after it) and prints one JSON line per push: the record's outcome beside this tree's.

    python benchmarks/hand_hold_band.py studies/held_out_results_9/pushes.csv \
        studies/held_out_9/g1_right_foot_right_hand_table_left_toe_front.yaml --body pelvis

With ``--friction-scale S`` (a number, or ``controller``: the ``id`` controller's 0.65), the
pushes kept are the band pelvis pushes that the *candidate* calls safe: the record's default
(the angular momentum term with the controller's K_L, the CoM's reach, the push's duration,
10 mm) with every contact's friction times S in the criterion (``push-test --friction-scale``),
computed here by ``predict_push``; the script first checks that at S = 1 it reproduces the
record's ``default_safe`` on every band pelvis push, and prints how many of the records' calls
the candidate keeps.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

import mujoco
import numpy as np

from impact_balance.balance.reach import com_reach
from impact_balance.scenario import load_scenario
from impact_balance.sim.control.gains import declared_angular_momentum_damping
from impact_balance.sim.model.build import SimOptions
from impact_balance.sim.studies.push import PushOutcome, predict_push, push_body
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions, Push


def _calls(setup: BalanceSetup, rows: list[dict[str, str]], body: str, reach: object) -> list[bool]:
    """The default's call (10 mm, the finite push, the reach) on each record, with ``setup``."""
    body_id = push_body(setup.sim, body)
    setup.sim.set_state(setup.start_configuration())
    mujoco.mj_forward(setup.sim.model, setup.sim.data)
    position = np.array(setup.sim.data.xipos[body_id], dtype=float)
    omega = float(setup.analysis.areas.omega)
    out = []
    for r in rows:
        push = Push(
            math.radians(float(r["direction_deg"])), float(r["impulse_Ns"]), 0.05, 0.5, body
        )
        p = predict_push(setup, push, float(position[2]), position, reach, True)  # type: ignore[arg-type]
        o = PushOutcome(push=push, relative=None, prediction=p, summary={}, trajectory={})
        out.append(o.safe("com", float(r["zmp_margin"]), omega))
    return out


def _candidate(
    scenario_path: str, rows: list[dict[str, str]], body: str, scale: float
) -> tuple[list[bool], list[bool]]:
    """(the default's calls at scale 1, the candidate's at ``scale``) on ``rows``."""
    options = BalanceTrialOptions(controller="id")
    scenario = load_scenario(scenario_path)
    stance = scenario.build_stance()
    gain = declared_angular_momentum_damping(
        options, stance, scenario.plane_height, scenario.gravity, SimOptions().timestep
    )
    judged = scenario.replace(angular_momentum_damping_time=1.0 / gain)
    reach = com_reach(stance)
    calls = []
    for s in (1.0, scale):
        setup = BalanceSetup.create(judged.replace(friction_scale=s), "servo", options)
        calls.append(_calls(setup, rows, body, reach))
    return calls[0], calls[1]


def main(argv: list[str] | None = None) -> int:
    """Run the pushes and print one line each, then the counts."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("records")
    p.add_argument("scenario")
    p.add_argument("--body", default="base_link")
    p.add_argument("--band", nargs=2, type=float, default=(0.75, 1.05))
    p.add_argument("--all", action="store_true", help="every pelvis push, not only band safe")
    p.add_argument("--after", type=float, default=2.5)
    p.add_argument("--friction-scale", default=None, help="a number in (0, 1] or controller")
    p.add_argument("--dry", action="store_true", help="the calls only, no trial")
    args = p.parse_args(argv)
    stance = Path(args.scenario).stem
    band = [
        r
        for r in csv.DictReader(open(args.records))
        if r["stance"] == stance
        and r["body"] == "pelvis"
        and args.band[0] - 1e-9 <= float(r["relative"]) <= args.band[1] + 1e-9
    ]
    if args.friction_scale is not None:
        scale = 0.65 if args.friction_scale == "controller" else float(args.friction_scale)
        default, candidate = _candidate(args.scenario, band, args.body, scale)
        agree = sum(d == (r["default_safe"] == "1") for d, r in zip(default, band, strict=True))
        standing = [r["strict_fail"] != "1" for r in band]
        print(
            json.dumps(
                {
                    "stance": stance,
                    "band_pushes": len(band),
                    "default_reproduced": agree,
                    "default_safe": sum(r["default_safe"] == "1" for r in band),
                    "candidate_safe": sum(candidate),
                    "standing_in_record": sum(standing),
                    "standing_in_record_called_safe_by_candidate": sum(
                        c and s for c, s in zip(candidate, standing, strict=True)
                    ),
                }
            ),
            flush=True,
        )
        rows = [r for r, c in zip(band, candidate, strict=True) if c]
        if args.dry:
            return 0
    else:
        rows = [
            r
            for r in csv.DictReader(open(args.records))
            if r["stance"] == stance
            and r["body"] == "pelvis"
            and (args.all or (r["default_safe"] == "1" and r in band))
        ]
    options = BalanceTrialOptions(controller="id", after=args.after)
    setup = BalanceSetup.create(args.scenario, "servo", options)
    failed = 0
    for r in rows:
        push = Push(
            math.radians(float(r["direction_deg"])),
            float(r["impulse_Ns"]),
            0.05,
            options.settle,
            args.body,
        )
        s = run_balance_trial(setup, push=push, options=options).summary()
        failed += bool(s["strict_fail"])
        print(
            json.dumps(
                {
                    "direction_deg": float(r["direction_deg"]),
                    "relative": float(r["relative"]),
                    "record": [r["outcome"], r["strict_fail"] == "1"],
                    "now": [s["outcome"], s["strict_fail"], s.get("reason")],
                    "events": [(e["contact"], e["kind"], round(e["time"], 3)) for e in s["events"]][
                        :3
                    ],
                }
            ),
            flush=True,
        )
    print(json.dumps({"stance": stance, "pushes": len(rows), "failed_strictly": failed}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
