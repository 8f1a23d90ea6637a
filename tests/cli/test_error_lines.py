"""Every error of a command is one line whatever raised it, with the right exit
status (2 bad input, 1 machine failure), no traceback, and no output folder created before the
inputs are known good; numbers limited to what the code can do; logs bounded and strict.

Each hostile input is driven through the command line (in process where that
sees the same thing, in a real process for streams, signals and ``--debug``), beside a control
that is accepted.
"""

from __future__ import annotations

import errno
import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from impact_balance import cli
from impact_balance.exceptions import (
    MESSAGE_CHARS,
    EnvironmentFailure,
    ImpactBalanceError,
    ScenarioError,
    SweepError,
)
from impact_balance.exit_status import describe_error
from impact_balance.ranges import MAX_SWEEP_POINTS
from impact_balance.scenario import scenario_from_dict
from impact_balance.scenario.reader import MAX_LOG_ROWS, parse_yaml
from tests.helpers.cli import SRC, run_cli, run_process
from tests.helpers.extras import needs_extra

UNWRITABLE = "/proc/forbidden"  # no folder can be made there, even by root


def error_line(err: str) -> str:
    """The one error line of stderr (the kernel's first-run notice aside)."""
    lines = [ln for ln in err.splitlines() if "compiling the projection kernel" not in ln]
    assert len(lines) == 1, err[-2000:]
    assert "Traceback" not in err
    assert ": error: " in lines[0] and len(lines[0]) <= 60 + MESSAGE_CHARS, lines[0]
    return lines[0]


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    """Run in an empty folder; yields a function listing what a command left there."""
    monkeypatch.chdir(tmp_path)
    return lambda: sorted(p.name for p in tmp_path.iterdir())


# -- YAML the reader refused with a traceback -----------------------------------------------------
@pytest.mark.parametrize(
    "bad, what",
    [
        ("\x07", "control character 0x07"),
        ("a\x00b", "NUL byte"),
        ("\x1b[31m", "control character 0x1b"),
    ],
)
def test_control_characters_and_nul_bytes_are_one_line(tmp_path, capsys, bad, what):
    path = tmp_path / "s.yaml"
    path.write_text(f"extends: palm_push_two_feet\nplane_height: 0.0\nname: x{bad}\n")
    rc, out, err = run_cli(capsys, "analyze", str(path))
    assert rc == 2 and out == ""
    line = error_line(err)
    assert what in line and "line 3" in line and "s.yaml" in line
    # control: the same file without the character
    path.write_text("extends: palm_push_two_feet\nname: x\n")
    assert run_cli(capsys, "analyze", str(path), "--json")[0] == 0


@needs_extra("sweep", "sim")
def test_control_character_in_a_sweep_file_and_simulate(tmp_path, capsys, in_tmp):
    sweep = tmp_path / "s.yaml"
    sweep.write_text(
        "base: palm_push_two_feet\naxes:\n  - path: impact.friction\n    values: [0.1\x07]\n"
    )
    rc, _, err = run_cli(capsys, "sweep", str(sweep), "--out", "o")
    assert rc == 2 and "control character" in error_line(err) and in_tmp() == ["s.yaml"]
    scenario = tmp_path / "sc.yaml"
    scenario.write_text("extends: palm_push_two_feet\nname: \x00\n")
    rc, _, err = run_cli(capsys, "simulate", str(scenario), "--speed", "0.1")
    assert rc == 2 and "NUL byte" in error_line(err)


def test_gui_shows_a_reader_error_as_a_reason_not_internal_error(tmp_path):
    from impact_balance.gui.session import Session

    session = Session(workspace=tmp_path)
    assert not session.upload("bad.yaml", b"extends: palm_push_two_feet\nname: \x07\n")
    assert "control character" in session.message and "internal error" not in session.message


