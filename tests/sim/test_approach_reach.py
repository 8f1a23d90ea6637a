"""``approach --com-reach``: the governor capped within the CoM's reach of the initial posture."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import impact_balance as ib
from impact_balance.analysis.reach import reach_answer
from impact_balance.balance.reach import ComReach
from impact_balance.cli import main
from impact_balance.scenario import load_scenario


@pytest.mark.parametrize("governor", ["zmp", "none"])
def test_the_reach_needs_the_com_governor(capsys, governor):
    argv = ["approach", "palm_push_two_feet", "--reference", "0.5", "--governor", governor]
    assert main([*argv, "--com-reach"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--com-reach" in err and governor in err


@pytest.mark.slow
def test_approach_com_reach_records_the_reach_and_caps_within_it(capsys):
    argv = ["approach", "palm_push_two_feet", "--reference", "0.8", "--rigid-impact"]
    assert main([*argv, "--com-reach", "--json"]) == 0
    out = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))
    block = out["com_reach"]
    assert len(block["radii"]) == 16 and block["height"] > 0
    # The cap at contact is the maximum within reach at the posture of the contact (close to the
    # stance's): the reach recorded, applied to analyze at the stance, independently.
    n = len(block["radii"])
    reach = ComReach(
        np.deg2rad(block["azimuths_deg"]),
        np.array(block["radii"]),
        block["height"],
        np.zeros((n, 1)),
    )
    scenario = load_scenario("palm_push_two_feet").replace(zmp_margin=out["zmp_margin"])
    within = reach_answer(ib.analyze(scenario), reach=reach).max_contact_velocity
    assert out["cap_at_contact"] == pytest.approx(within, rel=0.05)
    assert out["speed_at_contact"] <= 1.1 * out["cap_at_contact"]
