"""The calibration file: written, read back, refused when bad, applied to a scenario's margin."""

from __future__ import annotations

import pytest
import yaml

from impact_balance.exceptions import ScenarioError, UnknownKeyError
from impact_balance.scenario import load_scenario
from impact_balance.scenario.calibration import (
    CalibrationFile,
    apply_calibration,
    read_calibration,
    write_calibration,
)
from tests.helpers.calibration import calibration_mapping


def _write(tmp_path, mapping, name="c.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(mapping))
    return path


def test_a_written_file_reads_back_the_same(tmp_path):
    model = CalibrationFile.model_validate(calibration_mapping(zmp_margin=0.0123456789012345))
    path = tmp_path / "c.yaml"
    write_calibration(model, path)
    assert read_calibration(path) == model
    assert read_calibration(path).zmp_margin == 0.0123456789012345  # to the last digit


@pytest.mark.parametrize(
    "change, field",
    [
        ({"zmp_margin": -0.01}, "zmp_margin"),
        ({"zmp_margin": "1 cm"}, "zmp_margin"),
        ({"target": 1.5}, "target"),
        ({"outcome": "loose"}, "outcome"),
        ({"training": []}, "training"),
        ({"fell_given_safe": {"rate": 2.0, "ci95": None, "count": 1, "of": 1}}, "rate"),
    ],
)
def test_bad_fields_are_refused_naming_them(tmp_path, change, field):
    path = _write(tmp_path, {**calibration_mapping(), **change})
    with pytest.raises(ScenarioError) as info:
        read_calibration(path)
    assert field in info.value.field
    assert str(path) in str(info.value)


def test_an_unknown_key_is_refused(tmp_path):
    path = _write(tmp_path, {**calibration_mapping(), "zmp_margn": 0.02})
    with pytest.raises(UnknownKeyError, match="zmp_margn"):
        read_calibration(path)


@pytest.mark.parametrize("version", [2, None, "1"])
def test_another_version_is_refused(tmp_path, version):
    path = _write(tmp_path, {**calibration_mapping(), "version": version})
    with pytest.raises(ScenarioError, match="version"):
        read_calibration(path)


@pytest.mark.parametrize("text", ["robot: [talos", "- a list\n- of items\n", ""])
def test_not_a_calibration_is_refused(tmp_path, text):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        read_calibration(path)
    assert info.value.field == "--calibration"


def test_a_missing_file_or_a_folder_is_refused(tmp_path):
    with pytest.raises(ScenarioError, match="no such file"):
        read_calibration(tmp_path / "missing.yaml")
    with pytest.raises(ScenarioError, match="not a regular file"):
        read_calibration(tmp_path)


def test_applied_it_sets_the_zmp_margin_of_the_same_robot_only():
    scenario = load_scenario("palm_push_two_feet")
    calibration = CalibrationFile.model_validate(calibration_mapping(zmp_margin=0.021))
    applied = apply_calibration(scenario, calibration, "c.yaml")
    assert applied.zmp_margin == 0.021 and "zmp_margin" in applied.set_keys
    other = CalibrationFile.model_validate(calibration_mapping(robot="g1"))
    with pytest.raises(ScenarioError, match="calibrated for robot 'g1'") as info:
        apply_calibration(scenario, other, "c.yaml")
    assert info.value.field == "--calibration"
