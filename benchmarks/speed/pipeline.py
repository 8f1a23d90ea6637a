"""The whole pipeline from a configuration to the answer, stage by stage and ``analyze`` end to
end (YAML loading excluded), and the maximum contact velocity alone given the area."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import impact_balance as ib
from benchmarks.speed.compat import wrench_polytope
from benchmarks.speed.timing import Case, measure, stats

__all__ = ["PIPELINE_STAGES", "bench_max_velocity", "bench_pipeline", "pipeline_cases"]

PIPELINE_STAGES = (
    "stance",
    "constraints",
    "areas",
    "impact_model",
    "max_velocity",
    "zmp_max_velocity",
)


def pipeline_cases(sc: ib.Scenario) -> tuple[dict[str, Case], Any, Any, Any]:
    """The stages and ``analyze`` of ``sc`` as timed cases, with ``(stance, areas, model)``."""
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
        cases["max_velocity"] = Case(
            lambda: ib.max_contact_velocity(areas.com_velocity_area, model, sc.com_velocity)
        )
        cases["zmp_max_velocity"] = Case(
            lambda: ib.zmp_max_contact_velocity(
                areas.zmp_area, model, stance.com, sc.plane_height, sc.gravity, cfg.duration
            )
        )
    cases["analyze"] = Case(lambda: ib.analyze(sc))
    return cases, stance, areas, model


def bench_pipeline(sc: ib.Scenario, args) -> dict[str, Any]:
    cases, _stance, areas, model = pipeline_cases(sc)
    times, _ = measure(cases, args.repeat, args.warmup)
    out: dict[str, Any] = {k: stats(v) for k, v in times.items()}
    out["sum_of_stages"] = {
        "median": float(sum(out[k]["median"] for k in PIPELINE_STAGES if k in out))
    }
    # Sanity: analyze() and the staged pipeline give the same answer.
    a = ib.analyze(sc)
    out["consistent"] = bool(
        np.allclose(
            a.areas.com_velocity_area.vertices, areas.com_velocity_area.vertices, atol=1e-12
        )
    )
    if model is not None:
        staged = ib.max_contact_velocity(
            areas.com_velocity_area, model, sc.com_velocity
        ).max_contact_velocity
        out["consistent"] &= bool(
            a.impact.max_contact_velocity == staged
            or (math.isinf(staged) and math.isinf(a.impact.max_contact_velocity))
        )
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
            lambda: ib.zmp_max_contact_velocity(
                areas.zmp_area, model, stance.com, sc.plane_height, sc.gravity, sc.impact.duration
            )
        ),
    }
    times, _ = measure(cases, args.repeat_cheap, max(args.warmup, 10))
    return {k: stats(v) for k, v in times.items()} | {"area_edges": len(vel.vertices)}
