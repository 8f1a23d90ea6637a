"""``approach --impact-model held-stance``: the governor with the held-stance jumps of the
initial posture, recorded once; refused without the com governor or with another cap."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import impact_balance as ib
from impact_balance.analysis.held_stance import held_stance_max_contact_velocity
from impact_balance.cli import main
from impact_balance.scenario import load_scenario

ARGV = ["approach", "palm_push_two_feet", "--reference", "0.8"]


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--governor", "zmp"], "needs --governor com, not zmp"),
        (["--governor", "none"], "needs --governor com, not none"),
        (["--com-reach"], "not with --com-reach"),
        (["--contact-aware"], "not with --contact-aware"),
    ],
)
def test_held_stance_refuses_other_governors_and_caps(capsys, extra, needle):
    assert main([*ARGV, *extra, "--impact-model", "held-stance", "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert "--impact-model" in captured.err and needle in captured.err


def test_a_bad_impact_model_is_one_line(capsys):
    with pytest.raises(SystemExit) as info:
        main([*ARGV, "--impact-model", "held_stance"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "--impact-model: invalid choice: 'held_stance'" in err


def test_approach_held_stance_records_the_jumps_and_caps_with_them(capsys):
    assert main([*ARGV, "--rigid-impact", "--impact-model", "held-stance", "--json"]) == 0
    out = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))
    scenario = load_scenario("palm_push_two_feet").replace(zmp_margin=out["zmp_margin"])
    expected = held_stance_max_contact_velocity(ib.analyze(scenario))
    block = out["held_stance"]
    assert block["converged"] and not block["fell_back"]
    assert block["restitution"] == list(expected.restitution)
    np.testing.assert_allclose(block["jumps"], expected.jumps, rtol=0, atol=1e-9)
    # The cap at contact is the held-stance answer at the posture of the contact (close to the
    # stance's, the CoM nearly at rest), not the floating one.
    floating = ib.analyze(scenario).impact.max_contact_velocity
    assert out["cap_at_contact"] == pytest.approx(expected.max_contact_velocity, rel=0.05)
    assert abs(out["cap_at_contact"] - floating) > 0.02
    assert out["speed_at_contact"] <= 1.1 * out["cap_at_contact"]


def test_without_the_option_there_is_no_block(capsys):
    assert main([*ARGV, "--governor", "none", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "held_stance" not in out


def test_the_text_report_names_the_held_stance_jumps(capsys):
    assert main([*ARGV, "--rigid-impact", "--impact-model", "held-stance"]) == 0
    text = capsys.readouterr().out
    assert (
        "governed with the held-stance jumps of the scenario's posture (restitution 0 and 0.2)"
        in text
    )
