"""One option, one meaning: the simulation commands' defaults agree (docs/simulation.md)."""

from __future__ import annotations

import pytest

from impact_balance import cli
from impact_balance.cli._options import DEFAULT_CONTROLLER, TRIAL_JOINTS
from tests.helpers.cli import run_cli

#: The smallest command line of each trial command (its defaults are what is checked).
LINES = {
    "validate": ["validate", "palm_push_two_feet"],
    "push-test": ["push-test", "palm_push_two_feet"],
    "approach": ["approach", "palm_push_two_feet", "--reference", "0.8"],
}


def _defaults(line: list[str]):
    parser, _ = cli._parser()
    return parser.parse_args(line)


def test_the_controller_default_is_the_same_in_every_trial_command():
    controllers = {name: _defaults(line).controller for name, line in LINES.items()}
    assert controllers == dict.fromkeys(LINES, DEFAULT_CONTROLLER)
    assert DEFAULT_CONTROLLER == "id"


def test_rigid_impact_is_off_by_default_wherever_an_impact_is():
    for line in (LINES["validate"], LINES["approach"], ["simulate", "palm_push_two_feet"]):
        assert _defaults(line).rigid_impact is False
    assert not hasattr(_defaults(LINES["push-test"]), "rigid_impact")  # a push has no impact


def test_joints_words_mean_one_thing():
    # simulate: rigid = welded (its default); validate: servo (default) or stiff (stiff servos).
    assert _defaults(["simulate", "palm_push_two_feet"]).joints == "rigid"
    assert _defaults(LINES["validate"]).joints == "servo"
    stiff = _defaults([*LINES["validate"], "--joints", "stiff"])
    assert stiff.joints == "stiff" and TRIAL_JOINTS[stiff.joints] == "rigid"
    assert set(TRIAL_JOINTS) == {"servo", "stiff"}


def test_the_former_rigid_of_validate_is_read_as_stiff_with_a_deprecation_line(capsys):
    args = _defaults([*LINES["validate"], "--joints", "rigid"])
    assert args.joints == "stiff"
    err = capsys.readouterr().err
    assert "deprecated" in err and "--joints stiff" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("word", ["welded", "foo"])
def test_validate_refuses_other_joint_words(word, capsys):
    rc, out, err = run_cli(capsys, *LINES["validate"], "--joints", word)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "--joints" in err and word in err
