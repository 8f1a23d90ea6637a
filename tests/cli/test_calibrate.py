"""``impact-balance calibrate`` and ``--calibration``: end to end, on synthetic and real trials."""

from __future__ import annotations

import json

import pytest
import yaml

from tests.helpers.calibration import calibration_mapping, push_test_document, write_document
from tests.helpers.cli import assert_one_line_error, run_cli, strict_json

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

# Raw CoM velocity margins (m/s) at omega 3.3: the falls sit inside 0 to 10 mm of margin.
ROWS = [(0.3 * 0.001 * k, k < 10 and k % 2 == 0, k == 13) for k in range(60)]


def _files(tmp_path, *documents):
    return [str(write_document(tmp_path / f"t{i}.json", d)) for i, d in enumerate(documents)]


def _analysis(capsys, *argv):
    rc, out, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--json", *argv)
    assert rc == 0, err
    doc = strict_json(out)
    doc.pop("timings_ms")
    return doc, err


def test_calibrate_writes_a_file_that_analyze_applies(tmp_path, capsys):
    from impact_balance.sim.studies.calibrate import calibrate

    files = _files(tmp_path, push_test_document(ROWS), push_test_document(ROWS[::2]))
    out_file = tmp_path / "talos.yaml"
    rc, out, err = run_cli(capsys, "calibrate", *files, "--out", str(out_file), "--json")
    assert rc == 0, err
    doc = strict_json(out)
    expected = calibrate(files).zmp_margin
    assert doc["zmp_margin"] == expected is not None and doc["out"] == str(out_file)
    assert doc["outcome"] == "strict" and len(doc["curve"]) == 61
    written = yaml.safe_load(out_file.read_text())
    assert written["zmp_margin"] == expected and written["robot"] == "talos"
    assert [t["file"] for t in written["training"]] == files

    calibrated, _ = _analysis(capsys, "--calibration", str(out_file))
    explicit, _ = _analysis(capsys, "--zmp-margin", repr(expected))
    used = calibrated.pop("calibration")
    assert used["zmp_margin"] == expected and used["applied"] and used["target"] == 0.05
    assert calibrated == explicit


def test_lenient_calibrates_on_the_falls_alone(tmp_path, capsys):
    files = _files(tmp_path, push_test_document(ROWS))
    _, out, _ = run_cli(capsys, "calibrate", *files, "--json", "--lenient")
    lenient = strict_json(out)
    _, out, _ = run_cli(capsys, "calibrate", *files, "--json")
    strict = strict_json(out)
    assert lenient["outcome"] == "lenient"
    assert lenient["zmp_margin"] <= strict["zmp_margin"]


def test_text_names_the_margin_and_each_file(tmp_path, capsys):
    files = _files(tmp_path, push_test_document(ROWS, scenario="ramp", body="pelvis"))
    rc, out, _ = run_cli(capsys, "calibrate", *files)
    assert rc == 0
    assert "ZMP margin" in out and "ramp (pelvis, 60 pushes)" in out


def test_no_margin_reaching_the_target_is_an_answer(tmp_path, capsys):
    files = _files(tmp_path, push_test_document([(0.5, True, True), (-0.1, False, False)]))
    out_file = tmp_path / "c.yaml"
    rc, out, err = run_cli(capsys, "calibrate", *files, "--json", "--out", str(out_file))
    assert rc == 0, err
    doc = strict_json(out)
    assert doc["zmp_margin"] is None and doc["out"] is None
    assert doc["answer"].startswith("no margin reaches the target")
    assert not out_file.exists()
    rc, out, _ = run_cli(capsys, "calibrate", *files)
    assert rc == 0 and "no margin reaches the target" in out


def test_mixed_robots_are_one_error_line_naming_the_files(tmp_path, capsys):
    files = _files(tmp_path, push_test_document(ROWS), push_test_document(ROWS, robot="g1"))
    rc, _, err = run_cli(capsys, "calibrate", *files)
    assert_one_line_error(rc, err, "t0.json", "t1.json", "robot")


