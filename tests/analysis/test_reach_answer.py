"""``analyze --com-reach``: an analysis's answer within the CoM's reach."""

from __future__ import annotations

import json

import numpy as np
import pytest

from impact_balance import analyze, load_scenario
from impact_balance.analysis.reach import reach_answer
from impact_balance.balance.reach import ReachOptions, reach_speed_limit
from tests.helpers.cli import run_cli


@pytest.fixture(scope="module")
def wide():
    # A wide stance hit sideways, whose reach binds (Talos 0.36 m; the third held-out set's).
    from pathlib import Path

    path = Path(__file__).parents[2] / "studies" / "held_out_3" / "talos_wide_right_palm_side.yaml"
    return analyze(load_scenario(str(path)).replace(zmp_margin=0.01))


def test_the_answer_within_reach_is_at_most_the_default_and_reaches_a_vertex_limit(wide):
    answer = reach_answer(wide, ReachOptions(directions=8, bisections=5))
    impact = wide.impact
    assert answer.default_max_contact_velocity == impact.default.max_contact_velocity
    assert answer.max_contact_velocity <= answer.default_max_contact_velocity
    # at the answer, the binding post-impact vertex sits on its reach limit (or the default binds)
    area, omega = wide.areas.com_velocity_area, wide.areas.omega
    s = answer.max_contact_velocity
    velocities = wide.com_velocity[None, :2] + s * impact.model.com_jump_rates
    slack = [
        reach_speed_limit(area, omega, answer.reach, v) - np.linalg.norm(v) for v in velocities
    ]
    assert min(slack) >= -1e-9
    assert s < answer.default_max_contact_velocity  # the reach binds on this stance
    assert min(slack) == pytest.approx(0.0, abs=1e-9)
    assert answer.speed_limits.shape == answer.reach.radii.shape


@pytest.mark.slow
def test_analyze_com_reach_adds_one_key_and_one_line(capsys):
    rc, out, _ = run_cli(capsys, "analyze", "palm_push_two_feet", "--com-reach", "--json")
    assert rc == 0
    doc = json.loads(out)
    block = doc["com_reach"]
    assert len(block["radii"]) == 16 and len(block["speed_limits"]) == 16
    assert block["max_contact_velocity"] <= block["default_max_contact_velocity"]
    rc, out, _ = run_cli(capsys, "analyze", "palm_push_two_feet", "--com-reach")
    assert rc == 0 and "CoM reach at constant height" in out
