"""``--profile``: cProfile of ``analyze()`` and of the projection, and a micro-breakdown of the
costs that cProfile cannot see (pinocchio's boost.python calls, the compiled kernel)."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

import impact_balance as ib
from benchmarks.speed.projection import projection_cases
from benchmarks.speed.targets import TARGET_PIPELINE_SCENARIO
from benchmarks.speed.timing import Case, measure, stats
from impact_balance.balance.areas import FORCE_BOX
from impact_balance.contacts.stance import Stance
from impact_balance.contacts.wrench_polytope import wrench_polytope
from impact_balance.projection import project_polytope
from impact_balance.projection.walk import NO_HINT

__all__ = ["profile_report", "profile_text"]


def _median_us(fn: Callable[[], Any], n: int) -> float:
    times, _ = measure({"x": Case(fn)}, n, 3)
    return stats(times["x"])["median"]


def _cprofile(fn: Callable[[], Any], n: int, top: int) -> dict[str, Any]:
    import cProfile
    import pstats

    prof = cProfile.Profile()
    prof.enable()
    for _ in range(n):
        fn()
    prof.disable()
    st = pstats.Stats(prof)
    total = st.total_tt
    rows = []
    for (file, line, func), (_cc, nc, tt, ct, _callers) in st.stats.items():
        where = (
            f"{os.path.relpath(file) if file.startswith('/') else file}:{line}({func})"
            if line
            else func
        )
        rows.append(
            {
                "function": where,
                "calls_per_run": nc / n,
                "tottime_pct": 100 * tt / total,
                "cumtime_pct": 100 * ct / total,
                "tottime_us_per_run": 1e6 * tt / n,
            }
        )
    rows.sort(key=lambda r: -r["tottime_pct"])
    return {"runs": n, "total_us_per_run": 1e6 * total / n, "top": rows[:top]}


def profile_report(args) -> dict[str, Any]:
    """cProfile of analyze() and of the projection, plus a micro-breakdown of the costs.

    cProfile sees neither inside pinocchio's boost.python calls nor inside the compiled
    projection kernel: their time is counted in the calling Python function, hence the
    micro-breakdown.
    """
    import pinocchio as pin

    from impact_balance.criteria.linear_exit import first_exit
    from impact_balance.projection import kernel, project_walk

    out: dict[str, Any] = {}
    sc = ib.load_scenario(TARGET_PIPELINE_SCENARIO)
    ib.analyze(sc)
    out["analyze"] = _cprofile(lambda: ib.analyze(sc), 50, 15)
    sc3 = ib.load_scenario("talos_three_contacts")
    poly3 = wrench_polytope(sc3.build_stance(), sc3.torque_limits, sc3.gravity)
    ours3 = projection_cases(poly3, args.pypoman_scale, args.seed)["ours"].fn
    out["projection_talos_three_contacts"] = _cprofile(ours3, 20, 10)

    # Micro-breakdown on palm_push_two_feet.
    stance = sc.build_stance()
    robot, model, q = stance.robot, stance.robot.model, stance.q
    data, v0 = model.createData(), np.zeros(model.nv)
    specs = [c.spec() for c in sc.contacts]

    def kinematics():
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        pin.ccrba(model, data, q, v0)
        pin.centerOfMass(model, data, q, False)
        pin.computeGeneralizedGravity(model, data, q)

    poly = wrench_polytope(stance, sc.torque_limits, sc.gravity)
    A, b, C, d, F = poly.projection_data()
    U, S, Vt = np.linalg.svd(C)
    x0 = Vt[: len(S)].T @ ((U.T @ d) / S)
    N = np.ascontiguousarray(Vt[len(S) :].T)
    areas = ib.areas_from_polytope(poly, sc.plane_height)
    model_imp = ib.impact_model(stance, sc.impact.spec())
    vel = areas.com_velocity_area
    G, h = vel.halfplanes
    n = max(50, args.repeat)
    micro = {
        "pin Model.createData()": _median_us(model.createData, n),
        "pin kinematics+Jacobians+CRBA+CoM+gravity": _median_us(kinematics, n),
        "Scenario.configuration_vector": _median_us(lambda: sc.configuration_vector(robot), n),
        "Stance(robot, q, contacts)": _median_us(lambda: Stance(robot, q, specs), n),
        "Scenario.build_stance": _median_us(sc.build_stance, n),
        "wrench_polytope": _median_us(
            lambda: wrench_polytope(stance, sc.torque_limits, sc.gravity), n
        ),
        "numpy SVD of the LIPM equalities (in project_walk)": _median_us(
            lambda: np.linalg.svd(C), n
        ),
        "compiled kernel project() alone": _median_us(
            lambda: kernel.project(A, b, F, x0, N, FORCE_BOX, 5000, NO_HINT), n
        ),
        "project_walk": _median_us(
            lambda: project_walk(A, b, C, d, F, box=FORCE_BOX, merge_tol=1e-6), n
        ),
        "areas_from_polytope (walk + affine maps)": _median_us(
            lambda: ib.areas_from_polytope(poly, sc.plane_height), n
        ),
        "project_polytope(method='bretl') (HiGHS, for comparison)": _median_us(
            lambda: project_polytope(A, b, C, d, F, box=FORCE_BOX, method="bretl"), n
        ),
        "impact_model": _median_us(lambda: ib.impact_model(stance, sc.impact.spec()), 10 * n),
        "Polygon.halfplanes (recomputed per call)": _median_us(lambda: vel.halfplanes, 10 * n),
        "criteria.first_exit": _median_us(
            lambda: first_exit(h - G @ np.zeros(2), model_imp.com_jump_rates @ G.T), 10 * n
        ),
        "max_contact_velocity": _median_us(
            lambda: ib.max_contact_velocity(vel, model_imp, sc.com_velocity), 10 * n
        ),
    }
    out["micro_us"] = micro
    walk = project_walk(A, b, C, d, F, box=FORCE_BOX, merge_tol=1e-6)
    out["walk"] = {
        "scenario": TARGET_PIPELINE_SCENARIO,
        "pivots": walk.pivots,
        "vertices": len(walk.polygon.vertices),
        "reduced_variables": int(N.shape[1]),
        "rows": int(A.shape[0]),
    }
    return out


def profile_text(p: dict[str, Any]) -> str:
    out = [
        "",
        "Profile (cProfile; pinocchio and the compiled kernel are counted in their Python caller)",
    ]
    for key in ("analyze", "projection_talos_three_contacts"):
        e = p[key]
        out.append(
            f"  {key}: {e['total_us_per_run']:.0f} us per run under cProfile ({e['runs']} runs); "
            "top by own time:"
        )
        for r in e["top"]:
            out.append(
                f"    {r['tottime_pct']:5.1f}%  {r['tottime_us_per_run']:8.0f} us  "
                f"{r['calls_per_run']:6.1f} calls  {r['function']}"
            )
    out.append("  micro-breakdown, median us (palm_push_two_feet):")
    for k, v in p["micro_us"].items():
        out.append(f"    {v:9.1f}  {k}")
    w = p["walk"]
    out.append(
        f"  walk on {w['scenario']}: {w['pivots']} pivots for {w['vertices']} vertices "
        f"({w['reduced_variables']} variables after the equalities, {w['rows']} rows before "
        "dropping zero rows)"
    )
    return "\n".join(out)
