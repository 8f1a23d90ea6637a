"""The commands under hostile sweep files, logs and simulation options (hypothesis).

The contract is the command line's: for any input, either the command's answer (exit status 0)
or one line ``...: error: ...`` with exit status 2 (1 for a failure of the machine), never a
traceback (an exception escaping ``cli.main`` fails the test), never a hang. The simulation
commands are driven with their simulators replaced by a sentinel: an option that passes the
checks must lie within the documented limits (:mod:`impact_balance.ranges`).
"""

from __future__ import annotations

import contextlib
import copy
import io
import math
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impact_balance import cli
from impact_balance.exceptions import MESSAGE_CHARS
from impact_balance.ranges import MAX_APPROACH_SPEED, MIN_APPROACH_SPEED, TOLERANCE_RANGE
from tests.helpers.cli import strict_json
from tests.helpers.extras import needs_extra
from tests.helpers.hostile import HOSTILE_NUMBERS, apply_mutation, hostile_values, mapping_paths

#: Multiplies the number of examples: IMPACT_BALANCE_FUZZ_SCALE=20 for a deeper search (minutes).
SCALE = float(os.environ.get("IMPACT_BALANCE_FUZZ_SCALE", "1"))
SPEC = {
    "base": "palm_push_two_feet",
    "chunk_size": 5,
    "sampling": "grid",
    "axes": [
        {"path": "impact.friction", "range": [0.1, 0.5], "count": 3},
        {"path": "impact.restitution", "values": [[0.0, 0.2], [0.1, 0.5]]},
        {"direction": "impact.normal", "azimuth": {"values": [170, 190]}},
    ],
}


def run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = cli.main(argv)
        except SystemExit as exc:  # argparse's usage error: one line, status 2
            rc = int(exc.code)
    return rc, out.getvalue(), err.getvalue()


def assert_one_line(rc: int, err: str) -> None:
    assert "Traceback" not in err, err
    lines = [
        ln
        for ln in err.splitlines()
        if "compiling the projection kernel" not in ln and "warning:" not in ln
    ]
    assert rc in (1, 2), (rc, err)
    assert len(lines) == 1 and ": error: " in lines[0], err[-2000:]
    assert len(lines[0]) <= 60 + MESSAGE_CHARS


# -- sweep files ------------------------------------------------------------------------------
@st.composite
def mutated_specs(draw):
    data = copy.deepcopy(SPEC)
    for _ in range(draw(st.integers(1, 3))):
        op = draw(
            st.sampled_from(
                ["number", "number", "set", "set", "delete", "wrap", "unknown_key", "count"]
            )
        )
        numbers = [
            p
            for p, v in mapping_paths(data)
            if isinstance(v, (int, float)) and not isinstance(v, bool)
        ]
        if op == "count":  # a grid of any size, up to past 64 bits
            axes = data.get("axes")
            if isinstance(axes, list) and axes and isinstance(axes[0], dict):
                axes[0]["count"] = draw(st.sampled_from([0, 1, 2, 10**6, 10**6 + 1, 2**63, 10**40]))
            continue
        if op == "number" and numbers:
            path = draw(st.sampled_from(numbers))
            data = apply_mutation(
                data, path, "set", draw(st.sampled_from([*HOSTILE_NUMBERS, 0.3, 1, 2, -1]))
            )
            continue
        paths = [p for p, _ in mapping_paths(data)]
        path = draw(st.sampled_from(paths))
        if op in ("delete", "number") and not path:
            op = "set"
        data = apply_mutation(data, path, "set" if op == "number" else op, draw(hostile_values))
        if not isinstance(data, dict):
            break
    return data


@pytest.fixture(scope="module", autouse=True)
def warm_up():
    rc, _, err = run(["analyze", "palm_push_two_feet", "--json"])
    assert rc == 0, err


