"""The capture's premise per stance (the protocol's rule B), from the rigid impact searches.

The trials' own mean CoM velocity jump per unit of measured contact speed, ``j_m`` (1, the
horizontal CoM velocity jump in m/s per m/s), is rayed from rest against the stance's CoM
velocity area at ZMP margin 0: it reaches the area's edge at the speed ``s(j_m)`` (m/s). The
premise holds when ``s(j_m)`` is at most the strict failure (``B = strict / s(j_m) >= 1``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from impact_balance.analysis.analyze import analyze
from impact_balance.balance.reach import ray_extent
from impact_balance.geometry.polygon import Polygon
from impact_balance.scenario.load import load_scenario

__all__ = ["jump_reaches", "premise"]


def jump_reaches(area: Polygon, jump: np.ndarray) -> float:
    """The speed (m/s) at which ``speed * jump`` leaves ``area`` (inf if never): its ray."""
    return ray_extent(area, jump) / float(np.linalg.norm(jump))


def _mean_jump(document: dict[str, Any]) -> tuple[np.ndarray | None, int]:
    jumps = []
    for trial in document["trials"]:
        impact = (trial.get("trial") or {}).get("impact")
        speed = trial.get("approach_speed_measured")
        if impact is None or not speed:
            continue
        jumps.append(np.asarray(impact["com_velocity_jump"], dtype=float) / speed)
    return (np.mean(jumps, axis=0) if jumps else None), len(jumps)


def premise(run_dir: Path, set_dir: Path) -> dict[str, dict[str, Any]]:
    """B per stance of every ``val_<stance>_rigid.json`` whose scenario is in ``set_dir``.

    Args:
        run_dir: The run's output directory.
        set_dir: The set's stances (``<stance>.yaml``).

    Returns:
        Per stance: ``jump_reaches`` (s(j_m), m/s), ``strict`` (the strict failure, m/s, or
        None), ``B`` (None without a strict failure), ``premise`` (B >= 1) and ``trials``
        (the trials with a measured impact).

    Raises:
        FileNotFoundError: A stance's scenario is not in ``set_dir``.
    """
    out: dict[str, dict[str, Any]] = {}
    for path in sorted(run_dir.glob("val_*_rigid.json")):
        name = path.name[len("val_") : -len("_rigid.json")]
        scenario_path = set_dir / f"{name}.yaml"
        if not scenario_path.is_file():
            raise FileNotFoundError(f"set_dir: no stance {scenario_path}")
        document = json.loads(path.read_text())
        jump, trials = _mean_jump(document)
        if jump is None:
            continue
        scenario = load_scenario(scenario_path).replace(zmp_margin=0.0, com_velocity=(0.0, 0.0))
        area = analyze(scenario).areas.com_velocity_area
        reaches = jump_reaches(area, jump)
        strict = document["empirical"]["strict_failed"]
        out[name] = {
            "jump_reaches": reaches,
            "strict": strict,
            "B": strict / reaches if strict else None,
            "premise": strict is not None and reaches <= strict,
            "trials": trials,
        }
    return out
