"""Log checker on synthetic logs generated with pinocchio, and its bad-input errors."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("pandas", reason="needs the logs extra (pandas)")
pytest.importorskip("pyarrow", reason="needs the logs or sweep extra (pyarrow)")

import impact_balance as ib
from impact_balance.cli import main
from impact_balance.exceptions import ScenarioError
from impact_balance.logs import check_log, read_log, write_log
from tests.helpers.logs import SCENARIO, synthetic_log


def test_com_velocity_matches_finite_differences_and_pinocchio():
    frame, states, scenario = synthetic_log(np.array([0.05, -0.02, 0.0]))
    check = check_log(frame, scenario)
    s = check.samples
    com = s[["com_x", "com_y", "com_z"]].to_numpy()
    comd = s[["comd_x", "comd_y", "comd_z"]].to_numpy()
    # Independent: central differences of the CoM positions.
    fd = (com[2:] - com[:-2]) / (2 / 500.0)
    assert np.abs(fd - comd[1:-1]).max() < 2e-4
    # Round trip through the world-axis base velocity columns.
    model = scenario.load_robot().model
    data = model.createData()
    q, v = states[37]
    pin.centerOfMass(model, data, q, v)
    assert np.allclose(comd[37], data.vcom[0], atol=1e-12)


@pytest.mark.parametrize("speed, inside", [(0.05, True), (1.5, False)])
def test_inside_agrees_with_the_analysis(speed, inside):
    """A rigid translation at `speed` along x: the checker's verdict is the analysis' at that CoM
    velocity."""
    frame, _, scenario = synthetic_log(np.array([speed, 0.0, 0.0]), T=0.05, wiggle=0.0)
    check = check_log(frame, scenario)
    reference = ib.analyze(scenario.model_copy(update={"com_velocity": (speed, 0.0)}))
    assert reference.com_velocity_inside is inside
    assert bool(check.samples["com_velocity_inside"].iloc[0]) is inside
    # The margin is the distance of the CoM velocity to the area's boundary (the area is a polygon
    # in m/s).
    area = reference.areas.com_velocity_area
    assert check.samples["com_velocity_margin"].iloc[0] == pytest.approx(
        area.margins(np.array([speed, 0.0]))[0], abs=1e-6
    )
    assert check.ok is inside
    if not inside:
        (v,) = check.violations
        assert v.kind == "com_velocity" and v.start == 0.0 and v.samples == len(frame)


def test_violation_times_and_zmp_column(tmp_path):
    frame, _, scenario = synthetic_log(np.array([0.0, 0.0, 0.0]), T=0.2, wiggle=0.0)
    area = ib.analyze(scenario).areas.zmp_area
    zmp = np.tile(area.centroid, (len(frame), 1))
    bad = (frame["time"] >= 0.05) & (frame["time"] < 0.1)
    zmp[bad.to_numpy()] = area.vertices.max(axis=0) + 0.03  # outside
    frame["zmp_x"], frame["zmp_y"] = zmp[:, 0], zmp[:, 1]
    path = write_log(frame, tmp_path / "log.csv")
    check = check_log(read_log(path), scenario)
    (v,) = check.violations
    assert (
        v.kind == "zmp"
        and v.start == pytest.approx(0.05)
        and v.end == pytest.approx(0.098)
        and v.worst_margin < 0
    )


def test_bad_logs_name_what_is_missing(tmp_path, capsys):
    frame, _, scenario = synthetic_log(np.zeros(3), T=0.01, wiggle=0.0)
    with pytest.raises(ScenarioError, match="q_leg_left_1_joint"):
        check_log(frame.drop(columns=["q_leg_left_1_joint"]), scenario)
    with pytest.raises(ScenarioError, match="not in robot 'talos': q_wrist_joint"):
        check_log(frame.assign(q_wrist_joint=0.0), scenario)
    path = write_log(frame.drop(columns=["base_qw"]).assign(base_qw=1.0), tmp_path / "ok.parquet")
    assert main(["check-log", str(path), "--scenario", SCENARIO, "--json"]) == 0
    capsys.readouterr()
    frame.drop(columns=["base_vz"]).to_csv(tmp_path / "bad.csv", index=False)
    assert main(["check-log", str(tmp_path / "bad.csv"), "--scenario", SCENARIO]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "base_vz" in err[0]
