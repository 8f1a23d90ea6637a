"""``--touch-contact`` (``validate``, ``approach``): the id controller's option, off by default."""

from __future__ import annotations

import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.cli.touch_contact import impact_trial_options
from impact_balance.exceptions import SimulationError
from impact_balance.sim.control.gains import InverseDynamicsGains
from tests.helpers.cli import assert_one_line_error, run_cli


@pytest.mark.parametrize("command", ["validate", "approach"])
def test_the_ik_controller_has_no_touch_contact(capsys, command):
    rc, _, err = run_cli(
        capsys,
        command,
        "palm_push_two_feet",
        "--controller",
        "ik",
        "--touch-contact",
        *(["--no-journal"] if command == "validate" else ["--reference", "0.8"]),
    )
    assert_one_line_error(rc, err, "--touch-contact", "id controller", "'ik'")


@pytest.mark.parametrize("touch", [False, True])
@pytest.mark.parametrize("rigid", [False, True])
def test_the_options_carry_the_flag_and_nothing_else(touch, rigid):
    options = impact_trial_options("id", rigid, touch)
    assert options.id_gains == InverseDynamicsGains(touch_contact=touch)
    assert options.rigid_impact is rigid
    assert options.controller == "id"


def test_the_default_is_off():
    assert InverseDynamicsGains().touch_contact is False
    with pytest.raises(SimulationError, match="--touch-contact"):
        impact_trial_options("ik", False, True)
    assert impact_trial_options("ik", False, False).id_gains == InverseDynamicsGains()
