"""``--friction-scale``: on ``analyze`` and the simulation commands, one line on a bad value."""

from __future__ import annotations

import pytest

from impact_balance import analyze
from impact_balance.scenario import load_scenario
from tests.helpers.cli import assert_one_line_error, run_cli, strict_json
from tests.helpers.extras import needs_extra


@pytest.mark.parametrize("bad", ["0", "1.5", "nan", "-0.2", "abc", "inf"])
@pytest.mark.parametrize("command", ["analyze", "push-test", "validate", "approach"])
def test_a_bad_value_is_one_line_naming_the_option_and_value(capsys, command, bad):
    rc, _, err = run_cli(capsys, command, "talos_three_contacts", "--friction-scale", bad)
    assert_one_line_error(rc, err, "--friction-scale", bad)


def test_controller_is_refused_by_analyze(capsys):
    rc, _, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--friction-scale", "controller")
    assert_one_line_error(rc, err, "--friction-scale", "controller")


@needs_extra("sim")
def test_controller_needs_the_id_controller(capsys):
    rc, _, err = run_cli(
        capsys,
        "push-test",
        "palm_push_two_feet",
        "--controller",
        "ik",
        "--friction-scale",
        "controller",
        "--no-journal",
    )
    assert_one_line_error(rc, err, "--friction-scale", "controller", "id controller")


def test_analyze_json_with_the_option_is_the_librarys(capsys):
    rc, out, _ = run_cli(
        capsys, "analyze", "talos_three_contacts", "--json", "--friction-scale", "0.65"
    )
    assert rc == 0
    doc = strict_json(out)
    expected = analyze(load_scenario("talos_three_contacts").replace(friction_scale=0.65))
    assert doc["friction_scale"] == 0.65
    assert doc["zmp_area"]["area"] == expected.areas.zmp_area.area
    assert doc["impact"]["max_contact_velocity"] == expected.impact.max_contact_velocity
    rc, out, _ = run_cli(capsys, "analyze", "talos_three_contacts", "--json")
    plain = strict_json(out)
    assert "friction_scale" not in plain
    assert plain["zmp_area"]["area"] > doc["zmp_area"]["area"]
