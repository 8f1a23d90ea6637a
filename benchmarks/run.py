#!/usr/bin/env python
"""Benchmark of impact_balance (issue 3, measurement part).

    python benchmarks/run.py [--json] [--repeat N] [--scenarios NAME ...] [--no-scaling]

Measures, in one run and on the same polytopes:

1. the CoM-velocity-area projection (``impact_balance.projection.project_polytope``, what
   ``areas_from_polytope`` calls: the compiled parametric walk) against
   ``pypoman.project_polytope(..., method="bretl")`` and against the project's own
   LP-per-edge Bretl path (HiGHS), given the same inequality, equality and projection
   matrices, and checks at every repetition that all give the same polygon (relative area of
   the symmetric difference);
2. the whole pipeline from a configuration to the answer, stage by stage, and
   ``impact_balance.analyze`` end to end (YAML loading excluded);
3. the maximum contact velocity alone, given the area;
4. scaling with the number of contacts (Talos, 1 to 4, with and without torque limits) and
   with the number of friction-cone edges of the impact model (8 to 64).

Times are wall-clock ``time.perf_counter`` per call, in microseconds, after a warm-up, with
the garbage collector paused; cases of one group are run round-robin so that drifts of the
machine hit them alike. Reported: median and p10-p90 (IQR and min in the JSON).

Exit status: 0 when every pypoman/impact_balance comparison agrees within ``--tol``
(default 1e-6 relative area), 1 otherwise. Performance targets are reported PASS/FAIL but
never change the exit status.
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import importlib.metadata
import json
import math
import os
import platform
import sys
import time
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

import impact_balance as ib
from impact_balance.areas import FORCE_BOX, FORCE_TOLERANCE
from impact_balance.constraints import wrench_polytope
from impact_balance.projection import project_polytope
from impact_balance.stance import ContactSpec, Stance

try:  # pypoman is a test extra of the project
    import pypoman
except ImportError:  # pragma: no cover
    pypoman = None

#: Targets of issue 3.
TARGET_RATIO = 10.0  # pypoman median / ours median, on every stance
TARGET_PIPELINE_US = 1000.0  # whole pipeline, Talos two feet with torque limits
TARGET_PIPELINE_SCENARIO = "palm_push_two_feet"
TARGET_MAXVEL_US = 50.0  # max contact velocity given the area

PIPELINE_STAGES = ("stance", "constraints", "areas", "impact_model", "max_velocity", "zmp_max_velocity")


# ---------------------------------------------------------------------------------------
# timing
# ---------------------------------------------------------------------------------------
def stats(samples_us: list[float]) -> dict[str, float]:
    a = np.asarray(samples_us, dtype=float)
    p10, p25, p50, p75, p90 = np.percentile(a, [10, 25, 50, 75, 90])
    return {
        "median": float(p50), "p10": float(p10), "p90": float(p90), "iqr": float(p75 - p25),
        "min": float(a.min()), "n": int(a.size),
    }


@dataclasses.dataclass
class Case:
    """A timed call: ``setup(i)`` (untimed, optional), ``fn()`` (timed), ``keep(result)`` (untimed).

    Results are dropped (released before the next timed call) unless ``keep`` maps them to
    what to store: keeping whole results alive (e.g. pinocchio Data) makes later allocations
    much slower and would bias the timings.
    """

    fn: Callable[[], Any]
    setup: Callable[[int], None] | None = None
    keep: Callable[[Any], Any] | None = None


def measure(cases: dict[str, Case], repeat: int, warmup: int) -> tuple[dict[str, list[float]], dict[str, list[Any]]]:
    """Round-robin timing of ``cases``; returns per case the times (us) and the results."""
    for w in range(warmup):
        for case in cases.values():
            if case.setup is not None:
                case.setup(-1 - w)
            case.fn()
    times: dict[str, list[float]] = {k: [] for k in cases}
    results: dict[str, list[Any]] = {k: [] for k in cases}
    gc.collect()
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        for i in range(repeat):
            for name, case in cases.items():
                if case.setup is not None:
                    case.setup(i)
                t0 = time.perf_counter()
                r = case.fn()
                t1 = time.perf_counter()
                times[name].append((t1 - t0) * 1e6)
                if case.keep is not None:
                    results[name].append(case.keep(r))
                r = None  # release now, outside the timed region
    finally:
        if was_enabled:
            gc.enable()
    return times, results


# ---------------------------------------------------------------------------------------
# polygon comparison (independent of impact_balance.polygon)
# ---------------------------------------------------------------------------------------
def hull(points: np.ndarray) -> np.ndarray:
    """Convex hull, counter-clockwise, collinear points dropped (Andrew's monotone chain)."""
    pts = sorted({(float(x), float(y)) for x, y in np.asarray(points, dtype=float).reshape(-1, 2)})
    if len(pts) <= 2:
        return np.array(pts).reshape(-1, 2)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def area(v: np.ndarray) -> float:
    if len(v) < 3:
        return 0.0
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def intersection(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Intersection of two CCW convex polygons (Sutherland-Hodgman)."""
    out = [tuple(v) for v in p]
    for k in range(len(q)):
        a, b = q[k], q[(k + 1) % len(q)]
        if not out:
            break
        inp, out = out, []

        def side(v):
            return (b[0] - a[0]) * (v[1] - a[1]) - (b[1] - a[1]) * (v[0] - a[0])

        for j in range(len(inp)):
            cur, prev = inp[j], inp[j - 1]
            sc, sp = side(cur), side(prev)
            if sc >= 0:
                if sp < 0:
                    t = sp / (sp - sc)
                    out.append((prev[0] + t * (cur[0] - prev[0]), prev[1] + t * (cur[1] - prev[1])))
                out.append(cur)
            elif sp >= 0:
                t = sp / (sp - sc)
                out.append((prev[0] + t * (cur[0] - prev[0]), prev[1] + t * (cur[1] - prev[1])))
    return np.array(out).reshape(-1, 2)


def compare(reference: np.ndarray, other: np.ndarray) -> dict[str, float]:
    """Relative area difference and relative symmetric-difference area of two point sets' hulls."""
    P, Q = hull(reference), hull(other)
    a_p, a_q = area(P), area(Q)
    if a_p <= 0.0:  # degenerate reference: absolute figures
        return {"area_rel_diff": abs(a_q - a_p), "symdiff_rel": abs(a_q - a_p), "degenerate": True}
    a_i = area(intersection(P, Q)) if len(Q) >= 3 else 0.0
    return {"area_rel_diff": (a_q - a_p) / a_p, "symdiff_rel": (a_p + a_q - 2.0 * a_i) / a_p, "degenerate": False}


# ---------------------------------------------------------------------------------------
# projection: ours vs pypoman
# ---------------------------------------------------------------------------------------
def projection_cases(poly: ib.WrenchPolytope, scale: float, seed: int) -> dict[str, Case]:
    """Both projections of ``poly`` onto the resultant horizontal force (units of m g).

    Same matrices for both; pypoman projects onto ``scale * F`` (its stopping and merging
    tolerances are absolute) and clips unbounded directions with the same box as ours.
    """
    w = poly.weight
    A, b, C, d, F = poly.A, poly.b / w, poly.C, poly.d / w, poly.F
    E, f = scale * F, np.zeros(2)

    def ours():
        return project_polytope(A, b, C, d, F, tol=FORCE_TOLERANCE, box=FORCE_BOX)

    def ours_bretl():
        return project_polytope(A, b, C, d, F, tol=FORCE_TOLERANCE, box=FORCE_BOX, method="bretl").polygon.vertices

    def theirs():
        try:
            vertices = pypoman.project_polytope(
                proj=(E, f), ineq=(A, b), eq=(C, d), method="bretl", max_radius=scale * FORCE_BOX
            )
            return np.array(vertices) / scale
        except Exception as exc:  # noqa: BLE001 - report, do not crash the benchmark
            return exc

    def reseed(i: int) -> None:  # pypoman's first ray is random (numpy's global RNG)
        np.random.seed((seed + i) % 2**32)

    cases = {"ours": Case(ours, keep=lambda r: r)}  # a ProjectionResult holds only the polygon
    cases["bretl_highs"] = Case(ours_bretl, keep=lambda r: r)
    if pypoman is not None:
        cases["pypoman"] = Case(theirs, reseed, keep=lambda r: r)
    return cases


def check_projection(results: dict[str, list[Any]]) -> dict[str, Any]:
    """Compare every pypoman result (and every repeat of ours) with our first result."""
    ours = results["ours"]
    ref = ours[0].polygon.vertices
    out: dict[str, Any] = {
        "method": ours[0].method, "pivots": ours[0].pivots, "n_lp": ours[0].n_lp,
        "n_vertices": len(ref), "bounded": bool(ours[0].polygon.bounded),
        "ours_deterministic": all(np.array_equal(r.polygon.vertices, ref) for r in ours),
    }
    if "bretl_highs" in results:  # our LP-per-edge path: same polygon
        sd = [compare(ref, v)["symdiff_rel"] for v in results["bretl_highs"]] if len(ref) else [0.0]
        out["bretl_highs_symdiff_rel"] = float(max(sd))
    if "pypoman" not in results:
        return out
    diffs, errors, nverts = [], [], []
    for r in results["pypoman"]:
        if len(ref) == 0:  # infeasible: pypoman must fail too (it raises on infeasible LPs)
            if not isinstance(r, Exception):
                errors.append("ours is empty but pypoman returned vertices")
            continue
        if isinstance(r, Exception):
            errors.append(f"{type(r).__name__}: {r}")
            continue
        diffs.append(compare(ref, r))
        nverts.append(len(r))
    out["pypoman_errors"] = errors
    if diffs:
        ad = np.array([x["area_rel_diff"] for x in diffs])
        sd = np.array([x["symdiff_rel"] for x in diffs])
        out.update(
            area_rel_diff=float(ad[np.argmax(np.abs(ad))]),  # worst over repeats, signed (pypoman - ours)
            symdiff_rel=float(sd.max()),
            symdiff_rel_median=float(np.median(sd)),
            pypoman_n_vertices=int(np.median(nverts)),
        )
    return out


def bench_projection(poly, args) -> dict[str, Any]:
    times, results = measure(projection_cases(poly, args.pypoman_scale, args.seed), args.repeat, args.warmup)
    entry: dict[str, Any] = {
        "n_vars": int(poly.A.shape[1]), "n_ineq": int(poly.A.shape[0]), "n_eq": int(poly.C.shape[0]),
        "project_us": stats(times["ours"]),
    }
    entry.update(check_projection(results))
    entry["bretl_highs_us"] = stats(times["bretl_highs"])
    entry["ratio_vs_bretl_highs"] = entry["bretl_highs_us"]["median"] / entry["project_us"]["median"]
    if "pypoman" in times:
        entry["pypoman_us"] = stats(times["pypoman"])
        entry["ratio_vs_pypoman"] = entry["pypoman_us"]["median"] / entry["project_us"]["median"]
        entry["match"] = (
            not entry["pypoman_errors"] and entry.get("symdiff_rel", math.inf) <= args.tol and entry["ours_deterministic"]
            and entry["bretl_highs_symdiff_rel"] <= args.tol
        )
    return entry


# ---------------------------------------------------------------------------------------
# pipeline
# ---------------------------------------------------------------------------------------
def bench_pipeline(sc: ib.Scenario, args) -> dict[str, Any]:
    sc.build_stance()  # loads (and caches) the robot model: not part of the timings
    stance = sc.build_stance()
    poly = wrench_polytope(stance, sc.torque_limits, sc.gravity)
    areas = ib.areas_from_polytope(poly, sc.plane_height)
    cases = {
        "stance": Case(sc.build_stance),
        "constraints": Case(lambda: wrench_polytope(stance, sc.torque_limits, sc.gravity)),
        "areas": Case(lambda: ib.areas_from_polytope(poly, sc.plane_height)),
    }
    model = None
    if sc.impact is not None:
        cfg = sc.impact
        model = ib.impact_model(stance, cfg.spec())
        cases["impact_model"] = Case(lambda: ib.impact_model(stance, cfg.spec()))
        cases["max_velocity"] = Case(lambda: ib.max_contact_velocity(areas.com_velocity_area, model, sc.com_velocity))
        cases["zmp_max_velocity"] = Case(
            lambda: ib.zmp_max_contact_velocity(areas.zmp_area, model, stance.com, sc.plane_height, sc.gravity, cfg.duration)
        )
    cases["analyze"] = Case(lambda: ib.analyze(sc))
    times, _ = measure(cases, args.repeat, args.warmup)
    out: dict[str, Any] = {k: stats(v) for k, v in times.items()}
    out["sum_of_stages"] = {"median": float(sum(out[k]["median"] for k in PIPELINE_STAGES if k in out))}
    # Sanity: analyze() and the staged pipeline give the same answer.
    a = ib.analyze(sc)
    out["consistent"] = bool(np.allclose(a.areas.com_velocity_area.vertices, areas.com_velocity_area.vertices, atol=1e-12))
    if model is not None:
        staged = ib.max_contact_velocity(areas.com_velocity_area, model, sc.com_velocity).max_approach_speed
        out["consistent"] &= bool(a.impact.max_contact_velocity == staged or (math.isinf(staged) and math.isinf(a.impact.max_contact_velocity)))
        out["max_contact_velocity_m_s"] = None if math.isinf(staged) else staged
    return out


def bench_max_velocity(sc: ib.Scenario, args) -> dict[str, Any] | None:
    """The maximum contact velocity alone, given the area (many more repeats: it is cheap)."""
    if sc.impact is None:
        return None
    stance = sc.build_stance()
    areas = ib.balance_areas(stance, sc.plane_height, sc.torque_limits, sc.gravity)
    model = ib.impact_model(stance, sc.impact.spec())
    vel = areas.com_velocity_area
    cases = {
        "max_velocity": Case(lambda: ib.max_contact_velocity(vel, model, sc.com_velocity)),
        "zmp_max_velocity": Case(
            lambda: ib.zmp_max_contact_velocity(areas.zmp_area, model, stance.com, sc.plane_height, sc.gravity, sc.impact.duration)
        ),
    }
    times, _ = measure(cases, args.repeat_cheap, max(args.warmup, 10))
    return {k: stats(v) for k, v in times.items()} | {"area_edges": len(vel.vertices)}


# ---------------------------------------------------------------------------------------
# scaling
# ---------------------------------------------------------------------------------------
def talos_contact_sets() -> tuple[ib.Robot, np.ndarray, list[tuple[str, list[ContactSpec]]]]:
    import pinocchio as pin

    sc = ib.load_scenario("talos_three_contacts")
    robot = sc.load_robot()
    q = sc.configuration_vector(robot)
    left, right, left_hand = (c.spec() for c in sc.contacts)
    # Right palm (flat +x face of the gripper, as the palm_push impact point) on a wall in
    # front: contact z = gripper -x, i.e. world -x here (checked below).
    right_hand = ContactSpec(
        "gripper_right_base_link", 0.7, (0.1, 0.08),
        pin.SE3(pin.rpy.rpyToMatrix(0.0, -math.pi / 2, 0.0), np.array([0.051, 0.0, -0.045])),
    )
    sets = [
        ("right foot", [right]),
        ("two feet", [left, right]),
        ("two feet + left hand (wall)", [left, right, left_hand]),
        ("two feet + both hands (walls)", [left, right, left_hand, right_hand]),
    ]
    return robot, q, sets


def bench_contacts(args) -> list[dict[str, Any]]:
    robot, q, sets = talos_contact_sets()
    rows = []
    for label, specs in sets:
        stance = Stance(robot, q, specs)
        t_stance, _ = measure({"stance": Case(lambda: Stance(robot, q, specs))}, args.repeat, args.warmup)
        for tl in (True, False):
            poly = wrench_polytope(stance, tl)
            t_poly, _ = measure({"constraints": Case(lambda: wrench_polytope(stance, tl))}, args.repeat, args.warmup)
            entry = {
                "contacts": label, "n_contacts": len(specs), "torque_limits": tl,
                "normals": [np.round(c.normal, 3).tolist() for c in stance.contacts],
                "stance_us": stats(t_stance["stance"]), "constraints_us": stats(t_poly["constraints"]),
            }
            entry.update(bench_projection(poly, args))
            rows.append(entry)
            progress(f"  scaling {label}, torque limits {tl}: {entry['project_us']['median']:.0f} us, {entry['pivots']} pivots")
    return rows


def bench_cone_edges(args, names=("palm_push_two_feet", "talos_three_contacts")) -> list[dict[str, Any]]:
    rows = []
    for name in names:
        sc = ib.load_scenario(name)
        stance = sc.build_stance()
        areas = ib.balance_areas(stance, sc.plane_height, sc.torque_limits, sc.gravity)
        for n in (8, 16, 32, 64):
            spec = dataclasses.replace(sc.impact.spec(), cone_edges=n)
            model = ib.impact_model(stance, spec)
            cases = {
                "impact_model": Case(lambda: ib.impact_model(stance, spec)),
                "max_velocity": Case(lambda: ib.max_contact_velocity(areas.com_velocity_area, model, sc.com_velocity)),
                "zmp_max_velocity": Case(
                    lambda: ib.zmp_max_contact_velocity(areas.zmp_area, model, stance.com, sc.plane_height, sc.gravity, spec.duration)
                ),
            }
            times, _ = measure(cases, args.repeat_cheap, max(args.warmup, 10))
            v = ib.max_contact_velocity(areas.com_velocity_area, model, sc.com_velocity).max_approach_speed
            rows.append({"scenario": name, "cone_edges": n, "max_contact_velocity_m_s": None if math.isinf(v) else v}
                        | {f"{k}_us": stats(t) for k, t in times.items()})
    return rows


# ---------------------------------------------------------------------------------------
# profile (--profile)
# ---------------------------------------------------------------------------------------
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
        where = f"{os.path.relpath(file) if file.startswith('/') else file}:{line}({func})" if line else func
        rows.append({"function": where, "calls_per_run": nc / n, "tottime_pct": 100 * tt / total,
                     "cumtime_pct": 100 * ct / total, "tottime_us_per_run": 1e6 * tt / n})
    rows.sort(key=lambda r: -r["tottime_pct"])
    return {"runs": n, "total_us_per_run": 1e6 * total / n, "top": rows[:top]}


def profile_report(args) -> dict[str, Any]:
    """cProfile of analyze() and of the projection, plus a micro-breakdown of the costs.

    cProfile sees neither inside pinocchio's boost.python calls nor inside the compiled
    projection kernel: their time is counted in the calling Python function, hence the
    micro-breakdown.
    """
    import pinocchio as pin

    from impact_balance.criteria import first_exit
    from impact_balance.projection import _kernel, project_walk

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
    w = poly.weight
    A, b, C, d, F = poly.A, poly.b / w, poly.C, poly.d / w, poly.F
    U, S, Vt = np.linalg.svd(C)
    x0 = Vt[:len(S)].T @ ((U.T @ d) / S)
    N = np.ascontiguousarray(Vt[len(S):].T)
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
        "wrench_polytope": _median_us(lambda: wrench_polytope(stance, sc.torque_limits, sc.gravity), n),
        "numpy SVD of the LIPM equalities (in project_walk)": _median_us(lambda: np.linalg.svd(C), n),
        "compiled kernel project() alone": _median_us(
            lambda: _kernel.project(A, b, F, x0, N, FORCE_BOX, 1e-6, 5000), n),
        "project_walk": _median_us(lambda: project_walk(A, b, C, d, F, box=FORCE_BOX, merge_tol=1e-6), n),
        "areas_from_polytope (walk + affine maps)": _median_us(lambda: ib.areas_from_polytope(poly, sc.plane_height), n),
        "project_polytope(method='bretl') (HiGHS, for comparison)": _median_us(
            lambda: project_polytope(A, b, C, d, F, box=FORCE_BOX, method="bretl"), n),
        "impact_model": _median_us(lambda: ib.impact_model(stance, sc.impact.spec()), 10 * n),
        "Polygon.halfplanes (recomputed per call)": _median_us(lambda: vel.halfplanes, 10 * n),
        "criteria.first_exit": _median_us(lambda: first_exit(h - G @ np.zeros(2), model_imp.com_jump_rates @ G.T), 10 * n),
        "max_contact_velocity": _median_us(lambda: ib.max_contact_velocity(vel, model_imp, sc.com_velocity), 10 * n),
    }
    out["micro_us"] = micro
    walk = project_walk(A, b, C, d, F, box=FORCE_BOX, merge_tol=1e-6)
    out["walk"] = {"scenario": TARGET_PIPELINE_SCENARIO, "pivots": walk.pivots, "vertices": len(walk.polygon.vertices),
                   "reduced_variables": int(N.shape[1]), "rows": int(A.shape[0])}
    return out


def profile_text(p: dict[str, Any]) -> str:
    out = ["", "Profile (cProfile; pinocchio and the compiled kernel are counted in their Python caller)"]
    for key in ("analyze", "projection_talos_three_contacts"):
        e = p[key]
        out.append(f"  {key}: {e['total_us_per_run']:.0f} us per run under cProfile ({e['runs']} runs); top by own time:")
        for r in e["top"]:
            out.append(f"    {r['tottime_pct']:5.1f}%  {r['tottime_us_per_run']:8.0f} us  {r['calls_per_run']:6.1f} calls  {r['function']}")
    out.append("  micro-breakdown, median us (palm_push_two_feet):")
    for k, v in p["micro_us"].items():
        out.append(f"    {v:9.1f}  {k}")
    w = p["walk"]
    out.append(f"  walk on {w['scenario']}: {w['pivots']} pivots for {w['vertices']} vertices"
               f" ({w['reduced_variables']} variables after the equalities, {w['rows']} rows before dropping zero rows)")
    return "\n".join(out)


# ---------------------------------------------------------------------------------------
# machine
# ---------------------------------------------------------------------------------------
def machine_info() -> dict[str, Any]:
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass

    def version(dist: str) -> str | None:
        try:
            return importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            return None

    info = {
        "platform": platform.platform(),
        "cpu": cpu,
        "cpu_count": os.cpu_count(),
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "python": sys.version.split()[0],
        "versions": {d: version(d) for d in ("impact-balance", "numpy", "scipy", "numba", "highspy", "pin", "pypoman", "cvxopt")},
    }
    if pypoman is not None:
        from pypoman.lp import GLPK_IF_AVAILABLE

        info["pypoman_lp_solver"] = GLPK_IF_AVAILABLE or "cvxopt"
    return info


# ---------------------------------------------------------------------------------------
# report
# ---------------------------------------------------------------------------------------
def progress(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def fmt_us(s: dict[str, float] | None, spread: bool = True) -> str:
    if not s:
        return "-"
    m = s["median"]
    core = f"{m:.0f}" if m >= 100 else f"{m:.1f}"
    if spread and "p10" in s:
        return f"{core} ({s['p10']:.0f}-{s['p90']:.0f})" if m >= 100 else f"{core} ({s['p10']:.1f}-{s['p90']:.1f})"
    return core


def table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)]
    line = lambda cells: "  ".join(c.rjust(w) if i else c.ljust(w) for i, (c, w) in enumerate(zip(cells, widths)))  # noqa: E731
    return "\n".join([line(headers), line(["-" * w for w in widths])] + [line(r) for r in rows])