def test_yaml_1_2_floats_are_numbers_and_quoted_numbers_are_not():
    assert parse_yaml("a: 5e-05\nb: 1E3\nc: '0.7'\nd: e5\n") == {
        "a": 5e-05,
        "b": 1000.0,
        "c": "0.7",
        "d": "e5",
    }


# -- strict types -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "value, reason", [(True, "not a boolean"), ("0.7", "not text"), (b"0.7", "not text")]
)
def test_a_bool_or_a_string_is_not_a_number(value, reason):
    raw = {
        "robot": "talos",
        "contacts": [{"frame": "left_sole_link", "friction": value, "size": [0.2, 0.1]}],
    }
    with pytest.raises(ScenarioError, match=reason) as info:
        scenario_from_dict(raw)
    assert info.value.field == "contacts[0].friction"
    raw["contacts"][0]["friction"] = 1  # control: an int is a number
    assert scenario_from_dict(raw).contacts[0].friction == 1.0


def test_a_number_is_not_a_boolean():
    raw = {
        "robot": "talos",
        "contacts": [{"frame": "left_sole_link", "friction": 0.7, "size": [0.2, 0.1]}],
        "torque_limits": 1,
    }
    with pytest.raises(ScenarioError, match="true or false"):
        scenario_from_dict(raw)


# -- outputs: checked before anything runs, no folder left -----------------------------------------
def test_unwritable_plots_folder_is_one_line_exit_1_before_the_analysis(
    capsys, in_tmp, monkeypatch
):
    import impact_balance.analysis.analyze as analysis

    monkeypatch.setattr(
        analysis, "analyze", lambda *a, **k: pytest.fail("analyzed before the output was checked")
    )
    rc, out, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--plots", UNWRITABLE)
    assert rc == 1 and out == ""
    assert "--plots" in error_line(err) and "/proc" in err
    assert in_tmp() == []


def test_output_folder_that_is_a_file_is_bad_input(capsys, in_tmp):
    Path("taken").write_text("x")
    for argv in (
        ["analyze", "palm_push_two_feet", "--plots", "taken"],
        ["analyze", "palm_push_two_feet", "--plots", "taken/sub"],
        [
            "phase-portrait",
            "--com-height",
            "0.8",
            "--zmp-range",
            "-0.1",
            "0.1",
            "--plot",
            "taken/p.png",
        ],
    ):
        rc, _out, err = run_cli(capsys, *argv)
        assert rc == 2 and "taken" in error_line(err)
    assert in_tmp() == ["taken"]


@pytest.mark.parametrize("command", ["simulate", "validate", "push-test"])
@pytest.mark.parametrize(
    "option, value, status",
    [("--plots", UNWRITABLE, 1), ("--log", "/proc/forbidden/log.csv", 1), ("--log", "log.txt", 2)],
)
def test_simulation_outputs_are_checked_before_simulating(
    capsys, in_tmp, monkeypatch, command, option, value, status
):
    import impact_balance.scenario as scenario

    monkeypatch.setattr(
        scenario,
        "load_scenario",
        lambda *a, **k: pytest.fail("loaded before the outputs were checked"),
    )
    rc, out, err = run_cli(capsys, command, "palm_push_two_feet", option, value)
    assert rc == status and out == ""
    assert option in error_line(err)
    assert in_tmp() == []


def test_full_and_closed_stdout_are_one_line_exit_1(tmp_path):
    with open("/dev/full", "w") as full:
        proc = run_process("analyze", "palm_push_two_feet", "--json", stdout=full)
    assert proc.returncode == 1
    assert (
        error_line(proc.stderr)
        == "impact-balance: error: standard output: cannot write the output: "
        "No space left on device"
    )
    proc = subprocess.run(
        f"{sys.executable} -m impact_balance scenarios >&-",
        shell=True,
        env={**os.environ, "PYTHONPATH": SRC},
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
    )
    assert (
        proc.returncode == 1
        and "standard output" in error_line(proc.stderr)
        and "closed" in proc.stderr
    )