@pytest.mark.slow
@needs_extra("sweep")
@settings(
    max_examples=int(80 * SCALE),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(data=mutated_specs())
def test_mutated_sweep_file_gives_one_line_or_a_summary(data):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.yaml"
        path.write_text(yaml.safe_dump(data, allow_unicode=True))
        out = Path(tmp) / "out"
        rc, stdout, err = run(
            [
                "sweep",
                str(path),
                "--out",
                str(out),
                "--workers",
                "1",
                "--no-progress",
                "--no-plots",
                "--json",
            ]
        )
        if rc == 0:
            import json

            summary = json.loads(
                stdout, parse_constant=lambda c: pytest.fail(f"not strict JSON: {c}")
            )
            assert summary["complete"] and summary["rows"] == summary["n_points"] <= 10**6
        else:
            assert_one_line(rc, err)
            assert not out.exists()  # nothing created for bad input


# -- logs ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def log_text():
    from tests.helpers.logs import synthetic_log

    frame, _, _ = synthetic_log(np.array([0.05, 0.0, 0.0]), T=0.03)
    return frame.to_csv(index=False)


CELLS = [
    "abc",
    "",
    "nan",
    "inf",
    "-inf",
    "1e999",
    "True",
    "0x10",
    "1,5",
    '"',
    "1e-320",
    "9" * 400,
    "\x00",
    "é",
]


@needs_extra("logs")
@settings(
    max_examples=int(60 * SCALE),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(
    edits=st.lists(
        st.tuples(st.integers(0, 10_000), st.integers(0, 10_000), st.sampled_from(CELLS)),
        max_size=3,
    ),
    cut=st.one_of(st.none(), st.integers(1, 5000)),
    header=st.booleans(),
    shuffle=st.booleans(),
)
def test_mutated_log_gives_one_line_or_a_check(log_text, edits, cut, header, shuffle):
    lines = log_text.splitlines()
    rows = [ln.split(",") for ln in lines]
    for r, c, cell in edits:
        row = rows[1 + r % (len(rows) - 1)] if not header else rows[0]
        row[c % len(row)] = cell
    if shuffle:
        rows[1:] = rows[1:][::-1]
    text = "\n".join(",".join(r) for r in rows) + "\n"
    if cut is not None:
        text = text[: max(0, len(text) - cut)]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "log.csv"
        path.write_text(text, encoding="utf-8", errors="surrogateescape")
        rc, stdout, err = run(
            ["check-log", str(path), "--scenario", "palm_push_two_feet", "--json"]
        )
        if rc != 0:
            assert_one_line(rc, err)
            assert rc == 2
            return
        assert_a_check(stdout, err, path, rows=len(rows) - 1)
        if not edits and cut is None and not shuffle:  # the log as written: every sample is ok
            doc = strict_json(stdout)
            assert doc["ok"] and doc["samples"] == len(rows) - 1 and not doc["warnings"], doc


#: What ``check-log --json`` always answers (logs/check.py, LogCheck.to_dict, and the command's).
CHECK_KEYS = {
    "scenario",
    "samples",
    "duration",
    "ok",
    "has_zmp",
    "min_com_velocity_margin",
    "min_zmp_margin",
    "violations",
    "loaded_samples",
    "floating",
    "stances",
    "settings",
    "log",
    "warnings",
}


def assert_a_check(stdout: str, err: str, path: Path, rows: int) -> None:
    """A successful check-log: one strict JSON document with the check's verdict, nothing else."""
    assert "Traceback" not in err and ": error: " not in err, err[-2000:]
    doc = strict_json(stdout)
    assert CHECK_KEYS <= doc.keys(), CHECK_KEYS - doc.keys()
    assert doc["scenario"] == "palm_push_two_feet" and doc["log"] == str(path)
    assert isinstance(doc["ok"], bool) and doc["ok"] == (doc["violations"] == [])
    assert 1 <= doc["samples"] <= rows and 0 <= doc["loaded_samples"] <= doc["samples"]
    assert doc["duration"] >= 0.0 and isinstance(doc["warnings"], list)
    for v in doc["violations"]:
        assert v["kind"] in ("com_velocity", "zmp") and v["start"] <= v["end"], v
        assert v["samples"] >= 1 and (v["worst_margin"] is None or v["worst_margin"] < 0), v


# -- simulation options ------------------------------------------------------------------------
class Simulated(Exception):
    """Raised instead of simulating: the options passed every check (``main`` reports it as
    an internal error naming this class, which the test recognises)."""


def _patched():
    import impact_balance.sim.trials.balance_trial as balance_trial
    import impact_balance.sim.trials.impact_trial as trial

    def sentinel(*args, **kwargs):
        raise Simulated

    patch = pytest.MonkeyPatch()
    patch.setattr(trial, "run_trial", sentinel)
    patch.setattr(balance_trial, "run_balance_trial", sentinel)
    patch.setattr(
        balance_trial.BalanceSetup, "create", classmethod(lambda cls, *a, **k: sentinel())
    )
    return patch


OPTION_VALUES = st.one_of(
    st.sampled_from(
        [
            "0",
            "-1",
            "1e-300",
            "1e300",
            "nan",
            "inf",
            "-0",
            "0.3",
            "5",
            "5.0001",
            "0.01",
            "0.0099",
            "1000",
            "1000.1",
            "abc",
            "",
            "1,2",
            "0.1,0.2,nan",
            "1e-3",
            "0.5",
            "0.50001",
            "16",
            "361",
            "2.5e-2",
        ]
    ),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**6), 10**6).map(str),
    st.text(max_size=12),
)


