"""``analyze --impact-model``: the default's output unchanged, held-stance's block and line the
analysis's own answer, the fallback reported, a bad value refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

from impact_balance import analyze, load_scenario
from impact_balance.analysis.held_stance import held_stance_max_contact_velocity
from tests.helpers.cli import run_cli, strict_json
from tests.helpers.held_stance import NOT_CONVERGING


@pytest.mark.parametrize("name", ["palm_push_two_feet", "jvrc1_kick_one_foot"])
def test_floating_is_the_default_output_byte_for_byte(capsys, name):
    _, plain, _ = run_cli(capsys, "analyze", name, "--json")
    rc, floating, _ = run_cli(capsys, "analyze", name, "--json", "--impact-model", "floating")
    assert rc == 0
    a, b = strict_json(plain), strict_json(floating)
    a.pop("timings_ms"), b.pop("timings_ms")
    assert a == b and "held_stance" not in b


@pytest.mark.parametrize(("name", "margin"), [("palm_push_two_feet", "0"), ("g1_two_feet", "0.01")])
def test_held_stance_block_is_the_analysis_answer(capsys, name, margin):
    rc, out, _ = run_cli(
        capsys, "analyze", name, "--json", "--impact-model", "held-stance", "--zmp-margin", margin
    )
    assert rc == 0
    doc = strict_json(out)
    expected = held_stance_max_contact_velocity(
        analyze(load_scenario(name).replace(zmp_margin=float(margin)))
    ).to_dict()
    got = doc.pop("held_stance")
    assert got.keys() == expected.keys()
    for key in ("status", "restitution", "converged", "fell_back", "binding_restitution"):
        assert got[key] == expected[key], key
    assert got["max_contact_velocity"] == pytest.approx(expected["max_contact_velocity"], abs=1e-12)
    np.testing.assert_allclose(got["jumps"], expected["jumps"], rtol=0, atol=1e-12)
    assert not got["fell_back"] and got["binding_restitution"] in got["restitution"]
    # The rest of the document is the floating one.
    _, plain, _ = run_cli(capsys, "analyze", name, "--json", "--zmp-margin", margin)
    base = strict_json(plain)
    base.pop("timings_ms"), doc.pop("timings_ms")
    assert doc == base


def test_the_text_report_gains_one_line(capsys):
    _, plain, _ = run_cli(capsys, "analyze", "palm_push_two_feet")
    rc, held, _ = run_cli(capsys, "analyze", "palm_push_two_feet", "--impact-model", "held-stance")
    assert rc == 0
    extra = held.splitlines()[len(plain.splitlines()) :]
    assert len(extra) == 1
    answer = held_stance_max_contact_velocity(analyze("palm_push_two_feet"))
    assert extra[0].startswith(
        f"held-stance max contact velocity {answer.max_contact_velocity:.3f} m/s"
    )
    assert f"binding restitution {answer.binding_restitution:g}" in extra[0]


def test_the_fallback_is_the_papers_answer_and_says_so(capsys):
    args = ("analyze", str(NOT_CONVERGING), "--impact-model", "held-stance", "--zmp-margin", "0.01")
    rc, out, _ = run_cli(capsys, *args, "--json")
    assert rc == 0
    doc = strict_json(out)
    held = doc["held_stance"]
    assert held["fell_back"] and not held["converged"] and held["binding_restitution"] is None
    assert held["max_contact_velocity"] == doc["impact"]["max_contact_velocity"]
    rc, text, _ = run_cli(capsys, *args)
    assert rc == 0 and "the fixed point was not reached" in text.splitlines()[-1]


@pytest.mark.parametrize("value", ["bogus", "held_stance", ""])
def test_a_bad_impact_model_is_one_line_naming_the_option(capsys, value):
    rc, out, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--impact-model", value)
    assert rc == 2 and out == "" and "Traceback" not in err
    assert err.count("\n") == 1
    assert f"--impact-model: invalid choice: {value!r}" in err


def test_with_tau_the_block_and_the_line_carry_the_angular_momentum(capsys):
    args = ("analyze", "palm_push_two_feet", "--impact-model", "held-stance")
    rc, out, _ = run_cli(capsys, *args, "--angular-momentum-damping-time", "0.1", "--json")
    assert rc == 0
    held = strict_json(out)["held_stance"]
    expected = held_stance_max_contact_velocity(
        analyze(load_scenario("palm_push_two_feet").replace(angular_momentum_damping_time=0.1))
    )
    term = held["angular_momentum"]
    assert term["damping_time"] == 0.1
    assert term["max_contact_velocity"] == pytest.approx(
        expected.angular_momentum.max_contact_velocity, abs=1e-12
    )
    assert term["max_contact_velocity"] < held["max_contact_velocity"]  # the term binds here
    np.testing.assert_allclose(
        term["angular_momentum"], expected.angular_momentum.angular_momentum, atol=1e-12
    )
    rc, text, _ = run_cli(capsys, *args, "--angular-momentum-damping-time", "0.1")
    assert rc == 0
    line = text.splitlines()[-1]
    assert line.endswith(
        f"; with the angular momentum it leaves (tau 0.1 s) {term['max_contact_velocity']:.3f} m/s"
    )
    # Off: no block, whatever the scenario would say.
    rc, out, _ = run_cli(capsys, *args, "--angular-momentum-damping-time", "off", "--json")
    assert rc == 0 and "angular_momentum" not in strict_json(out)["held_stance"]
