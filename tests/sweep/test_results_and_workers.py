"""A sweep's results folder is checked like a database, every axis does what it says,
nothing is created for bad input, and workers die with their sweep.

Folders are damaged in every way a folder can be (a part cut in half, emptied, copied from
another sweep, extra, renamed, edited, deleted): ``--verify`` names each in one line, the
summary leaves them out without crashing, and a resume recomputes exactly what is missing or
damaged, ending with the same rows as an uninterrupted run.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("dask", reason="needs the sweep extra (Dask)")
pytest.importorskip("distributed", reason="needs the sweep extra (Dask distributed)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")
pytest.importorskip("pyarrow", reason="needs the logs or sweep extra (pyarrow)")
pytest.importorskip("pyarrow.parquet", reason="needs the logs or sweep extra (pyarrow)")
pytest.importorskip("psutil", reason="needs psutil (installed with the sweep extra's Dask)")

import psutil
import pyarrow as pa
import pyarrow.parquet as pq
import yaml

from impact_balance import analyze, cli
from impact_balance.exceptions import EnvironmentFailure, OptionError
from impact_balance.robot.robot import load_robot
from impact_balance.scenario import read_mapping, scenario_from_dict, scenario_path
from impact_balance.sweep import Evaluator, make_plan, read_results, run_sweep, sweep_spec_from_dict
from impact_balance.sweep.cluster import check_scheduler_address, connect
from impact_balance.sweep.store import LEDGER, MANIFEST, check_folder, table_checksum
from tests.helpers.hostile import hostile_values, nested

SRC = str(Path(__file__).parents[2] / "src")
BASE = "palm_push_two_feet"
SPEC = {
    "base": BASE,
    "chunk_size": 4,
    "axes": [
        {"path": "impact.friction", "range": [0.0, 0.6], "count": 5},
        {"path": "impact.restitution[1]", "values": [0.0, 0.5, 1.0]},
    ],
}  # 15 points, 4 chunks


def main(argv: list[str]) -> int:
    """``cli.main``, with argparse's usage errors (SystemExit) as their status."""
    try:
        return cli.main(argv)
    except SystemExit as exc:
        return int(exc.code)


def plan_of(spec=SPEC):
    return make_plan(sweep_spec_from_dict(spec))


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """An uninterrupted run (the reference) and another sweep's folder (for foreign parts)."""
    root = tmp_path_factory.mktemp("clean")
    run_sweep(plan_of(), root / "whole", workers=1, progress=False)
    other = {
        **SPEC,
        "axes": [SPEC["axes"][0], {"path": "impact.restitution[1]", "values": [0.1, 0.2, 0.3]}],
    }
    run_sweep(plan_of(other), root / "other", workers=1, progress=False)
    return root


def _cut(path: Path) -> None:
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def _edit(path: Path) -> None:
    """Change one value, keep the part's metadata (what an edit in place would do)."""
    table = pq.read_table(path)
    values = table["max_contact_velocity"].to_pylist()
    values[1] += 0.1
    column = table.schema.get_field_index("max_contact_velocity")
    pq.write_table(table.set_column(column, "max_contact_velocity", pa.array(values)), path)


def _without_metadata(path: Path) -> None:
    pq.write_table(pq.read_table(path).replace_schema_metadata(None), path)


DAMAGE = {
    "cut in half": (
        lambda p, o: _cut(p / "parts/part-000001.parquet"),
        "part-000001",
        "damaged",
        {1},
    ),
    "emptied": (
        lambda p, o: (p / "parts/part-000002.parquet").write_bytes(b""),
        "part-000002",
        "damaged",
        {2},
    ),
    "foreign": (
        lambda p, o: shutil.copy(o / "parts/part-000000.parquet", p / "parts/part-000000.parquet"),
        "part-000000",
        "foreign",
        {0},
    ),
    "extra": (
        lambda p, o: shutil.copy(p / "parts/part-000001.parquet", p / "parts/part-000009.parquet"),
        "part-000009",
        "extra",
        set(),
    ),
    "renamed": (
        lambda p, o: os.replace(p / "parts/part-000003.parquet", p / "parts/part-000002.parquet"),
        "part-000002",
        "renamed",
        {2, 3},
    ),
    "edited": (lambda p, o: _edit(p / "parts/part-000003.parquet"), "part-000003", "damaged", {3}),
    "metadata stripped": (
        lambda p, o: _without_metadata(p / "parts/part-000000.parquet"),
        "part-000000",
        "foreign",
        {0},
    ),
    "deleted": (
        lambda p, o: (p / "parts/part-000001.parquet").unlink(),
        "part-000001",
        "missing",
        {1},
    ),
}


