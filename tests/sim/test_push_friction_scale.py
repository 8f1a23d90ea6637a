"""``push-test --friction-scale``: the same pushes and trials, scaled predictions."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.analysis.analyze import contact_model_areas
from impact_balance.scenario import load_scenario
from impact_balance.sim.studies.push import push_test
from impact_balance.sim.trials.setup import BalanceTrialOptions


def test_the_grid_and_trials_stay_and_the_prediction_uses_the_scaled_areas():
    scenario = load_scenario("talos_three_contacts")
    options = BalanceTrialOptions(controller="id")
    runs = [
        push_test(s, 1, None, 0.05, None, options=options, relative=[0.9])
        for s in (scenario, scenario.replace(friction_scale=0.65))
    ]
    full, scaled = (r.outcomes[0] for r in runs)
    assert scaled.push.magnitude == full.push.magnitude  # the grid: the contacts' own friction
    assert scaled.summary["outcome"] == full.summary["outcome"]  # the controller ignores it
    analysis = runs[0].setup.analysis
    areas = contact_model_areas(analysis.scenario, analysis.stance, 0.65)
    velocity = np.asarray(full.prediction.com_velocity)  # the trial's start at rest included
    expected = float(areas.com_velocity_area.margins(velocity[None, :])[0])
    assert scaled.prediction.com_velocity_margin == pytest.approx(expected, abs=1e-12)
    assert scaled.prediction.com_velocity_margin < full.prediction.com_velocity_margin
