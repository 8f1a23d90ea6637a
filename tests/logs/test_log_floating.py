"""check-log on a log with no loaded contact (simulate --joints rigid: floating, gravity off)."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")
pytest.importorskip("pyarrow", reason="needs the logs or sweep extra (pyarrow)")

from impact_balance.cli import main
from impact_balance.logs import check_log, read_log

#: The log comes from a simulation (simulate --joints rigid).
pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def rigid_log(tmp_path_factory):
    folder = tmp_path_factory.mktemp("floating")
    path = folder / "rigid.parquet"
    assert (
        main(
            [
                "simulate",
                "palm_push_two_feet",
                "--joints",
                "rigid",
                "--speed",
                "0.3",
                "--duration",
                "0.05",
                "--log",
                str(path),
                "--json",
            ]
        )
        == 0
    )
    return path


def test_a_floating_log_says_so_and_what_it_shows(rigid_log, capsys):
    capsys.readouterr()
    assert (
        main(
            [
                "simulate",
                "palm_push_two_feet",
                "--joints",
                "rigid",
                "--speed",
                "0.3",
                "--duration",
                "0.05",
                "--json",
            ]
        )
        == 0
    )
    measured = json.loads(capsys.readouterr().out)
    check = check_log(read_log(rigid_log), "palm_push_two_feet")
    assert check.floating and check.loaded_samples == 0
    assert not check.gravity_seen and abs(check.com_vertical_acceleration) < 0.5
    # Independent: no gravity and no contact, so the CoM velocity only changes at the impact:
    # the log's change is the jump simulate measured.
    np.testing.assert_allclose(
        check.com_velocity_change[:2], measured["com_velocity_jump_measured"], atol=2e-3
    )
    assert main(["check-log", str(rigid_log), "--scenario", "palm_push_two_feet", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (
        doc["floating"] is True and doc["gravity_seen"] is False and "gravity is off" in doc["note"]
    )
    assert main(["check-log", str(rigid_log), "--scenario", "palm_push_two_feet"]) == 0
    text = capsys.readouterr().out
    assert (
        "no contact is loaded" in text and "-inf" not in text and "CoM velocity changed by" in text
    )


def test_a_standing_log_is_not_floating(tmp_path, capsys):
    path = tmp_path / "servo.parquet"
    assert (
        main(
            [
                "simulate",
                "palm_push_two_feet",
                "--joints",
                "servo",
                "--speed",
                "0.3",
                "--duration",
                "0.05",
                "--log",
                str(path),
            ]
        )
        == 0
    )
    check = check_log(read_log(path), "palm_push_two_feet")
    assert not check.floating and check.loaded_samples == len(check.samples) and check.note is None
