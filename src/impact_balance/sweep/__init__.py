"""Sweeps: the maximum contact velocity over many points of a scenario's keys and postures.

A sweep file (:mod:`.spec`) names a base scenario and axes; the plan (:mod:`.plan`) checks
them and numbers the points in chunks; an evaluator (:mod:`.evaluate`) turns a chunk into rows;
the runner (:mod:`.runner`) spreads chunks over processes or a Dask cluster and the store
(:mod:`.store`) writes each finished chunk as a Parquet part, so that a sweep resumes.
:mod:`.summary` and :mod:`.figures` read the results back.
"""

from impact_balance.sweep.evaluate import RESULT_COLUMNS, STATUSES, Evaluator, result_schema
from impact_balance.sweep.plan import Dimension, SweepPlan, make_plan, plan_sweep
from impact_balance.sweep.runner import RunReport, default_workers, run_sweep
from impact_balance.sweep.spec import (
    SweepSpec,
    bundled_sweeps,
    load_sweep_spec,
    sweep_path,
    sweep_spec_from_dict,
)
from impact_balance.sweep.store import ResultStore, read_manifest, read_results

__all__ = [
    "RESULT_COLUMNS",
    "STATUSES",
    "Dimension",
    "Evaluator",
    "ResultStore",
    "RunReport",
    "SweepPlan",
    "SweepSpec",
    "bundled_sweeps",
    "default_workers",
    "load_sweep_spec",
    "make_plan",
    "plan_sweep",
    "read_manifest",
    "read_results",
    "result_schema",
    "run_sweep",
    "sweep_path",
    "sweep_spec_from_dict",
]
