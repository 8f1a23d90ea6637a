"""The verdict of validate: the fall bracket over the prediction, on synthetic brackets."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.sim.studies.validate import fall_verdict

speeds = st.floats(0.01, 5.0, allow_nan=False)


def test_within_the_bracket():
    v = fall_verdict(0.5, 0.6, 0.55, 0.6)
    assert v["verdict"] == "within" and v["by"] is None
    assert v["fall_over_predicted"] == pytest.approx({"low": 0.5 / 0.55, "high": 0.6 / 0.55})
    assert v["text"] == "prediction within the bracket"


def test_optimistic_names_the_shortfall():
    v = fall_verdict(1.5, 1.59, 2.10, 1.59)  # the Go2 of issue 27: fell at 1.59 against 2.10
    assert v["verdict"] == "optimistic" and v["by"] == pytest.approx(1 - 1.59 / 2.10)
    assert "optimistic by 24 %" in v["text"]


def test_conservative_names_the_excess():
    v = fall_verdict(0.66, 0.7, 0.55, 0.7)
    assert v["verdict"] == "conservative" and v["by"] == pytest.approx(0.2)
    assert "conservative by 20 %" in v["text"]


def test_no_fall_is_inconclusive_and_names_the_fastest_speed():
    v = fall_verdict(4.0, None, 2.0, 5.53)
    assert v["verdict"] == "inconclusive" and v["fall_over_predicted"]["high"] is None
    assert v["fall_over_predicted"]["low"] == pytest.approx(2.0)
    assert "no fall up to 5.530 m/s" in v["text"]


def test_no_prediction_is_inconclusive():
    for p in (None, 0.0):
        v = fall_verdict(0.5, 0.6, p)
        assert v["verdict"] == "inconclusive" and v["fall_over_predicted"]["low"] is None


def test_no_stand_below_the_fall_gives_a_zero_low_end():
    v = fall_verdict(None, 0.3, 0.5, 0.3)
    assert v["fall_over_predicted"]["low"] == 0.0 and v["verdict"] == "optimistic"


@given(survived=speeds, gap=st.floats(0.0, 2.0), predicted=speeds)
def test_the_verdict_is_where_the_prediction_falls(survived, gap, predicted):
    fell = survived + gap
    v = fall_verdict(survived, fell, predicted, fell)
    expected = (
        "optimistic" if fell < predicted else "conservative" if survived > predicted else "within"
    )
    assert v["verdict"] == expected
    low, high = v["fall_over_predicted"]["low"], v["fall_over_predicted"]["high"]
    assert low <= high
    assert (low <= 1.0 <= high) == (expected == "within")
    if v["by"] is not None:
        assert v["by"] > 0