@needs_extra("plots", "logs", "sim", "sweep", "gui")
def test_every_command_reports_a_failing_stdout_in_one_line(capsys, monkeypatch):
    """The rule is in ``main``, not in the commands: a command added later gets it too."""

    class Full(io.StringIO):
        def write(self, text):
            raise OSError(errno.ENOSPC, "No space left on device")

    _, owners = cli._parser()
    argv = {
        "analyze": ["s"],
        "frames": ["talos"],
        "simulate": ["s"],
        "validate": ["s"],
        "push-test": ["s"],
        "calibrate": ["t.json"],
        "check-log": ["l", "--scenario", "s"],
        "phase-portrait": ["--com-height", "1", "--zmp-range", "0", "1"],
        "pose": ["s", "--place", "f", "0", "0", "1", "--out", "o.yaml"],
        "approach": ["s", "--reference", "0.5"],
    }
    assert set(cli.COMMANDS) == set(owners.values())
    for name, module in owners.items():
        monkeypatch.setattr(module, "run", lambda args: print("x" * 100_000) or 0)
        monkeypatch.setattr(sys, "stdout", Full())
        rc = cli.main([name, *argv.get(name, [])])
        monkeypatch.undo()
        err = capsys.readouterr().err
        assert rc == 1, (name, err)
        assert "standard output: cannot write the output" in error_line(err), name