@needs_extra("sim")
@settings(max_examples=int(80 * SCALE), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(command=st.sampled_from(["simulate", "validate", "push-test"]), data=st.data())
def test_simulation_options_are_refused_in_one_line_or_within_the_limits(command, data):
    options = {
        "simulate": ["--speed", "--duration", "--armature"],
        "validate": ["--tolerance", "--max-speed"],
        "push-test": ["--directions", "--magnitudes", "--duration"],
    }[command]
    chosen = data.draw(
        st.lists(st.sampled_from(options), min_size=1, max_size=len(options), unique=True)
    )
    argv = [command, "palm_push_two_feet"]
    given_values = {}
    for option in chosen:
        value = data.draw(OPTION_VALUES)
        given_values[option] = value
        argv += [f"{option}={value}"]
    patch = _patched()
    try:
        rc, _, err = run(argv)
    finally:
        patch.undo()
    if (
        rc == 1 and f"{Simulated.__module__}.Simulated" in err
    ):  # accepted: every value within the documented limits
        if "--speed" in given_values:
            speeds = [float(v) for v in given_values["--speed"].split(",")]
            assert all(MIN_APPROACH_SPEED <= v <= MAX_APPROACH_SPEED for v in speeds)
        if "--tolerance" in given_values:
            assert TOLERANCE_RANGE[0] <= float(given_values["--tolerance"]) <= TOLERANCE_RANGE[1]
        for option in ("--duration", "--max-speed", "--magnitudes", "--armature"):
            if option in given_values:
                assert math.isfinite(float(given_values[option]))
    else:
        assert_one_line(rc, err)
        assert rc == 2


# -- inputs that are not regular files: refused at once, in one line ---------------------------
def _not_a_file(tmp_path: Path, kind: str, name: str) -> Path:
    path = tmp_path / name
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        path.mkdir()
    else:  # a link to an endless device
        path.symlink_to("/dev/zero")
    return path


@pytest.mark.parametrize("kind", ["fifo", "folder", "dev-zero"])
@pytest.mark.parametrize(
    "command",
    [
        ["analyze", "{path}", "--json"],
        ["check-log", "{log}", "--scenario", "palm_push_two_feet", "--json"],
    ],
    ids=["analyze", "check-log"],
)
def test_a_fifo_device_or_folder_input_is_refused_in_one_line(tmp_path, kind, command):
    from tests.helpers.cli import assert_one_line_error, run_process

    if command[0] == "check-log":
        pytest.importorskip("pandas", reason="needs the logs extra (pandas)")
    path = _not_a_file(tmp_path, kind, "input.yaml")
    log = _not_a_file(tmp_path, kind, "input.csv")
    argv = [a.format(path=path, log=log) for a in command]
    proc = run_process(*argv, timeout=60)  # a FIFO read would block: the timeout fails the test
    what = {"fifo": "FIFO", "folder": "a folder", "dev-zero": "a character device"}[kind]
    assert_one_line_error(proc.returncode, proc.stderr, what)
    assert proc.stdout == ""