@pytest.mark.parametrize("argv", [["--target", "0"], ["--upper-target", "1.5"]])
def test_a_bad_target_is_refused(tmp_path, capsys, argv):
    files = _files(tmp_path, push_test_document(ROWS))
    rc, _, err = run_cli(capsys, "calibrate", *files, *argv)
    assert_one_line_error(rc, err, argv[0])


def test_a_file_that_is_not_a_push_test_output_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"scenario": "x"}))
    rc, _, err = run_cli(capsys, "calibrate", str(bad))
    assert_one_line_error(rc, err, "bad.json", "pushes")
    bad.write_text("{not json")
    rc, _, err = run_cli(capsys, "calibrate", str(bad))
    assert_one_line_error(rc, err, "not strict JSON")


def test_another_robots_calibration_is_refused(tmp_path, capsys):
    path = tmp_path / "g1.yaml"
    path.write_text(yaml.safe_dump(calibration_mapping(robot="g1")))
    rc, _, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--calibration", str(path))
    assert_one_line_error(rc, err, "--calibration", "'g1'", "'talos'")


def test_a_bad_calibration_file_is_refused(tmp_path, capsys):
    path = tmp_path / "c.yaml"
    path.write_text("zmp_margin: [0.01")
    rc, _, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--calibration", str(path))
    assert_one_line_error(rc, err, "--calibration", "not valid YAML")


def test_an_explicit_zmp_margin_wins_and_says_so(tmp_path, capsys):
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(calibration_mapping(zmp_margin=0.017)))
    doc, err = _analysis(capsys, "--calibration", str(path), "--zmp-margin", "0.005")
    assert doc["zmp_margin"] == 0.005
    assert doc["calibration"]["applied"] is False
    assert doc["calibration"]["zmp_margin_in_use"] == 0.005
    assert "--zmp-margin 0.005 given" in err and "not used" in err


