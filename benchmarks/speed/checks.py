"""The answer checks that set the exit status: every pypoman and Bretl/HiGHS polygon matches
ours within the tolerance, ours is deterministic, and ``analyze()`` agrees with the stages."""

from __future__ import annotations

from typing import Any

__all__ = ["answer_checks"]


def answer_checks(result: dict[str, Any], tol: float) -> dict[str, Any]:
    """``{"ok", "failures", "worst_symdiff_rel"}`` over the stances and the contact scaling rows."""
    stances = result["stances"]
    failures, worst = [], 0.0
    entries = [(n, e["projection"]) for n, e in stances.items()]
    entries += [
        (f"scaling {e['contacts']} (torque limits {e['torque_limits']})", e)
        for e in result.get("scaling", {}).get("contacts", [])
    ]
    for label, p in entries:
        if "match" not in p:
            continue
        worst = max(worst, p.get("symdiff_rel", 0.0))
        if not p["match"]:
            why = "; ".join(p["pypoman_errors"][:2]) or (
                f"symmetric difference {p.get('symdiff_rel', float('nan')):.2e} (pypoman),"
                f" {p.get('bretl_highs_symdiff_rel', float('nan')):.2e} (Bretl/HiGHS) > {tol:g}"
                if p["ours_deterministic"]
                else "ours not deterministic across repeats"
            )
            failures.append(f"{label}: {why}")
    for name, e in stances.items():
        if not e["pipeline"]["consistent"]:
            failures.append(f"{name}: analyze() and the staged pipeline disagree")
    return {"ok": not failures, "failures": failures, "worst_symdiff_rel": worst}
