"""``Governor(..., calibration=FILE)``: the calibrated ZMP margin, as analyze applies it."""

from __future__ import annotations

import pytest
import yaml

from impact_balance import analyze
from impact_balance.exceptions import ScenarioError
from impact_balance.governor import Governor
from impact_balance.scenario import load_scenario
from impact_balance.scenario.calibration import CalibrationFile
from tests.helpers.calibration import calibration_mapping


@pytest.mark.parametrize("as_file", [True, False])
def test_the_governor_uses_the_calibrated_margin(tmp_path, as_file):
    mapping = calibration_mapping(zmp_margin=0.017)
    path = tmp_path / "talos.yaml"
    path.write_text(yaml.safe_dump(mapping))
    calibration = path if as_file else CalibrationFile.model_validate(mapping)
    governor = Governor("palm_push_two_feet", calibration=calibration)
    assert governor.scenario.zmp_margin == 0.017
    assert governor.calibration is not None and governor.calibration.zmp_margin == 0.017
    scenario = load_scenario("palm_push_two_feet")
    limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    expected = analyze(scenario.replace(zmp_margin=0.017)).impact
    assert limit.max_contact_velocity == pytest.approx(expected.max_contact_velocity, abs=1e-9)
    assert expected.max_contact_velocity < analyze(scenario).impact.max_contact_velocity


def test_another_robots_calibration_is_refused(tmp_path):
    path = tmp_path / "g1.yaml"
    path.write_text(yaml.safe_dump(calibration_mapping(robot="g1")))
    with pytest.raises(ScenarioError, match="calibrated for robot 'g1'") as info:
        Governor("palm_push_two_feet", calibration=path)
    assert info.value.field == "calibration"
    assert Governor("palm_push_two_feet").calibration is None