def evaluate_targets(result: dict[str, Any]) -> list[dict[str, Any]]:
    stances = result["stances"]
    targets = []
    ratios = {k: v["projection"].get("ratio_vs_pypoman") for k, v in stances.items()}
    ratios = {k: r for k, r in ratios.items() if r is not None}
    if ratios:
        worst = min(ratios, key=ratios.get)
        targets.append({
            "target": f"area projection >= {TARGET_RATIO:g}x faster than pypoman (median ratio) on every stance",
            "measured": f"worst {ratios[worst]:.2f}x ({worst}); best {max(ratios.values()):.2f}x",
            "pass": all(r >= TARGET_RATIO for r in ratios.values()),
        })
    if TARGET_PIPELINE_SCENARIO in stances:
        p = stances[TARGET_PIPELINE_SCENARIO]["pipeline"]
        targets.append({
            "target": f"whole pipeline, Talos two feet with torque limits ({TARGET_PIPELINE_SCENARIO}) < {TARGET_PIPELINE_US:g} us",
            "measured": f"analyze() median {p['analyze']['median']:.0f} us (sum of stage medians {p['sum_of_stages']['median']:.0f} us)",
            "pass": p["analyze"]["median"] < TARGET_PIPELINE_US,
        })
    mv = {k: v["max_velocity"]["max_velocity"]["median"] for k, v in stances.items() if v.get("max_velocity")}
    if mv:
        worst = max(mv, key=mv.get)
        targets.append({
            "target": f"max contact velocity given the area < {TARGET_MAXVEL_US:g} us",
            "measured": f"worst median {mv[worst]:.1f} us ({worst}); best {min(mv.values()):.1f} us",
            "pass": all(t < TARGET_MAXVEL_US for t in mv.values()),
        })
    return targets


