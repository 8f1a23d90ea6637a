"""The held-out stances (studies/held_out/, docs/studies/held-out-protocol.md).

Only the criterion is evaluated here (no simulation): each file loads, can balance at rest, has a
finite maximum contact velocity and no warning; together they cover the robots and the
categories the protocol lists; none repeats a bundled scenario's contacts and impact.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import ModelRepairWarning
from impact_balance.scenario import load_scenario
from impact_balance.scenario.bundled import bundled_scenarios
from tests.helpers.extras import needs_extra

HELD_OUT = Path(__file__).resolve().parents[1] / "studies" / "held_out"
FILES = sorted(HELD_OUT.glob("*.yaml"))
#: What the set must cover together (issue 26, item 6).
REQUIRED = {
    "lateral impact",
    "backward impact",
    "hand impact",
    "foot impact",
    "torso push",
    "pelvis push",
    "slope",
}
FOOT_FRAMES = {"left_sole_link", "right_sole_link", "l_sole", "r_sole"}
HAND_FRAMES = {
    "gripper_left_base_link",
    "gripper_right_base_link",
    "left_rubber_hand",
    "right_rubber_hand",
    "l_wrist",
    "r_wrist",
    "l_hand",
    "r_hand",
}
#: A contact whose normal makes more than this with the vertical is on a slope (deg).
SLOPE_DEG = 5.0


def _header(path: Path, key: str) -> str:
    match = re.search(rf"^# {key}: (.+)$", path.read_text(), flags=re.MULTILINE)
    assert match, f"{path.name}: no '# {key}:' line in the header"
    return match.group(1)


def _covers(path: Path) -> set[str]:
    return {c.strip() for c in _header(path, "covers").split(",")}


def _signature(scenario: Any) -> tuple[Any, ...]:
    """The contact layout and the impact, as compared with the bundled scenarios."""
    impact = scenario.impact
    normal = np.asarray(impact.normal, dtype=float)
    return (
        scenario.robot,
        tuple(sorted(c.frame for c in scenario.contacts)),
        impact.frame,
        tuple(np.round(normal / np.linalg.norm(normal), 2)),
    )


def test_the_set_is_there() -> None:
    assert len(FILES) >= 6, [f.name for f in FILES]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_each_stance_is_well_posed(path: Path) -> None:
    a = analyze(str(path))
    d = a.to_dict()
    assert d["can_balance"] is True
    assert d["verdict"] == "balanced"
    assert d["warnings"] == []
    assert d["impact"] is not None
    v = d["impact"]["max_contact_velocity"]
    assert v is not None and math.isfinite(v) and v > 0.05, v
    assert d["impact"]["status"] == "ok"


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_declared_categories_match_the_data(path: Path) -> None:
    covers = _covers(path)
    assert covers <= REQUIRED, covers - REQUIRED
    d = analyze(str(path)).to_dict()
    normal = np.asarray(d["impact"]["normal"], dtype=float)
    normal /= np.linalg.norm(normal)
    # The normal points from the surface into the robot: a wall behind pushes along +x.
    assert ("backward impact" in covers) == (normal[0] > 0.7)
    assert ("lateral impact" in covers) == (abs(normal[1]) > 0.7)
    frame = d["impact"]["frame"]
    assert ("foot impact" in covers) == (frame in FOOT_FRAMES)
    assert ("hand impact" in covers) == (frame in HAND_FRAMES)
    tilts = [
        math.degrees(math.acos(min(1.0, c["normal"][2] / np.linalg.norm(c["normal"]))))
        for c in d["contacts"]
    ]
    assert ("slope" in covers) == (max(tilts) > SLOPE_DEG), tilts
    # Every stance is pushed at the torso and at the pelvis; the header names the bodies.
    assert {"torso push", "pelvis push"} <= covers
    bodies = _header(path, "robot")
    assert re.match(r"\w+; push bodies: torso \(default, \w+\) and pelvis \(--body \w+\)$", bodies)


def test_the_set_covers_three_robots_and_every_category() -> None:
    robots = {load_scenario(str(f)).robot for f in FILES}
    assert {"talos", "g1"} <= robots
    assert len(robots) >= 3, robots
    covered = set().union(*(_covers(f) for f in FILES))
    assert covered == REQUIRED, REQUIRED - covered


def test_no_held_out_stance_repeats_a_bundled_one() -> None:
    bundled = {}
    for name in bundled_scenarios():
        s = load_scenario(name)
        if s.impact is not None:
            bundled[_signature(s)] = name
    held = [_signature(load_scenario(str(f))) for f in FILES]
    for f, sig in zip(FILES, held, strict=True):
        assert sig not in bundled, (f.name, bundled.get(sig))
    # Nor do two held-out stances repeat each other.
    assert len(set(held)) == len(held)


@needs_extra("sim")
@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_the_simulation_model_builds_with_the_push_bodies(path: Path) -> None:
    """The MuJoCo model builds (no trial is run) and has the bodies the header pushes."""
    from impact_balance.sim import build_model
    from impact_balance.sim.trials.setup import push_body

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sim = build_model(str(path))
    # Only the documented repairs of Romeo's and iCub's inertias (docs/simulation.md).
    assert all(issubclass(w.category, ModelRepairWarning) for w in caught), caught
    torso, pelvis = re.findall(r"\((?:default, |--body )(\w+)\)", _header(path, "robot"))
    assert sim.model.body(push_body(sim, None)).name == torso
    assert push_body(sim, pelvis) == sim.root_body
