"""The performance targets of issue 3, evaluated PASS/FAIL (informative: they never change the
exit status)."""

from __future__ import annotations

from typing import Any

__all__ = [
    "TARGET_MAXVEL_US",
    "TARGET_PIPELINE_SCENARIO",
    "TARGET_PIPELINE_US",
    "TARGET_RATIO",
    "evaluate_targets",
]

#: Targets of issue 3.
TARGET_RATIO = 10.0  # pypoman median / ours median, on every stance
TARGET_PIPELINE_US = 1000.0  # whole pipeline, Talos two feet with torque limits
TARGET_PIPELINE_SCENARIO = "palm_push_two_feet"
TARGET_MAXVEL_US = 50.0  # max contact velocity given the area


def evaluate_targets(result: dict[str, Any]) -> list[dict[str, Any]]:
    stances = result["stances"]
    targets = []
    ratios = {k: v["projection"].get("ratio_vs_pypoman") for k, v in stances.items()}
    ratios = {k: r for k, r in ratios.items() if r is not None}
    if ratios:
        worst = min(ratios, key=ratios.get)
        targets.append(
            {
                "target": (
                    f"area projection >= {TARGET_RATIO:g}x faster than pypoman (median "
                    "ratio) on every stance"
                ),
                "measured": (
                    f"worst {ratios[worst]:.2f}x ({worst}); best {max(ratios.values()):.2f}x"
                ),
                "pass": all(r >= TARGET_RATIO for r in ratios.values()),
            }
        )
    if TARGET_PIPELINE_SCENARIO in stances:
        p = stances[TARGET_PIPELINE_SCENARIO]["pipeline"]
        targets.append(
            {
                "target": (
                    "whole pipeline, Talos two feet with torque limits "
                    f"({TARGET_PIPELINE_SCENARIO}) < {TARGET_PIPELINE_US:g} us"
                ),
                "measured": (
                    f"analyze() median {p['analyze']['median']:.0f} us (sum of stage "
                    f"medians {p['sum_of_stages']['median']:.0f} us)"
                ),
                "pass": p["analyze"]["median"] < TARGET_PIPELINE_US,
            }
        )
    mv = {
        k: v["max_velocity"]["max_velocity"]["median"]
        for k, v in stances.items()
        if v.get("max_velocity")
    }
    if mv:
        worst = max(mv, key=mv.get)
        targets.append(
            {
                "target": f"max contact velocity given the area < {TARGET_MAXVEL_US:g} us",
                "measured": (
                    f"worst median {mv[worst]:.1f} us ({worst}); best {min(mv.values()):.1f} us"
                ),
                "pass": all(t < TARGET_MAXVEL_US for t in mv.values()),
            }
        )
    return targets