def text_report(result: dict[str, Any], args) -> str:
    out = []
    m = result["machine"]
    out.append(f"Machine: {m['cpu']}, {m['cpu_count']} CPUs; {m['platform']}; Python {m['python']}")
    out.append("Versions: " + ", ".join(f"{k} {v}" for k, v in m["versions"].items()) + f"; pypoman LP solver: {m.get('pypoman_lp_solver')}")
    s = result["settings"]
    out.append(f"Repeats: {s['repeat']} (cheap calls {s['repeat_cheap']}), warm-up {s['warmup']}; times in us, median (p10-p90)")
    out.append("")
    out.append("1. Projection (resultant horizontal force polygon, units of m g): ours (compiled walk) vs pypoman bretl"
               f" (onto {s['pypoman_scale']:g} F) and vs our own Bretl/HiGHS path;"
               f" agreement = relative area of the symmetric difference, tol {s['tol']:g}, with both")
    rows = []
    for name, e in result["stances"].items():
        p = e["projection"]
        rows.append([
            name, e["robot"], str(e["n_contacts"]), str(p["n_ineq"]), str(p["pivots"]), str(p["n_vertices"]),
            fmt_us(p["project_us"]), fmt_us(p.get("pypoman_us")),
            f"{p['ratio_vs_pypoman']:.1f}" if "ratio_vs_pypoman" in p else "-",
            fmt_us(p["bretl_highs_us"], False), f"{p['ratio_vs_bretl_highs']:.1f}",
            f"{p['area_rel_diff']:+.1e}" if "area_rel_diff" in p else "-",
            f"{p['symdiff_rel']:.1e}" if "symdiff_rel" in p else "-",
            ("ok" if p.get("match") else "MISMATCH") if "match" in p else "-",
        ])
    out.append(table(["stance", "robot", "contacts", "ineq rows", "pivots", "verts", "ours us", "pypoman us",
                      "ratio", "bretl/HiGHS us", "ratio", "area rel diff", "symdiff", "check"], rows))
    out.append("")
    out.append("2. Pipeline per stage (median us; analyze() = whole pipeline end to end, YAML excluded)")
    rows = []
    for name, e in result["stances"].items():
        p = e["pipeline"]
        rows.append([name] + [fmt_us(p.get(k), False) for k in PIPELINE_STAGES]
                    + [fmt_us({"median": p["sum_of_stages"]["median"]}, False), fmt_us(p["analyze"])])
    out.append(table(["stance", *PIPELINE_STAGES, "sum", "analyze (p10-p90)"], rows))
    out.append("")
    out.append("3. Maximum contact velocity given the area")
    rows = []
    for name, e in result["stances"].items():
        mv = e.get("max_velocity")
        if mv:
            v = e["pipeline"].get("max_contact_velocity_m_s")
            rows.append([name, str(mv["area_edges"]), fmt_us(mv["max_velocity"]), fmt_us(mv["zmp_max_velocity"]),
                         "inf" if v is None else f"{v:.4f}"])
    out.append(table(["stance", "area edges", "max_contact_velocity us", "zmp_max_contact_velocity us", "answer m/s"], rows))
    sc = result.get("scaling")
    if sc:
        out.append("")
        out.append("4a. Scaling with contacts (Talos, configuration of talos_three_contacts)")
        rows = []
        for e in sc["contacts"]:
            rows.append([
                e["contacts"], "yes" if e["torque_limits"] else "no", str(e["n_ineq"]), str(e["pivots"]), str(e["n_vertices"]),
                fmt_us(e["stance_us"], False), fmt_us(e["constraints_us"], False), fmt_us(e["project_us"]),
                fmt_us(e.get("pypoman_us")), f"{e['ratio_vs_pypoman']:.1f}" if "ratio_vs_pypoman" in e else "-",
                f"{e['symdiff_rel']:.1e}" if "symdiff_rel" in e else "-",
                ("ok" if e.get("match") else "MISMATCH") if "match" in e else "-",
            ])
        out.append(table(["contacts", "torque lim", "ineq rows", "pivots", "verts", "Stance us", "constraints us",
                          "ours us", "pypoman us", "ratio", "symdiff", "check"], rows))
        out.append("")
        out.append("4b. Scaling with friction-cone edges of the impact (median us)")
        rows = [[e["scenario"], str(e["cone_edges"]), fmt_us(e["impact_model_us"]), fmt_us(e["max_velocity_us"]),
                 fmt_us(e["zmp_max_velocity_us"]),
                 "inf" if e["max_contact_velocity_m_s"] is None else f"{e['max_contact_velocity_m_s']:.4f}"]
                for e in sc["cone_edges"]]
        out.append(table(["stance", "edges", "impact_model", "max_velocity", "zmp_max_velocity", "answer m/s"], rows))
    out.append("")
    out.append("Targets (informative; they do not change the exit status)")
    for t in result["targets"]:
        out.append(f"  [{'PASS' if t['pass'] else 'FAIL'}] {t['target']}: {t['measured']}")
    c = result["checks"]
    out.append("")
    if c["ok"]:
        out.append(f"Answers: OK, every pypoman and Bretl/HiGHS polygon matches ours within {s['tol']:g} relative area "
                   f"(worst symmetric difference {c['worst_symdiff_rel']:.1e}).")
    else:
        out.append("Answers: MISMATCH")
        for f in c["failures"]:
            out.append(f"  {f}")
    return "\n".join(out)


