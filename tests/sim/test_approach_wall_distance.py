"""``approach`` refuses a wall closer than the approach needs: nothing would be tested (a wall at
1e-9 m was touched before the approach began and scored a governed success)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.cli import main
from impact_balance.exceptions import SimulationError
from impact_balance.sim.studies.wall import (
    MIN_WALL_DISTANCE,
    WallOptions,
    check_wall_distance,
    run_wall_trial,
)


@pytest.mark.parametrize(
    "argv, needle, least",
    [
        (["--reference", "0.5", "--wall-distance", "1e-9"], "--wall-distance = 1e-09", "0.02"),
        (["--reference", "0.5", "--wall-distance", "0.019"], "--wall-distance = 0.019", "0.02"),
        (["--reference", "3"], "--wall-distance = 0.15", "0.225"),  # 3 m/s needs 22.5 cm
        (
            ["--reference", "0.5", "--wall-distance-range", "0.001", "0.2"],
            "--wall-distance-range = 0.001",
            "0.02",
        ),
    ],
)
def test_a_wall_too_close_is_refused_before_any_trial(capsys, argv, needle, least):
    assert main(["approach", "palm_push_two_feet", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err
    assert f"at least {least} m" in err


def test_the_library_refuses_it_too():
    with pytest.raises(SimulationError, match="--wall-distance") as info:
        run_wall_trial(None, WallOptions(reference=0.5, wall_distance=1e-9))  # type: ignore[arg-type]
    assert info.value.field == "--wall-distance"


@given(
    distance=st.floats(1e-12, 1.0),
    reference=st.floats(1e-3, 5.0),
    acceleration=st.floats(1.0, 100.0),
)
def test_the_least_distance_is_the_ramp_or_the_minimum(distance, reference, acceleration):
    needed = max(MIN_WALL_DISTANCE, reference**2 / (2 * acceleration))
    if distance >= needed:
        assert check_wall_distance(distance, reference, acceleration) == distance
    else:
        with pytest.raises(SimulationError, match="the wall must be at least"):
            check_wall_distance(distance, reference, acceleration)
    for bad in (0.0, -0.1, 1.5, math.nan, math.inf):
        with pytest.raises(SimulationError, match=r"must be in \(0, 1\] m"):
            check_wall_distance(bad, reference, acceleration)