@pytest.mark.parametrize("case", list(DAMAGE))
def test_a_damaged_folder_is_named_left_out_and_recomputed(tmp_path, capsys, clean, case):
    damage, file, kind, recomputed = DAMAGE[case]
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    damage(out, clean / "other")
    # verify: one line naming the part and what is wrong, exit 2
    assert main(["sweep", "--verify", str(out)]) == 2
    lines = capsys.readouterr().out.splitlines()
    bad = [ln for ln in lines if file in ln]
    assert bad and all(f": {kind}: " in ln or ": missing: " in ln for ln in bad), lines
    # the summary leaves the part out and says so; it never crashes nor mixes
    assert main(["sweep", "--summary", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    assert file in captured.err and "left out" in captured.err
    good = check_folder(out)
    assert good.rows == 15 - sum(4 if c < 3 else 3 for c in recomputed)
    # a resume recomputes exactly the bad chunks: same rows as an uninterrupted run, no duplicate
    computed = []
    report = run_sweep(
        plan_of(),
        out,
        workers=1,
        progress=False,
        on_chunk=computed.append,
        notify=lambda line: computed.append(line),
    )
    assert {c for c in computed if isinstance(c, int)} == recomputed
    assert any(file in str(c) for c in computed if isinstance(c, str))
    resumed, whole = read_results(out), read_results(clean / "whole")
    assert resumed.num_rows == 15 and resumed.equals(whole)
    assert check_folder(out).ok and report.complete
    assert main(["sweep", "--verify", str(out)]) == 0
    capsys.readouterr()


def test_a_part_of_the_same_chunk_with_edited_metadata_is_caught_by_the_manifest(tmp_path, clean):
    """Values edited and the part's own checksum recomputed: the manifest of parts still differs."""
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    path = out / "parts/part-000002.parquet"
    table = pq.read_table(path)
    meta = dict(table.schema.metadata)
    values = table["max_contact_velocity"].to_pylist()
    values[0] *= 2
    edited = table.set_column(
        table.schema.get_field_index("max_contact_velocity"),
        "max_contact_velocity",
        pa.array(values),
    ).replace_schema_metadata(None)
    meta[b"impact_balance.checksum"] = table_checksum(edited).encode()
    pq.write_table(edited.replace_schema_metadata(meta), path)
    problems = check_folder(out).problems
    assert len(problems) == 1 and "recorded in the manifest" in problems[0].reason


def test_the_checksum_survives_parquet_and_sees_one_bit(tmp_path, clean):
    table = read_results(clean / "whole")
    pq.write_table(table, tmp_path / "t.parquet")
    back = pq.read_table(tmp_path / "t.parquet")
    assert table_checksum(back.replace_schema_metadata(None)) == table_checksum(
        table.replace_schema_metadata(None)
    )
    values = table["zmp_max_contact_velocity"].to_pylist()
    values[7] = float.fromhex(
        values[7].hex()[:-1] + ("0" if values[7].hex()[-1] != "0" else "1")
    )  # flip the last bit
    other = table.set_column(
        table.schema.get_field_index("zmp_max_contact_velocity"),
        "zmp_max_contact_velocity",
        pa.array(values),
    )
    assert table_checksum(other) != table_checksum(table)


def test_a_torn_manifest_line_is_skipped_and_repaired(tmp_path, clean):
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    ledger = out / LEDGER
    ledger.write_text(ledger.read_text()[:-20])  # killed while appending
    assert check_folder(out).ok  # the unrecorded part is checked by its own metadata
    run_sweep(plan_of(), out, workers=1, progress=False)
    assert len(ledger.read_text().splitlines()) == 4


def _manifest_edit(out: Path, **changes) -> None:
    manifest = json.loads((out / MANIFEST).read_text())
    (out / MANIFEST).write_text(json.dumps({**manifest, **changes}))


def _verify_line(capsys, out: Path) -> tuple[int, str]:
    rc = main(["sweep", "--verify", str(out)])
    captured = capsys.readouterr()
    return rc, captured.out + captured.err


@pytest.mark.parametrize(
    "changes, needle",
    [
        ({"chunk_size": 7}, "chunk_size is 7, its sweep has 4"),
        ({"n_chunks": 100000000}, "n_chunks is 100000000, its sweep has 4"),
        ({"n_points": 16}, "n_points is 16"),
        ({"dimensions": 3}, "dimensions is not a list"),
        ({"dimensions": [{"name": "a"}]}, "1 dimensions"),
        ({"spec": [1]}, "spec"),
    ],
)
def test_a_manifest_is_checked_against_the_sweep_it_records(
    tmp_path, capsys, clean, changes, needle
):
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    _manifest_edit(out, **changes)
    rc, text = _verify_line(capsys, out)
    assert rc == 2 and len(text.splitlines()) == 1 and "manifest.json is damaged" in text
    assert needle in text and "internal error" not in text


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    key=st.sampled_from(
        ["n_points", "chunk_size", "n_chunks", "dimensions", "spec", "digest", "format"]
    ),
    value=st.one_of(hostile_values, st.lists(hostile_values, max_size=3), st.just(nested(3000))),
)
def test_any_manifest_edit_is_one_line_never_an_internal_error(
    tmp_path_factory, capsys, clean, key, value
):
    out = tmp_path_factory.mktemp("m") / "out"
    shutil.copytree(clean / "whole", out)
    manifest = json.loads((out / MANIFEST).read_text())
    manifest[key] = value
    try:
        text = json.dumps(manifest)
    except (ValueError, RecursionError):
        return  # not JSON at all: the torn-file cases cover it
    (out / MANIFEST).write_text(text)
    rc, shown = _verify_line(capsys, out)
    assert "internal error" not in shown and "Traceback" not in shown
    assert rc in (0, 2) and (rc == 0) == (
        manifest == json.loads((clean / "whole" / MANIFEST).read_text())
    )


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    lines=st.lists(
        st.one_of(st.text(max_size=30), st.builds(json.dumps, hostile_values)), max_size=4
    )
)
def test_a_garbled_ledger_never_is_an_internal_error(tmp_path_factory, capsys, clean, lines):
    out = tmp_path_factory.mktemp("l") / "out"
    shutil.copytree(clean / "whole", out)
    (out / LEDGER).write_text("\n".join(line.replace("\n", " ") for line in lines) + "\n")
    rc, shown = _verify_line(capsys, out)
    assert rc in (0, 2) and "internal error" not in shown and "Traceback" not in shown