@pytest.mark.slow
def test_calibrate_on_a_real_push_test(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = ["palm_push_two_feet", "--directions", "2", "--relative", "0.5", "1.2"]
    rc, out, err = run_cli(capsys, "push-test", *argv, "--json", "--no-journal")
    assert rc == 0, err
    trials = strict_json(out)
    assert trials["robot"] == "talos"
    omega, margin = trials["omega"], trials["zmp_margin"]
    assert trials["finite_push"] is True  # the default counts the push's duration
    for push in trials["pushes"]:
        raw = push["predicted_com_velocity_margin"]
        assert raw - omega * margin == pytest.approx(push["finite_push_margin"], abs=1e-12)
        assert push["finite_push_margin"] < push["com_velocity_margin"]  # kappa > 1
    path = tmp_path / "trials.json"
    path.write_text(out)
    rc, out, err = run_cli(
        capsys, "calibrate", str(path), "--out", "talos.yaml", "--json", "--target", "0.5"
    )
    assert rc == 0, err
    doc = strict_json(out)
    # Counted independently: the smallest margin whose safe pushes fail at most half the time,
    # from the controller's own margin (the floor) up.
    assert doc["margin_floor"] == trials["controller_margin"] == 0.01
    expected = None
    for mm in range(10, 61):
        safe = [
            p for p in trials["pushes"] if p["predicted_com_velocity_margin"] >= omega * mm / 1000
        ]
        if safe and sum(p["strict_fail"] for p in safe) <= 0.5 * len(safe):
            expected = mm / 1000
            break
    assert doc["zmp_margin"] == expected
    if expected is not None:
        rc, out, err = run_cli(capsys, "push-test", *argv, "--json", "--calibration", "talos.yaml")
        assert rc == 0, err
        again = strict_json(out)
        assert again["zmp_margin"] == expected and again["calibration"]["applied"]


def test_the_floor_is_the_controllers_margin_unless_given(tmp_path, capsys, monkeypatch):
    from impact_balance.scenario.calibration import read_calibration

    monkeypatch.chdir(tmp_path)
    # Every push called safe at any margin stands: without a floor the answer is 0 mm.
    document = push_test_document([(0.2, False, False)] * 5, controller_margin=0.01)
    path = write_document(tmp_path / "t.json", document)
    rc, out, err = run_cli(capsys, "calibrate", str(path), "--json", "--out", "c.yaml")
    assert rc == 0, err
    doc = strict_json(out)
    assert (doc["zmp_margin"], doc["margin_floor"], doc["unfloored_margin"]) == (0.01, 0.01, 0.0)
    written = read_calibration("c.yaml")
    assert (written.zmp_margin, written.margin_floor, written.unfloored_margin) == (0.01, 0.01, 0.0)
    rc, out, err = run_cli(capsys, "calibrate", str(path), "--json", "--floor", "0")
    assert rc == 0, err
    assert strict_json(out)["zmp_margin"] == 0.0
    rc, out, err = run_cli(capsys, "calibrate", str(path), "--floor", "0.0125")
    assert rc == 0, err
    assert "ZMP margin 12.5 mm" in out and "without it: 0 mm" in out
    rc, out, err = run_cli(capsys, "calibrate", str(path), "--floor", "-1")
    assert rc == 2 and "--floor" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    "argv",
    [
        ["validate", "palm_push_two_feet"],
        ["push-test", "palm_push_two_feet", "--directions", "1"],
        ["approach", "palm_push_two_feet", "--reference", "0.5"],
        ["simulate", "palm_push_two_feet"],
    ],
)
def test_every_trial_command_reads_the_calibration_before_any_trial(tmp_path, capsys, argv):
    path = tmp_path / "g1.yaml"
    path.write_text(yaml.safe_dump(calibration_mapping(robot="g1")))
    rc, _, err = run_cli(capsys, *argv, "--calibration", str(path))
    assert_one_line_error(rc, err, "--calibration", "calibrated for robot 'g1'")


def test_the_file_records_the_realised_angular_momentum_removal(tmp_path, capsys, monkeypatch):
    from impact_balance.scenario.calibration import read_calibration

    monkeypatch.chdir(tmp_path)
    document = push_test_document([(0.2, False, False)] * 3 + [(0.2, True, True)])
    measured = [([0.5, 6.0, 0.1], [0.2, 3.0, 0.0])] * 3 + [([0.0, 6.0, 0.0], [0.0, -5.0, 0.0])]
    for push, (at_end, removed) in zip(document["pushes"], measured, strict=True):
        push["trial"] = {"angular_momentum_at_end": at_end, "angular_momentum_removed": removed}
    path = write_document(tmp_path / "t.json", document)
    argv = ["calibrate", str(path), "--target", "0.5"]
    rc, out, err = run_cli(capsys, *argv, "--json", "--out", "c.yaml")
    assert rc == 0, err
    removal = strict_json(out)["angular_momentum_removal"]
    # The three pushes that stood: pitch share 3/6 = 0.5; the one that failed is left out; roll
    # carries under a quarter of the momentum (0.5 of 6.02 N m s): not counted.
    assert removal["y"]["pushes"] == 3 and removal["y"]["share"] == 0.5
    assert removal["y"]["damping_time"] == pytest.approx((1 / 0.5 - 1) / 3.3, rel=1e-12)
    assert removal["x"] == {"pushes": 0, "share": None, "damping_time": None}
    written = read_calibration("c.yaml").angular_momentum_removal
    assert written is not None
    assert written["y"].model_dump() == removal["y"] and written["x"].model_dump() == removal["x"]
    rc, out, err = run_cli(capsys, *argv)
    assert "pitch tau 0.303 s (share 0.50, 3 pushes), roll not measured" not in out
    assert "roll not measured, pitch tau 0.303 s (share 0.50, 3 pushes)" in out