@pytest.mark.slow
def test_debug_flag_and_environment_variable_show_the_traceback(tmp_path):
    for argv, env in (
        (["analyze", "nope.yaml", "--debug"], {}),
        (["--debug", "analyze", "nope.yaml"], {}),
        (["analyze", "nope.yaml"], {"IMPACT_BALANCE_DEBUG": "1"}),
    ):
        proc = run_process(*argv, cwd=tmp_path, env=env)
        assert (
            proc.returncode == 2 and "Traceback" in proc.stderr and "ScenarioError" in proc.stderr
        )
        assert (
            proc.stderr.rstrip()
            .splitlines()[-1]
            .startswith("impact-balance: error: scenario = 'nope.yaml'")
        )
    proc = run_process("analyze", "nope.yaml", cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_the_error_rule_classifies_what_others_raise():
    import yaml as pyyaml

    assert describe_error(FileNotFoundError(2, "No such file or directory", "/x/y")) == (
        "/x/y: No such file or directory",
        1,
    )
    assert describe_error(MemoryError())[1] == 1
    assert describe_error(ModuleNotFoundError("No module named 'mujoco'", name="mujoco"))[
        0
    ].startswith("cannot import mujoco")
    assert describe_error(pyyaml.YAMLError("bad"))[1] == 2
    line, status = describe_error(ZeroDivisionError("division by zero"))
    assert (
        status == 1
        and line.startswith("internal error (ZeroDivisionError: division by zero)")
        and "--debug" in line
    )
    assert describe_error(SweepError("axes", 1, "bad")) == ("axes = 1: bad", 2)
    assert describe_error(EnvironmentFailure("--scheduler", "tcp://h:1", "cannot connect")) == (
        "--scheduler = 'tcp://h:1': cannot connect",
        1,
    )

    class MissingExtra(ImpactBalanceError, ImportError):  # what an extra's error would be
        pass

    assert describe_error(MissingExtra("needs impact-balance[sim]"))[1] == 1


def test_an_unexpected_exception_in_a_command_is_one_line_exit_1(capsys, monkeypatch):
    from impact_balance.cli import listing

    def broken(args):
        raise KeyError("surprise")

    monkeypatch.setattr(listing, "run", broken)
    rc, _out, err = run_cli(capsys, "scenarios")
    assert rc == 1 and "internal error (KeyError: 'surprise')" in error_line(err)


# -- numbers the code cannot use ------------------------------------------------------------------
@needs_extra("sim")
@pytest.mark.parametrize(
    "argv, needle",
    [
        (["simulate", "palm_push_two_feet", "--speed", "1e-300"], "--speed"),
        (["simulate", "palm_push_two_feet", "--speed", "0.3,nan"], "--speed"),
        (["simulate", "palm_push_two_feet", "--duration", "1e308"], "--duration"),
        (["validate", "palm_push_two_feet", "--tolerance", "1e-300"], "--tolerance"),
        (["validate", "palm_push_two_feet", "--tolerance", "nan"], "--tolerance"),
    ],
)
def test_numbers_outside_what_the_simulation_can_do_are_refused(capsys, monkeypatch, argv, needle):
    import impact_balance.sim.trials.balance_trial as balance_trial
    import impact_balance.sim.trials.impact_trial as trial

    monkeypatch.setattr(trial, "run_trial", lambda *a, **k: pytest.fail("simulated"))
    monkeypatch.setattr(
        balance_trial, "run_balance_trial", lambda *a, **k: pytest.fail("simulated")
    )
    start = time.perf_counter()
    rc, _out, err = run_cli(capsys, *argv)
    assert rc == 2 and needle in error_line(err)
    assert time.perf_counter() - start < 60  # refused, not run for ever (a hang guard)


@needs_extra("sim")
def test_a_push_that_throws_the_robot_is_an_answer(capsys):
    """1000 N s is inside the documented (0, 1000]: the robot leaves the ground, an answer."""
    rc, out, err = run_cli(
        capsys,
        "push-test",
        "palm_push_two_feet",
        "--directions",
        "1",
        "--magnitudes",
        "1000",
        "--json",
    )
    assert rc == 0, err
    push = json.loads(out, parse_constant=lambda c: pytest.fail(c))["pushes"][0]
    assert push["fell"] is True and push["magnitude"] == 1000.0


# -- logs ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def log_frame():
    from tests.helpers.logs import synthetic_log

    frame, _, _ = synthetic_log(np.array([0.05, 0.0, 0.0]), T=0.1)
    return frame


def _check_log(capsys, path) -> tuple[int, str, str]:
    return run_cli(capsys, "check-log", str(path), "--scenario", "palm_push_two_feet")


def test_text_in_a_numeric_column_names_the_column_and_line(tmp_path, capsys, log_frame):
    frame = log_frame.copy()
    frame["base_z"] = frame["base_z"].astype(object)
    frame.loc[17, "base_z"] = "abc"
    frame.to_csv(tmp_path / "log.csv", index=False)
    rc, _, err = _check_log(capsys, tmp_path / "log.csv")
    assert rc == 2 and "column base_z, row 18 (line 19): 'abc' is not a number" in error_line(err)
    log_frame.to_csv(tmp_path / "good.csv", index=False)
    assert _check_log(capsys, tmp_path / "good.csv")[0] == 0


def test_nan_in_base_x_names_the_column_not_a_stance(tmp_path, capsys, log_frame):
    frame = log_frame.copy()
    frame.loc[5, "base_x"] = np.nan
    frame.to_parquet(tmp_path / "log.parquet")
    rc, _, err = _check_log(capsys, tmp_path / "log.parquet")
    line = error_line(err)
    assert rc == 2 and "column base_x, row 6" in line and "stances" not in line


def test_a_log_cut_mid_line_is_read_with_a_warning(tmp_path, capsys, log_frame):
    text = log_frame.to_csv(index=False)
    (tmp_path / "cut.csv").write_text(text[: len(text) - 300])
    rc, out, err = _check_log(capsys, tmp_path / "cut.csv")
    assert rc == 0 and err == ""
    assert (
        f"{len(log_frame) - 1} samples" in out
        and "warning: LOG: the last line" in out
        and "left out" in out
    )
    rc, out, _ = run_cli(
        capsys, "check-log", str(tmp_path / "cut.csv"), "--scenario", "palm_push_two_feet", "--json"
    )
    assert json.loads(out)["warnings"][0]["code"] == "log_cut"


@needs_extra("logs")
def test_a_log_over_the_row_limit_is_refused_from_its_metadata(tmp_path, capsys):
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = tmp_path / "huge.parquet"
    pq.write_table(pa.table({"time": np.zeros(MAX_LOG_ROWS + 1, dtype=np.int8)}), path)
    start = time.perf_counter()
    rc, _, err = _check_log(capsys, path)
    assert rc == 2 and "1,000,001 rows" in error_line(err)
    assert time.perf_counter() - start < 30


# -- sweeps: bounded plans, the robot axis, files that are not sweep files -------------------------
BASE = "palm_push_two_feet"


def sweep_spec_from_dict(data: dict):
    """The sweep package's, imported when a test runs (it needs the sweep extra)."""
    from impact_balance.sweep import sweep_spec_from_dict as from_dict

    return from_dict(data)


def make_plan(spec):
    """The sweep package's, imported when a test runs (it needs the sweep extra)."""
    from impact_balance.sweep import make_plan as plan

    return plan(spec)


@needs_extra("sweep")
def test_two_axes_of_a_million_values_are_refused_at_once(capsys, in_tmp):
    spec = {
        "base": BASE,
        "axes": [
            {"path": "impact.friction", "range": [0, 1], "count": 1_000_000},
            {"path": "impact.restitution[1]", "range": [0, 1], "count": 1_000_000},
        ],
    }
    Path("s.yaml").write_text(yaml.safe_dump(spec))
    start = time.perf_counter()
    rc, _, err = run_cli(capsys, "sweep", "s.yaml")
    assert rc == 2 and "1000000000000 points" in error_line(err) and f"{MAX_SWEEP_POINTS:,}" in err
    assert time.perf_counter() - start < 10 and in_tmp() == ["s.yaml"]


@needs_extra("sweep")
def test_point_count_is_exact_beyond_64_bits():
    axes = [{"path": "impact.friction", "range": [0, 1], "count": 999_999}] * 4
    with pytest.raises(SweepError) as info:
        sweep_spec_from_dict({"base": BASE, "axes": axes})
    assert str(999_999**4) in str(info.value)  # 999996000005999996000001: no overflow, no wrap to 0


@needs_extra("sweep")
def test_quasi_random_samples_are_bounded():
    with pytest.raises(SweepError, match=r"sampling\.samples"):
        sweep_spec_from_dict(
            {
                "base": BASE,
                "axes": [{"path": "impact.friction", "range": [0, 1]}],
                "sampling": {"method": "sobol", "samples": 100_000_000},
            }
        )


@needs_extra("sweep")
@pytest.mark.parametrize(
    "dim, needle",
    [
        ({"range": [-1e308, 1e308], "count": 3}, "overflows"),
        ({"values": [0.1, float("nan")]}, "finite"),
        ({"values": [0.1], "count": True}, "integer"),
        ({"range": ["0", 1], "count": 2}, "not text"),
    ],
)
def test_sweep_numbers_are_finite_and_strict(dim, needle):
    with pytest.raises(SweepError, match=needle):
        sweep_spec_from_dict({"base": BASE, "axes": [{"path": "impact.friction", **dim}]})


@needs_extra("sweep")
def test_sweep_file_linked_to_a_system_file_is_not_quoted(tmp_path, capsys, in_tmp):
    secret = tmp_path / "secret.txt"
    secret.write_text("root:x:0:0:SECRET-CONTENT:/root:/bin/bash\ndaemon:x:1:1\n")
    (tmp_path / "s.yaml").symlink_to(secret)
    rc, _, err = run_cli(capsys, "sweep", "s.yaml", "--out", "o")
    assert rc == 2 and "SECRET" not in err and "must be a YAML mapping" in error_line(err)
    (tmp_path / "t.yaml").write_text(
        "base: palm_push_two_feet\nSECRET-KEY: SECRET-CONTENT\n"
        "axes: [{path: impact.friction, values: [0.1]}]\n"
    )
    rc, _, err = run_cli(capsys, "sweep", "t.yaml", "--out", "o")
    assert rc == 2 and "unknown key" in error_line(err) and "SECRET-CONTENT" not in err
    assert "o" not in in_tmp()


@needs_extra("sweep")
def test_robot_axis_of_robots_without_the_base_frames_is_refused():
    spec = sweep_spec_from_dict(
        {
            "base": BASE,
            "axes": [{"path": "robot", "values": ["g1", "icub", {"urdf": "/etc/passwd"}]}],
        }
    )
    with pytest.raises(SweepError) as info:
        make_plan(spec)
    assert info.value.field == "axes[0].values[0]" and "g1" in str(info.value)
    spec = sweep_spec_from_dict(
        {"base": BASE, "axes": [{"path": "robot", "values": ["talos", {"urdf": "/etc/passwd"}]}]}
    )
    with pytest.raises(SweepError) as info:
        make_plan(spec)
    assert (
        info.value.field == "axes[0].values[1]"
        and "/etc/passwd" in str(info.value)
        and "root:" not in str(info.value)
    )


# -- writing fails after the check: the option and the file are named, exit 1 ---------------------
def full_link(folder: Path, name: str) -> Path:
    """``folder/name``, a link to /dev/full: every write there fails with ENOSPC."""
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full on this system")
    folder.mkdir(parents=True, exist_ok=True)
    link = folder / name
    link.symlink_to("/dev/full")
    return link


@needs_extra("plots")
def test_a_full_disk_under_plots_names_the_option_and_the_figure(tmp_path, capsys):
    figure = full_link(tmp_path / "figs", "palm_push_two_feet_areas.png")
    rc, out, err = run_cli(capsys, "analyze", "palm_push_two_feet", "--plots", str(figure.parent))
    line = error_line(err)
    assert rc == 1 and out == ""
    assert f"--plots = '{figure.parent}'" in line and str(figure) in line, line
    assert "No space left on device" in line


@needs_extra("plots")
def test_a_full_disk_under_plot_names_the_option(tmp_path, capsys):
    figure = full_link(tmp_path, "p.png")
    rc, _, err = run_cli(
        capsys, "phase-portrait", "--com-height", "0.8", "--zmp-range", "-0.1", "0.1",
        "--plot", str(figure),
    )  # fmt: skip
    line = error_line(err)
    assert rc == 1 and f"--plot = '{figure}'" in line and "No space left on device" in line


@needs_extra("sim", "logs")
@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_full_disk_under_log_names_the_option(tmp_path, capsys, suffix):
    log = full_link(tmp_path, f"log{suffix}")
    rc, _, err = run_cli(
        capsys, "simulate", "palm_push_two_feet", "--speed", "0.3", "--log", str(log)
    )
    line = error_line(err)
    assert rc == 1 and f"--log = '{log}'" in line and "No space left on device" in line


def test_writing_keeps_a_broken_pipe_and_names_other_failures():
    from impact_balance.cli.output_paths import writing
    from impact_balance.exceptions import OutputError

    with pytest.raises(BrokenPipeError), writing("--log", "x.csv"):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")
    with pytest.raises(OutputError) as caught, writing("--plots", "d"):
        raise OSError(errno.EROFS, "Read-only file system", "d/a.png")
    assert str(caught.value) == "--plots = 'd': cannot write d/a.png: Read-only file system"
    assert caught.value.exit_status == 1


# -- pose --out: checked before the IK ------------------------------------------------------------
@pytest.fixture
def no_scenario_load(monkeypatch):
    """Record any scenario load (the IK starts with one); yields the list of calls."""
    import impact_balance.scenario as scenario

    calls: list[object] = []
    monkeypatch.setattr(scenario, "load_scenario", lambda *a, **k: calls.append(a))
    return calls


@pytest.mark.parametrize("out", ["/proc/posed.yaml", "/sys/posed.yaml", "/proc/self/posed.yaml"])
def test_pose_into_a_virtual_file_system_is_exit_1_before_the_ik(capsys, no_scenario_load, out):
    if not Path(out).parent.is_dir():
        pytest.skip(f"no {Path(out).parent} here")
    try:
        os.rmdir(__import__("tempfile").mkdtemp(dir=Path(out).parent))
        pytest.skip(f"{Path(out).parent} is writable here")
    except OSError:
        pass
    rc, stdout, err = run_cli(capsys, "pose", "palm_push_two_feet", "--com", "0", "0", "--out", out)
    line = error_line(err)
    assert rc == 1 and stdout == "" and f"--out = '{out}'" in line, line
    assert no_scenario_load == []


def test_pose_that_cannot_write_its_file_is_exit_1_naming_out(tmp_path, capsys, monkeypatch):
    import impact_balance.gui.workspace as workspace

    real = os.fdopen

    class Full(io.StringIO):
        def write(self, text):
            raise OSError(errno.ENOSPC, "No space left on device")

    def fdopen(fd, mode="r", *args, **kwargs):
        if "w" in mode:
            os.close(fd)
            return Full()
        return real(fd, mode, *args, **kwargs)

    monkeypatch.setattr(workspace.os, "fdopen", fdopen)
    out = tmp_path / "posed.yaml"
    rc, _, err = run_cli(capsys, "pose", "palm_push_two_feet", "--com", "0", "0", "--out", str(out))
    line = error_line(err)
    assert rc == 1 and "--out" in line and "No space left on device" in line, line
    assert not out.exists()


# -- failures of the machine raised as something else ---------------------------------------------
def test_a_governor_error_or_a_foreign_broken_pipe_is_one_line_exit_1(capsys, monkeypatch):
    from impact_balance.cli import listing
    from impact_balance.exceptions import GovernorError

    def dead_worker(args):
        raise GovernorError("worker", None, "the contact-aware worker process ended")

    monkeypatch.setattr(listing, "run", dead_worker)
    rc, _, err = run_cli(capsys, "scenarios")
    assert rc == 1 and "worker" in error_line(err)

    def broken(args):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    monkeypatch.setattr(listing, "run", broken)
    rc, _, err = run_cli(capsys, "scenarios")
    assert rc == 1 and "Broken pipe" in error_line(err) and "worker" in err


CHILD = """
import pathlib, sys, time
from impact_balance import cli
from impact_balance.cli import listing

def slow(args):
    pathlib.Path(sys.argv[1]).write_text("ready")
    time.sleep(60)
    return 0

listing.run = slow
sys.exit(cli.main(["scenarios"]))
"""


@pytest.mark.parametrize(
    "sig, message",
    [("SIGINT", "impact-balance: error: interrupted"), ("SIGTERM", "terminated (SIGTERM)")],
)
def test_sigint_and_sigterm_exit_130_with_one_line(tmp_path, sig, message):
    import signal

    marker = tmp_path / "ready"
    proc = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(marker)],
        env={**os.environ, "PYTHONPATH": SRC},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60
        while not marker.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert marker.exists(), proc.communicate(timeout=10)
        proc.send_signal(getattr(signal, sig))
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert message in error_line(err)


def test_the_exit_status_table_of_the_readme(tmp_path):
    """0 an answer, 2 bad input, 1 the machine, 141 stdout closed early (130: the test above)."""
    assert run_process("scenarios", cwd=tmp_path).returncode == 0
    bad = run_process("analyze", "nope.yaml", cwd=tmp_path)
    assert bad.returncode == 2 and "nope.yaml" in error_line(bad.stderr)
    machine = run_process("analyze", "palm_push_two_feet", "--plots", UNWRITABLE, cwd=tmp_path)
    assert machine.returncode == 1 and "--plots" in error_line(machine.stderr)
    proc = subprocess.Popen(
        [sys.executable, "-m", "impact_balance", "frames", "talos", "--json"],
        env={**os.environ, "PYTHONPATH": SRC},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None
    proc.stdout.close()  # closed before the command writes
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 141 and err == b"", err