# ---------------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the text tables")
    ap.add_argument("--repeat", type=int, default=50, help="timed repetitions per case (default 50)")
    ap.add_argument("--warmup", type=int, default=3, help="untimed warm-up calls per case (default 3)")
    ap.add_argument("--scenarios", nargs="*", help="bundled scenario names (default: all)")
    ap.add_argument("--no-scaling", action="store_true", help="skip the scaling part")
    ap.add_argument("--pypoman-scale", type=float, default=1e3,
                    help="pypoman projects onto SCALE*F (its tolerances are absolute: 1e-4, 1e-2); default 1e3")
    ap.add_argument("--tol", type=float, default=1e-6, help="max relative area of the symmetric difference (default 1e-6)")
    ap.add_argument("--profile", action="store_true", help="also profile analyze() and the projection (cProfile + micro-breakdown)")
    ap.add_argument("--seed", type=int, default=0, help="seed of numpy's global RNG for pypoman (seed + repetition)")
    ap.add_argument("--no-sweep", action="store_true", help="skip the sweep rates (benchmarks/sweep.py --quick)")
    args = ap.parse_args(argv)
    args.repeat = max(1, args.repeat)
    args.repeat_cheap = 10 * args.repeat
    if pypoman is None:
        progress("warning: pypoman is not installed: no comparison")
    warnings.simplefilter("ignore")  # pypoman/cvxopt chatter must not pollute --json

    t_start = time.perf_counter()
    names = args.scenarios or list(ib.bundled_scenarios())
    stances: dict[str, Any] = {}
    for name in names:
        sc = ib.load_scenario(name)
        stance = sc.build_stance()
        poly = wrench_polytope(stance, sc.torque_limits, sc.gravity)
        progress(f"{name}: projection ...")
        proj = bench_projection(poly, args)
        progress(f"{name}: pipeline ...")
        pipe = bench_pipeline(sc, args)
        mv = bench_max_velocity(sc, args)
        stances[name] = {
            "robot": stance.robot.name, "n_contacts": len(stance.contacts), "torque_limits": sc.torque_limits,
            "n_ineq": proj["n_ineq"], "project_median_us": proj["project_us"]["median"],
            "pypoman_median_us": proj.get("pypoman_us", {}).get("median"),
            "ratio_vs_pypoman": proj.get("ratio_vs_pypoman"), "area_rel_diff": proj.get("area_rel_diff"),
            "analyze_median_us": pipe["analyze"]["median"],
            "max_velocity_median_us": mv["max_velocity"]["median"] if mv else None,
            "projection": proj, "pipeline": pipe, "max_velocity": mv,
        }
    result: dict[str, Any] = {
        "benchmark": "impact_balance benchmarks/run.py",
        "machine": machine_info(),
        "settings": {"repeat": args.repeat, "repeat_cheap": args.repeat_cheap, "warmup": args.warmup,
                     "pypoman_scale": args.pypoman_scale, "tol": args.tol, "seed": args.seed, "unit": "us"},
        "stances": stances,
    }
    if not args.no_scaling:
        progress("scaling: contacts ...")
        contacts = bench_contacts(args)
        progress("scaling: cone edges ...")
        result["scaling"] = {"contacts": contacts, "cone_edges": bench_cone_edges(args)}

    failures, worst = [], 0.0
    entries = [(n, e["projection"]) for n, e in stances.items()]
    entries += [(f"scaling {e['contacts']} (torque limits {e['torque_limits']})", e) for e in result.get("scaling", {}).get("contacts", [])]
    for label, p in entries:
        if "match" not in p:
            continue
        worst = max(worst, p.get("symdiff_rel", 0.0))
        if not p["match"]:
            why = "; ".join(p["pypoman_errors"][:2]) or (
                f"symmetric difference {p.get('symdiff_rel', float('nan')):.2e} (pypoman),"
                f" {p.get('bretl_highs_symdiff_rel', float('nan')):.2e} (Bretl/HiGHS) > {args.tol:g}"
                if p["ours_deterministic"] else "ours not deterministic across repeats")
            failures.append(f"{label}: {why}")
    for name, e in stances.items():
        if not e["pipeline"]["consistent"]:
            failures.append(f"{name}: analyze() and the staged pipeline disagree")
    result["checks"] = {"ok": not failures, "failures": failures, "worst_symdiff_rel": worst}
    result["targets"] = evaluate_targets(result)
    if args.profile:
        progress("profile ...")
        result["profile"] = profile_report(args)
    if not args.no_sweep:
        progress("sweep (benchmarks/sweep.py --quick) ...")
        from sweep import measure as measure_sweep  # benchmarks/sweep.py, beside this file

        result["sweep"] = measure_sweep(quick=True)
    result["wall_time_s"] = time.perf_counter() - t_start

    if args.json:
        print(json.dumps(result, indent=1, default=float))
    else:
        print(text_report(result, args))
        if args.profile:
            print(profile_text(result["profile"]))
        print(f"\n(wall time {result['wall_time_s']:.0f} s)")
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