def test_a_resume_rewrites_an_edited_manifest_and_repairs_once(tmp_path, capsys, clean):
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    _manifest_edit(out, chunk_size=2, n_chunks=8)
    lines: list = []
    report = run_sweep(plan_of(), out, workers=1, progress=False, notify=lines.append)
    assert any("manifest.json: damaged: chunk_size is 2" in str(line) for line in lines)
    assert report.chunks_computed == 0 and report.complete
    assert not (out / "rejected").exists()  # the parts were good: nothing moved aside
    assert read_results(out).equals(read_results(clean / "whole"))
    assert _verify_line(capsys, out)[0] == 0
    again: list = []
    run_sweep(plan_of(), out, workers=1, progress=False, notify=again.append)
    assert again == []


def test_a_missing_ledger_is_damage_even_with_a_forged_part(tmp_path, capsys, clean):
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    path = out / "parts/part-000002.parquet"
    table = pq.read_table(path)
    meta = dict(table.schema.metadata)
    values = table["max_contact_velocity"].to_pylist()
    values[0] *= 2
    forged = table.set_column(
        table.schema.get_field_index("max_contact_velocity"),
        "max_contact_velocity",
        pa.array(values),
    ).replace_schema_metadata(None)
    meta[b"impact_balance.checksum"] = table_checksum(forged).encode()
    pq.write_table(forged.replace_schema_metadata(meta), path)
    (out / LEDGER).unlink()
    rc, text = _verify_line(capsys, out)
    assert rc == 2 and f"{LEDGER}: missing" in text and "part-000002.parquet: damaged" in text
    computed: list = []
    run_sweep(plan_of(), out, workers=1, progress=False, on_chunk=computed.append)
    assert sorted(computed) == [0, 1, 2, 3]
    assert read_results(out).equals(read_results(clean / "whole"))
    assert _verify_line(capsys, out)[0] == 0


