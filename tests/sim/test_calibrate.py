"""Calibrating the ZMP margin on synthetic push-test outputs: the margin, its interval, refusals."""

from __future__ import annotations

import hashlib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.exceptions import ScenarioError
from impact_balance.sim.studies.calibrate import calibrate, read_training
from impact_balance.sim.studies.scores import MARGIN_GRID, wilson
from tests.helpers.calibration import push_test_document, write_document

OMEGAS = (3.0, 3.3, 3.9)

# A push: its threshold margin in mm plus half a millimetre (never on a grid point, so that
# "safe at M" is the same whichever way it is computed), its stance and its outcome.
push_rows = st.lists(
    st.tuples(
        st.integers(-20, 80),
        st.sampled_from(range(len(OMEGAS))),
        st.booleans(),
        st.booleans(),
    ),
    min_size=1,
    max_size=40,
)


def _documents(rows):
    """One document per stance (omega), each push's raw margin omega (k + 0.5) mm."""
    by_stance = {}
    for k, s, fell, strict in rows:
        raw = OMEGAS[s] * (k + 0.5) * 1e-3
        by_stance.setdefault(s, []).append((raw, fell, strict))
    return [
        push_test_document(r, omega=OMEGAS[s], scenario=f"stance{s}")
        for s, r in sorted(by_stance.items())
    ]


def _brute(rows, target, strict):
    """The smallest grid margin (m) by counting, in integer millimetres: safe when k >= M mm."""
    for mm in range(61):
        safe = [(fell, fell or st_) for k, _, fell, st_ in rows if k >= mm]
        failed = sum(f[1] if strict else f[0] for f in safe)
        if safe and failed <= target * len(safe):
            return mm / 1000, failed, len(safe)
    return None, None, None


@settings(max_examples=60, deadline=None)
@given(push_rows, st.sampled_from([0.05, 0.1, 0.25]), st.booleans())
def test_the_smallest_margin_is_the_one_counting_finds(rows, target, strict):
    result = calibrate(_documents(rows), target=target, strict=strict)
    margin, failed, safe = _brute(rows, target, strict)
    assert result.zmp_margin == margin
    out = result.to_dict()
    if margin is None:
        assert out["fell_given_safe"] is None
        assert out["answer"].startswith("no margin reaches the target")
        return
    r = out["fell_given_safe"]
    assert (r["count"], r["of"]) == (failed, safe)
    assert r["ci95"] == wilson(failed, safe)  # the interval of scores.py
    # The standing pushes called safe at that margin, counted.
    stood = [k for k, _, fell, st_ in rows if not (fell or st_ if strict else fell)]
    called = sum(k >= round(1000 * margin) for k in stood)
    assert (out["safe_given_stood"]["count"], out["safe_given_stood"]["of"]) == (
        called,
        len(stood),
    )
    # Every smaller margin misses the target (or calls nothing safe).
    for point in out["curve"]:
        if point["zmp_margin"] < margin:
            rate = point["fell_given_safe"]["rate"]
            assert rate is None or rate > target


@settings(max_examples=40, deadline=None)
@given(push_rows, st.sampled_from([0.12, 0.3, 0.6]))
def test_the_upper_margin_is_where_the_upper_wilson_bound_reaches_its_target(rows, upper):
    result = calibrate(_documents(rows), upper_target=upper)
    expected = None
    for mm in range(61):
        safe = [fell or st_ for k, _, fell, st_ in rows if k >= mm]
        if safe and wilson(sum(safe), len(safe))[1] <= upper:
            expected = mm / 1000
            break
    assert result.upper_margin == expected


@settings(max_examples=40, deadline=None)
@given(push_rows, st.integers(0, 60), st.booleans())
def test_the_floor_bounds_the_answer_from_below(rows, floor_mm, from_files):
    documents = _documents(rows)
    if from_files:
        for d in documents:
            d["controller_margin"] = floor_mm / 1000
        result = calibrate(documents)
    else:
        result = calibrate(documents, floor=floor_mm / 1000)
    below = [(k, s, fell, st_) for k, s, fell, st_ in rows]
    unfloored, _, _ = _brute(below, 0.05, True)
    assert result.unfloored_margin == unfloored
    assert result.floor == floor_mm / 1000
    expected = None
    for mm in range(floor_mm, 61):
        safe = [fell or st_ for k, _, fell, st_ in rows if k >= mm]
        if safe and sum(safe) <= 0.05 * len(safe):
            expected = mm / 1000
            break
    assert result.zmp_margin == expected
    assert result.to_dict()["margin_floor"] == floor_mm / 1000


def test_without_a_recorded_controller_margin_there_is_no_floor():
    result = calibrate([push_test_document([(0.2, False, False)] * 3)])
    assert (result.floor, result.zmp_margin) == (0.0, 0.0)


@pytest.mark.parametrize("floor", [-0.001, 1.5, float("nan"), "ik", True])
def test_a_bad_floor_is_refused(floor):
    with pytest.raises(ScenarioError, match="floor"):
        calibrate([push_test_document([(0.2, False, False)])], floor=floor)


