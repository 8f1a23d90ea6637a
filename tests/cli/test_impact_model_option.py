"""``validate --impact-model``: its values, and a bad one refused in one line before any trial."""

from __future__ import annotations

import pytest

from tests.helpers.cli import run_cli


@pytest.mark.parametrize("value", ["bogus", "held_stance", ""])
def test_a_bad_impact_model_is_one_line_naming_the_option(capsys, value):
    rc, out, err = run_cli(capsys, "validate", "palm_push_two_feet", "--impact-model", value)
    assert rc == 2 and out == "" and "Traceback" not in err
    assert err.count("\n") == 1
    assert f"--impact-model: invalid choice: {value!r}" in err
    assert "'floating', 'held-stance'" in err


def test_the_help_names_both_impact_models(capsys):
    rc, out, _ = run_cli(capsys, "validate", "--help")
    assert rc == 0
    assert "--impact-model {floating,held-stance}" in out
