"""One bundled stance measured whole: its projection, its pipeline and its maximum contact
velocity, with the headline figures beside the details."""

from __future__ import annotations

from typing import Any

import impact_balance as ib
from benchmarks.speed.pipeline import bench_max_velocity, bench_pipeline
from benchmarks.speed.projection import bench_projection
from benchmarks.speed.timing import progress
from impact_balance.contacts.wrench_polytope import wrench_polytope

__all__ = ["bench_stance"]


def bench_stance(name: str, args) -> dict[str, Any]:
    """The ``stances[name]`` entry of the result for the bundled scenario ``name``."""
    sc = ib.load_scenario(name)
    stance = sc.build_stance()
    poly = wrench_polytope(stance, sc.torque_limits, sc.gravity)
    progress(f"{name}: projection ...")
    proj = bench_projection(poly, args)
    progress(f"{name}: pipeline ...")
    pipe = bench_pipeline(sc, args)
    mv = bench_max_velocity(sc, args)
    return {
        "robot": stance.robot.name,
        "n_contacts": len(stance.contacts),
        "torque_limits": sc.torque_limits,
        "n_ineq": proj["n_ineq"],
        "project_median_us": proj["project_us"]["median"],
        "pypoman_median_us": proj.get("pypoman_us", {}).get("median"),
        "ratio_vs_pypoman": proj.get("ratio_vs_pypoman"),
        "area_rel_diff": proj.get("area_rel_diff"),
        "analyze_median_us": pipe["analyze"]["median"],
        "max_velocity_median_us": mv["max_velocity"]["median"] if mv else None,
        "projection": proj,
        "pipeline": pipe,
        "max_velocity": mv,
    }