def _padded(path: Path, how: str) -> None:
    table = pq.read_table(path)
    meta = table.schema.metadata
    if how == "padding column":
        pad = pa.array(["0" * 4_000_000] * table.num_rows)
        table = table.append_column("padding", pad)
    else:  # the message column holds megabytes
        column = table.schema.get_field_index("message")
        table = table.set_column(column, "message", pa.array(["0" * 4_000_000] * table.num_rows))
    pq.write_table(table.replace_schema_metadata(meta), path, compression="zstd")


@pytest.mark.parametrize(
    "how, needle", [("padding column", "not this sweep's"), ("huge values", "uncompressed")]
)
def test_verify_checks_a_part_from_its_footer_before_reading_it(
    tmp_path, capsys, clean, how, needle
):
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    path = out / "parts/part-000001.parquet"
    _padded(path, how)
    assert path.stat().st_size < 200_000  # small on disk, 16 MB once read
    read = []
    real = pq.ParquetFile.read
    pq.ParquetFile.read = lambda self, *a, **k: read.append(1) or real(self, *a, **k)
    try:
        rc, text = _verify_line(capsys, out)
    finally:
        pq.ParquetFile.read = real
    assert rc == 2 and "part-000001.parquet: damaged" in text and needle in text
    assert len(read) == 3  # the three good parts only


def _in_thread(fn, timeout=20.0):
    result: list = []
    worker = threading.Thread(target=lambda: result.append(fn()), daemon=True)
    worker.start()
    worker.join(timeout)
    assert not worker.is_alive(), "blocked"
    return result[0]


@pytest.mark.parametrize("name", [MANIFEST, LEDGER])
@pytest.mark.parametrize("kind", ["fifo", "/dev/zero"])
def test_a_fifo_or_device_manifest_does_not_block(tmp_path, capsys, clean, name, kind):
    out = tmp_path / "out"
    shutil.copytree(clean / "whole", out)
    (out / name).unlink()
    if kind == "fifo":
        os.mkfifo(out / name)
    else:
        (out / name).symlink_to("/dev/zero")
    rc, text = _in_thread(lambda: _verify_line(capsys, out))
    assert rc == 2 and len(text.splitlines()) == 1 and name in text
    assert "not a regular file" in text


def test_rows_say_what_was_evaluated_and_match_analyze():
    plan = plan_of({"base": BASE, "axes": [{"path": "impact.friction", "values": [0.2]}]})
    row = Evaluator(plan).evaluate_chunk(0).to_pylist()[0]
    stance = analyze(BASE).stance
    assert row["robot_name"] == "talos" and row["contact_frames"] == ",".join(
        c.spec.frame for c in stance.contacts
    )
    assert (
        row["q"] == pytest.approx(stance.q.tolist(), abs=1e-12) and len(row["stance_digest"]) == 12
    )


