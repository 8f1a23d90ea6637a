"""The CoM-velocity-area projection: ours (the compiled walk) against ``pypoman`` (Bretl) and
against our own LP-per-edge Bretl path (HiGHS), on the same polytope, with the answer checked
at every repetition."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import impact_balance as ib
from benchmarks.speed.compat import force_box_and_tolerance
from benchmarks.speed.polygons import compare
from benchmarks.speed.timing import Case, measure, stats
from impact_balance.projection import project_polytope

try:  # pypoman is a test extra of the project
    import pypoman
except ImportError:  # pragma: no cover
    pypoman = None

__all__ = ["bench_projection", "check_projection", "projection_cases", "pypoman"]

FORCE_BOX, FORCE_TOLERANCE = force_box_and_tolerance()


def projection_cases(poly: ib.WrenchPolytope, scale: float, seed: int) -> dict[str, Case]:
    """Both projections of ``poly`` onto the resultant horizontal force (units of m g).

    Ours projects ``poly.projection_data()`` (as areas_from_polytope does), pypoman the same
    set in the original variables; pypoman projects onto ``scale * F`` (its stopping and merging
    tolerances are absolute) and clips unbounded directions with the same box as ours.
    """
    A, b, C, d, F = poly.projection_data()  # what areas_from_polytope projects
    # pypoman gets the polytope in the original variables (the same set, an independent
    # formulation: its absolute tolerances would not suit the friction-normalised columns).
    w = poly.weight
    A0, b0, C0, d0, E = poly.A, poly.b / w, poly.C, poly.d / w, scale * poly.F
    f = np.zeros(2)

    def ours():
        return project_polytope(A, b, C, d, F, tol=FORCE_TOLERANCE, box=FORCE_BOX)

    def ours_bretl():
        return project_polytope(
            A, b, C, d, F, tol=FORCE_TOLERANCE, box=FORCE_BOX, method="bretl"
        ).polygon.vertices

    def theirs():
        try:
            vertices = pypoman.project_polytope(
                proj=(E, f),
                ineq=(A0, b0),
                eq=(C0, d0),
                method="bretl",
                max_radius=scale * FORCE_BOX,
            )
            return np.array(vertices) / scale
        except Exception as exc:
            return exc

    def reseed(i: int) -> None:  # pypoman's first ray is random (numpy's global RNG)
        np.random.seed((seed + i) % 2**32)  # noqa: NPY002 (pypoman draws from the global RNG)

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
        "method": ours[0].method,
        "pivots": ours[0].pivots,
        "n_lp": ours[0].n_lp,
        "n_vertices": len(ref),
        "bounded": bool(ours[0].polygon.bounded),
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
            area_rel_diff=float(
                ad[np.argmax(np.abs(ad))]
            ),  # worst over repeats, signed (pypoman - ours)
            symdiff_rel=float(sd.max()),
            symdiff_rel_median=float(np.median(sd)),
            pypoman_n_vertices=int(np.median(nverts)),
        )
    return out


def bench_projection(poly, args) -> dict[str, Any]:
    times, results = measure(
        projection_cases(poly, args.pypoman_scale, args.seed), args.repeat, args.warmup
    )
    entry: dict[str, Any] = {
        "n_vars": int(poly.A.shape[1]),
        "n_ineq": int(poly.A.shape[0]),
        "n_eq": int(poly.C.shape[0]),
        "project_us": stats(times["ours"]),
    }
    entry.update(check_projection(results))
    entry["bretl_highs_us"] = stats(times["bretl_highs"])
    entry["ratio_vs_bretl_highs"] = (
        entry["bretl_highs_us"]["median"] / entry["project_us"]["median"]
    )
    if "pypoman" in times:
        entry["pypoman_us"] = stats(times["pypoman"])
        entry["ratio_vs_pypoman"] = entry["pypoman_us"]["median"] / entry["project_us"]["median"]
        entry["match"] = (
            not entry["pypoman_errors"]
            and entry.get("symdiff_rel", math.inf) <= args.tol
            and entry["ours_deterministic"]
            and entry["bretl_highs_symdiff_rel"] <= args.tol
        )
    return entry
