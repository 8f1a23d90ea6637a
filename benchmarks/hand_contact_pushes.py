"""Listed pushes on one stance, each as push-test runs it (the id controller), to a CSV.

The before/after trials of docs/studies/hand-contacts.md (records in studies/hand_contacts/):

    python benchmarks/hand_contact_pushes.py palm_push_two_feet base_link out.csv 0:0.78 90:0.84

Each push is ``DEG:FRACTION``: its direction (deg from world x) and its impulse as a fraction of
that direction's boundary impulse (the CoM velocity area's, from rest), for push-test's 0.05 s
after its 0.3 s of settling, with push-test's trial options (2.5 s after the push). Columns:
direction, fraction, impulse (N s), outcome, reason, strict failure (0/1), its reason, the first
contact event (contact, kind, time in s).
"""

from __future__ import annotations

import csv
import math
import sys

from impact_balance.sim.studies.push import START_COM_VELOCITY, boundary_impulse
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions, Push

COLUMNS = [
    "direction_deg",
    "relative",
    "impulse_Ns",
    "outcome",
    "reason",
    "strict_fail",
    "strict_reason",
    "first_event",
]


def main(argv: list[str]) -> int:
    """Run the pushes of ``argv`` (scenario, body, output CSV, DEG:FRACTION ...)."""
    scenario, body, out, *pushes = argv
    options = BalanceTrialOptions(controller="id")
    setup = BalanceSetup.create(scenario, "servo", options)
    a = setup.analysis
    with open(out, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(COLUMNS)
        for item in pushes:
            deg, rel = (float(x) for x in item.split(":"))
            angle = math.radians(deg)
            impulse = rel * boundary_impulse(
                a.areas.com_velocity_area, a.stance.mass, angle, START_COM_VELOCITY
            )
            push = Push(angle, impulse, 0.05, options.settle, body)
            s = run_balance_trial(setup, push=push, options=options).summary()
            events = s.get("events") or []
            first = (
                f"{events[0]['contact']} {events[0]['kind']} {events[0]['time']:.3f}"
                if events
                else ""
            )
            row = [deg, rel, round(impulse, 4), s.get("outcome"), s.get("reason")]
            writer.writerow(
                [*row, int(bool(s.get("strict_fail"))), s.get("strict_reason") or "", first]
            )
            f.flush()
            print(*row, s.get("strict_fail"), first, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