def test_the_wilson_interval_agrees_with_scipy():
    stats = pytest.importorskip("scipy.stats")
    rows = [(0.01 * k, k % 7 == 0, False) for k in range(1, 30)]
    result = calibrate([push_test_document(rows)], target=0.2)
    r = result.to_dict()["fell_given_safe"]
    ci = stats.binomtest(r["count"], r["of"]).proportion_ci(method="wilson")
    assert r["ci95"] == pytest.approx([ci.low, ci.high], abs=1e-9)


def test_the_raw_margin_is_recovered_from_older_files():
    rows = [(0.003 * k - 0.02, k % 3 == 0, k % 4 == 0) for k in range(40)]
    new = calibrate([push_test_document(rows)])
    old = calibrate([push_test_document(rows, raw_key=False)])
    assert new.zmp_margin == old.zmp_margin
    assert new.to_dict()["curve"] == old.to_dict()["curve"]


def test_aborted_trials_are_left_out():
    document = push_test_document([(0.1, False, False), (0.1, True, True)])
    document["pushes"][1]["outcome"] = "aborted"
    result = calibrate([document])
    assert result.to_dict()["pushes"] == 1
    assert result.zmp_margin == 0.0


def test_a_file_scored_with_the_reach_is_refused_by_name():
    # Its calls depend on the reach at the score's margin: a margin scan would ignore it.
    document = push_test_document([(0.1, False, False)])
    document["com_reach"] = {"azimuths_deg": [0, 90, 180, 270], "radii": [0.1] * 4, "height": 1}
    with pytest.raises(ScenarioError) as caught:
        calibrate([document])
    assert caught.value.field == "com_reach"


def test_files_are_pooled_and_hashed(tmp_path):
    a = write_document(tmp_path / "a.json", push_test_document([(0.1, False, False)] * 3))
    b = write_document(
        tmp_path / "b.json", push_test_document([(0.1, True, True)], scenario="other")
    )
    result = calibrate([a, b], target=0.3)
    out = result.to_dict()
    assert out["zmp_margin"] == 0.0 and out["fell_given_safe"]["of"] == 4
    assert [f["sha256"] for f in out["files"]] == [
        hashlib.sha256(p.read_bytes()).hexdigest() for p in (a, b)
    ]
    rates = {row["scenario"]: row["fell_given_safe"]["rate"] for row in out["per_file"]}
    assert rates == {"synthetic": 0.0, "other": 1.0}
    assert read_training(a).robot == "talos"


@pytest.mark.parametrize(
    "change, key",
    [
        ({"robot": "g1"}, "robot"),
        ({"controller": "ik"}, "controller"),
        ({"angular_momentum_damping_time": 0.3}, "criterion"),
    ],
)
def test_mixed_trials_are_refused_naming_the_files(tmp_path, change, key):
    rows = [(0.1, False, False)]
    a = write_document(tmp_path / "a.json", push_test_document(rows))
    b = write_document(tmp_path / "b.json", push_test_document(rows, **change))
    with pytest.raises(ScenarioError) as info:
        calibrate([a, b])
    assert info.value.field == key
    assert "a.json" in str(info.value) and "b.json" in str(info.value)


@pytest.mark.parametrize("from_robot", [True, False])
def test_gains_derived_from_the_robot_may_differ_between_stances(tmp_path, from_robot):
    """Derived gains follow each stance's CoM height: one controller, other numbers."""
    rows = [(0.1, False, False)]
    docs = []
    for name, gain in (("a", 2.0), ("b", 2.3)):
        doc = push_test_document(rows, scenario=name)
        doc["controller"] = {
            "name": "id",
            "gains": {"dcm_gain": gain},
            "gains_from_robot": from_robot,
        }
        docs.append(write_document(tmp_path / f"{name}.json", doc))
    if from_robot:
        assert calibrate(docs).to_dict()["fell_given_safe"]["of"] == 2
    else:
        with pytest.raises(ScenarioError) as info:
            calibrate(docs)
        assert info.value.field == "controller"


def test_unknown_criterion_settings_are_recorded_verbatim():
    document = push_test_document([(0.1, False, False)], angular_momentum_damping_time=0.3)
    out = calibrate([document, dict(document)]).to_dict()
    assert out["criterion"]["angular_momentum_damping_time"] == 0.3


@pytest.mark.parametrize(
    "document, field",
    [
        ({"pushes": "no"}, "pushes"),
        ({**push_test_document([]), "robot": None}, "robot"),
        ({**push_test_document([]), "omega": "x"}, "omega"),
        (
            {**push_test_document([]), "pushes": [{"fell": 1, "strict_fail": False}]},
            "pushes[0].com_velocity_margin",
        ),
    ],
)
def test_bad_documents_are_refused_naming_the_field(document, field):
    with pytest.raises(ScenarioError) as info:
        calibrate([document])
    assert info.value.field == field


@pytest.mark.parametrize("target", [0.0, 1.0, -0.1, float("nan")])
def test_a_target_outside_0_1_is_refused(target):
    with pytest.raises(ScenarioError, match="--target"):
        calibrate([push_test_document([(0.1, False, False)])], target=target)


def test_the_grid_is_the_margin_studys():
    result = calibrate([push_test_document([(0.1, False, False)])])
    assert result.grid == MARGIN_GRID