def test_a_robot_axis_varies_the_robot(tmp_path):
    """Talos and a Talos with a heavier torso: rows differ, and each matches analyze() of that
    robot."""
    talos = load_robot("talos")
    text = Path(talos.urdf_path).read_text()
    start = text.index('<link name="torso_2_link">')
    mass = text.index("<mass value=", start)
    heavy = tmp_path / "talos_heavy.urdf"
    heavy.write_text(text[:mass] + '<mass value="40.0"/>' + text[text.index("/>", mass) + 2 :])
    files = {"urdf": str(heavy), "srdf": str(talos.srdf_path)}
    plan = plan_of(
        {
            "base": BASE,
            "axes": [
                {"path": "robot", "values": ["talos", files]},
                {"path": "impact.friction", "values": [0.1]},
            ],
        }
    )
    rows = Evaluator(plan).evaluate_chunk(0).to_pylist()
    assert [r["robot_name"] for r in rows] == ["talos", str(heavy)]
    assert rows[0]["stance_digest"] != rows[1]["stance_digest"]
    for row, robot in zip(rows, ("talos", files), strict=True):
        raw = read_mapping(scenario_path(BASE))
        raw["robot"], raw["impact"]["friction"] = robot, 0.1
        expected = analyze(scenario_from_dict(raw)).impact.max_contact_velocity
        assert row["status"] == "ok" and row["max_contact_velocity"] == pytest.approx(
            expected, rel=1e-9
        )
    assert rows[0]["max_contact_velocity"] != pytest.approx(
        rows[1]["max_contact_velocity"], rel=1e-3
    )


# -- nothing created for bad input ----------------------------------------------------------------
def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize(
    "out, scheduler, status, needle",
    [
        ("/proc/nope/out", None, 1, "--out"),
        ("AFILE", None, 2, "--out"),
        ("o", "tcp://", 2, "no host"),
        ("o", "not-an-address", 2, "no port"),
        ("o", "http://127.0.0.1:8787", 2, "not Dask's protocol"),
        ("o", "tcp://127.0.0.1:{port}", 1, "cannot connect"),
        ("o", "tcp://no-such-host.invalid:8786", 1, "unknown host"),
    ],
)
def test_bad_out_or_scheduler_is_one_line_and_creates_nothing(
    tmp_path, capsys, monkeypatch, out, scheduler, status, needle
):
    monkeypatch.chdir(tmp_path)
    Path("AFILE").write_text("x")
    Path("s.yaml").write_text(yaml.safe_dump(SPEC))
    argv = ["sweep", "s.yaml", "--out", out, "--no-progress"]
    if scheduler:
        argv += ["--scheduler", scheduler.format(port=_closed_port())]
    start = time.perf_counter()
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == status and len(err.splitlines()) == 1 and needle in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["AFILE", "s.yaml"]
    assert (
        time.perf_counter() - start < 30
    )  # the closed port answers at once, not after Dask's 30 s


