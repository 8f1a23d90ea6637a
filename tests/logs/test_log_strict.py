"""check-log reads only what it can trust: an infinite value in any column it reads, a quaternion
off unit norm, a base or a joint beyond the scenario's bounds, time that does not strictly
increase: each one line naming the column and the row, exit 2 (it was silently normalised,
or changed the verdict, or gave ``ok: true`` for a log of duration 0)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance.cli import main
from impact_balance.exceptions import ScenarioError
from impact_balance.governor.governor import JOINT_LIMIT_TOLERANCE
from impact_balance.logs import check_log
from impact_balance.logs.check import QUATERNION_TOLERANCE
from tests.helpers.logs import SCENARIO, synthetic_log


@pytest.fixture(scope="module")
def clean():
    frame, _, scenario = synthetic_log(np.zeros(3), T=0.02, wiggle=0.01)
    frame = frame.copy()
    for axis in "xyz":  # a logged contact force (a foot's frame) and the ZMP
        frame[f"force_{scenario.contacts[0].frame}_{axis}"] = 400.0 if axis == "z" else 0.0
    frame["zmp_x"], frame["zmp_y"] = 0.0, 0.0
    return frame, scenario


def hostile(frame, column, row, value):
    out = frame.copy()
    out.loc[row, column] = value
    return out


def scaled_quaternion(frame, row, scale):
    out = frame.copy()
    for c in ("base_qx", "base_qy", "base_qz", "base_qw"):
        out.loc[row, c] = out.loc[row, c] * scale
    return out


def constant_time(frame):
    return frame.assign(time=0.0)


def repeated_time(frame):
    out = frame.copy()
    out.loc[6, "time"] = out.loc[5, "time"]
    return out


CASES = {
    "infinite force": (
        lambda f, foot: hostile(f, f"force_{foot}_z", 4, np.inf),
        "column force_{foot}_z, row 5",
        "not a finite number",
    ),
    "infinite zmp": (lambda f, foot: hostile(f, "zmp_x", 2, -np.inf), "column zmp_x, row 3", ""),
    "quaternion x 1e6": (
        lambda f, foot: scaled_quaternion(f, 3, 1e6),
        "base_qx..base_qw",
        "row 4",
    ),
    "base at 1e300 m": (
        lambda f, foot: hostile(f, "base_x", 1, 1e300),
        "column base_x, row 2",
        "must be in [-10000, 10000] m",
    ),
    "joint at 1e6 rad": (
        lambda f, foot: hostile(f, "q_arm_right_4_joint", 3, 1e6),
        "column q_arm_right_4_joint, row 4",
        "joint limits",
    ),
    "constant time": (lambda f, foot: constant_time(f), "column time, row 2", "strictly increase"),
    "repeated time": (lambda f, foot: repeated_time(f), "column time, row 7", "strictly increase"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_each_hostile_log_is_one_line_naming_column_and_row(clean, tmp_path, capsys, case):
    frame, scenario = clean
    make, needle, more = CASES[case]
    foot = scenario.contacts[0].frame
    needle = needle.format(foot=foot)
    bad = make(frame, foot)
    with pytest.raises(ScenarioError) as info:
        check_log(bad, scenario)
    assert needle in str(info.value) and more in str(info.value)
    path = tmp_path / "bad.csv"
    bad.to_csv(path, index=False)
    assert main(["check-log", str(path), "--scenario", SCENARIO]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err


def test_the_clean_log_passes(clean, tmp_path, capsys):
    frame, scenario = clean
    assert check_log(frame, scenario).samples.shape[0] == len(frame)
    path = tmp_path / "ok.csv"
    frame.to_csv(path, index=False)
    assert main(["check-log", str(path), "--scenario", SCENARIO, "--json"]) == 0
    capsys.readouterr()


def test_an_unmeasured_optional_value_is_still_allowed(clean):
    frame, scenario = clean
    check_log(hostile(frame, "zmp_x", 2, np.nan), scenario)  # an empty cell: not measured


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(scale=st.floats(0.5, 2.0), row=st.integers(0, 9))
def test_the_quaternion_rule(clean, scale, row):
    frame, scenario = clean
    bad = scaled_quaternion(frame, row, scale)
    if abs(scale - 1.0) > 1.01 * QUATERNION_TOLERANCE:
        with pytest.raises(ScenarioError, match=f"row {row + 1}: the base quaternion"):
            check_log(bad, scenario)
    elif abs(scale - 1.0) < 0.99 * QUATERNION_TOLERANCE:
        check_log(bad, scenario)  # normalised, as before


@settings(
    max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(excess=st.floats(0.0, 10.0), upper=st.booleans())
def test_the_joint_rule_is_the_governors(clean, excess, upper):
    frame, scenario = clean
    robot = scenario.load_robot()
    slot = robot.joint_slot("arm_left_1_joint")
    value = slot.upper + excess if upper else slot.lower - excess
    bad = hostile(frame, "q_arm_left_1_joint", 0, value)
    if excess > JOINT_LIMIT_TOLERANCE * 1.001:
        with pytest.raises(ScenarioError, match="column q_arm_left_1_joint, row 1"):
            check_log(bad, scenario)
    elif excess < JOINT_LIMIT_TOLERANCE * 0.999:
        try:
            check_log(bad, scenario)
        except ScenarioError as exc:
            assert "q_arm_left_1_joint" not in str(exc)