def test_scheduler_addresses():
    assert check_scheduler_address("tcp://10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert check_scheduler_address("localhost:8786") == "tcp://localhost:8786"
    assert check_scheduler_address("tls://[::1]:8786") == "tls://[::1]:8786"
    for bad in (
        "",
        "tcp://",
        "tcp://host",
        "host:0",
        "host:99999",
        "ucx://h:1",
        "tcp://h:1/path",
        "a b:1",
    ):
        with pytest.raises(OptionError):
            check_scheduler_address(bad)
    with pytest.raises(EnvironmentFailure, match="cannot connect"):
        connect(f"tcp://127.0.0.1:{_closed_port()}")


def test_a_scheduler_given_by_address_runs_the_sweep(tmp_path, clean):
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp://",
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        report = run_sweep(
            plan_of(), tmp_path / "d", scheduler=cluster.scheduler_address, progress=False
        )
    assert report.backend == "dask" and read_results(tmp_path / "d").equals(
        read_results(clean / "whole")
    )


@contextlib.contextmanager
def _silent_port():
    """A port that accepts connections (the kernel's backlog) and never says anything."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(8)
        yield server.getsockname()[1]


def test_a_silent_port_is_refused_within_the_timeout():
    with _silent_port() as port:
        start = time.perf_counter()
        with pytest.raises(EnvironmentFailure, match="says nothing within 1 s"):
            connect(f"tcp://127.0.0.1:{port}", timeout=1.0)
        assert time.perf_counter() - start < 3


@pytest.mark.slow
def test_the_command_gives_up_on_a_silent_scheduler_within_ten_seconds(tmp_path, capsys):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SPEC))
    with _silent_port() as port:
        start = time.perf_counter()
        argv = ["sweep", str(tmp_path / "s.yaml"), "--out", str(tmp_path / "o")]
        rc = main([*argv, "--no-progress", "--scheduler", f"tcp://127.0.0.1:{port}"])
        elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    assert rc == 1 and len(err.splitlines()) == 1 and "--scheduler" in err and "10 s" in err
    assert elapsed < 15 and not (tmp_path / "o").exists()


def _sabotaged(monkeypatch, sig, chunk_timeout=None):
    """Local worker processes that get ``sig`` as soon as they are up; their pids.

    ``chunk_timeout``: the wait for chunks once the workers are up (their start keeps the
    run's, longer on a busy machine).
    """
    from impact_balance.sweep import runner

    pids: list[int] = []
    real = runner._Processes.__init__

    def init(self, *args, **kwargs):
        real(self, *args, **kwargs)
        if chunk_timeout is not None:
            self.timeout = chunk_timeout
        for process in self.processes:
            pids.append(process.pid)
            os.kill(process.pid, sig)

    monkeypatch.setattr(runner._Processes, "__init__", init)
    return pids


def _gone(pids, timeout=5.0):
    procs = []
    for pid in pids:
        with contextlib.suppress(psutil.NoSuchProcess):
            procs.append(psutil.Process(pid))
    _, alive = psutil.wait_procs(procs, timeout=timeout)
    return not [p for p in alive if p.status() != psutil.STATUS_ZOMBIE]


@pytest.mark.slow
def test_a_stopped_worker_fails_the_sweep_after_the_chunk_timeout(tmp_path, clean, monkeypatch):
    pids = _sabotaged(monkeypatch, signal.SIGSTOP, chunk_timeout=2.0)
    out = tmp_path / "out"
    start = time.perf_counter()
    with pytest.raises(EnvironmentFailure, match=r"--chunk-timeout .*within 2 s \(chunks 0, 1"):
        run_sweep(plan_of(), out, workers=2, progress=False, chunk_timeout=120)
    assert time.perf_counter() - start < 60 and pids and _gone(pids)
    monkeypatch.undo()
    run_sweep(plan_of(), out, workers=1, progress=False)  # the same command resumes
    assert read_results(out).equals(read_results(clean / "whole"))


def test_a_killed_worker_is_one_line_naming_a_chunk(tmp_path, capsys, monkeypatch):
    pids = _sabotaged(monkeypatch, signal.SIGKILL)
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SPEC))
    argv = ["sweep", str(tmp_path / "s.yaml"), "--out", str(tmp_path / "o"), "--no-progress"]
    rc = main([*argv, "--workers", "2"])
    err = capsys.readouterr().err
    assert rc == 1 and len(err.splitlines()) == 1 and "internal error" not in err, err
    assert "chunk = " in err and "worker process died" in err and pids and _gone(pids)


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "soon"])
def test_a_bad_chunk_timeout_is_a_usage_error(capsys, value):
    assert main(["sweep", "s.yaml", "--chunk-timeout", value]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "--chunk-timeout" in err


def test_a_full_disk_names_out_and_the_part(tmp_path, capsys, monkeypatch):
    from impact_balance.sweep import store

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(store.pq, "write_table", full)
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SPEC))
    argv = ["sweep", str(tmp_path / "s.yaml"), "--out", str(tmp_path / "o"), "--no-progress"]
    rc = main([*argv, "--workers", "1"])
    err = capsys.readouterr().err
    assert rc == 1 and len(err.splitlines()) == 1, err
    assert "--out" in err and "part-000000.parquet: No space left on device" in err
    assert not list((tmp_path / "o" / "parts").iterdir())  # no part cut short left


@pytest.mark.slow
def test_sigterm_while_the_workers_start_exits_130_with_a_message(tmp_path):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SPEC))
    argv = ["sweep", "s.yaml", "--out", "out", "--workers", "2", "--no-progress", "--no-plots"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "impact_balance", *argv],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": SRC},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    descendants: list[psutil.Process] = []
    try:
        command = psutil.Process(proc.pid)
        deadline = time.time() + 120
        while time.time() < deadline and not command.children():  # the fork server: starting
            assert proc.poll() is None, proc.stderr.read().decode()[-2000:]
            time.sleep(0.02)
        descendants = command.children(recursive=True)
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
        err = proc.stderr.read().decode()
        assert proc.returncode == 130 and "interrupted" in err, (proc.returncode, err)
        assert _gone([p.pid for p in descendants])
    finally:
        if proc.poll() is None:
            proc.kill()
        for p in descendants:
            with contextlib.suppress(psutil.Error):
                p.kill()


# -- workers die with their sweep -----------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("how", ["SIGKILL", "SIGTERM", "Ctrl-C"])
def test_no_process_is_left_five_seconds_after_a_killed_sweep(tmp_path, how):
    spec = {
        "base": BASE,
        "chunk_size": 8,
        "axes": [
            {
                "posture": {
                    "y": {"range": [-0.5, 0.0], "count": 12},
                    "z": {"range": [0.8, 1.2], "count": 12},
                }
            }
        ],
    }
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(spec))
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "impact_balance",
            "sweep",
            "s.yaml",
            "--out",
            "out",
            "--workers",
            "2",
            "--no-progress",
            "--no-plots",
        ],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": SRC},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    descendants: list[psutil.Process] = []
    try:
        command = psutil.Process(proc.pid)
        deadline = time.time() + 240
        while time.time() < deadline:  # running: the workers exist and a first part is written
            parts = tmp_path / "out" / "parts"
            if parts.is_dir() and any(p.name.startswith("part-") for p in parts.iterdir()):
                break
            assert proc.poll() is None, proc.stderr.read().decode()[-2000:]
            time.sleep(0.1)
        descendants = command.children(recursive=True)
        assert len(descendants) >= 2, descendants  # the two workers (and multiprocessing's helpers)
        if how == "SIGKILL":
            proc.send_signal(signal.SIGKILL)  # the workers must notice by themselves
        elif how == "SIGTERM":
            proc.send_signal(signal.SIGTERM)
        else:
            os.killpg(proc.pid, signal.SIGINT)  # what a terminal sends to the foreground group
        killed = time.time()
        proc.wait(timeout=30)
        _gone, alive = psutil.wait_procs(
            descendants, timeout=max(0.0, 5.0 - (time.time() - killed))
        )
        assert not [p for p in alive if p.status() != psutil.STATUS_ZOMBIE], (how, alive)
        assert time.time() - killed <= 5.0 + 0.5
        if how != "SIGKILL":
            assert proc.returncode == 130 and "interrupted" in proc.stderr.read().decode()
    finally:
        if proc.poll() is None:
            proc.kill()
        for p in descendants:
            with contextlib.suppress(psutil.Error):
                p.kill()


def test_a_fifo_named_as_sweep_file_or_part_is_named_never_waited_on(tmp_path):
    """A FIFO given as the sweep file is named for what it is (no open, no wait)."""
    import os

    from impact_balance.exceptions import SweepError
    from impact_balance.sweep.spec import sweep_path

    fifo = tmp_path / "sweep.yaml"
    os.mkfifo(fifo)
    with pytest.raises(SweepError, match="FIFO"):
        sweep_path(fifo)
    with pytest.raises(SweepError, match="a folder, not a regular file"):
        sweep_path(tmp_path)
