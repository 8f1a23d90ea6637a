"""``check-log`` reads a log through one checked descriptor, only the columns it uses, with the
uncompressed size of each read Parquet column bounded from the footer before reading.

- an unused column is never read (a 2 MB dictionary string repeated on every row: a small file
  that would unpack into hundreds of MB);
- a used column whose uncompressed size is beyond a column of numbers is refused from the
  footer, named;
- a FIFO or a folder named as the log is refused at once;
- the peak memory of reading such a file stays under 500 MB;
- the read starts no thread (Arrow's reader threads can abort the process at exit).
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading

import numpy as np
import pytest

pytest.importorskip("pyarrow", reason="needs the logs extra (pyarrow)")

import pyarrow as pa
import pyarrow.parquet as pq

from impact_balance.exceptions import ScenarioError
from impact_balance.logs import read_log
from impact_balance.logs.io import MAX_LOG_COLUMN_BYTES_PER_ROW
from tests.helpers.cli import SRC, assert_one_line_error, run_cli
from tests.helpers.logs import SCENARIO, synthetic_log

PAD = 2 << 20  # one 2 MB string


@pytest.fixture(scope="module")
def log_frame():
    frame, _, _ = synthetic_log(np.array([0.01, 0.0, 0.0]), T=0.4, rate=500.0)
    return frame


def _padded(frame, path, column="padding", dictionary=True):
    """``frame`` and a string column ``column``: ~PAD bytes on every row, compressed small."""
    table = pa.Table.from_pandas(frame, preserve_index=False)
    rows = table.num_rows
    if dictionary:
        pad = pa.DictionaryArray.from_arrays(
            pa.array(np.zeros(rows, dtype=np.int32)), pa.array(["a" * PAD])
        )
    else:
        pad = pa.array(["a" * (PAD // rows)] * rows)
    if column in table.column_names:
        table = table.set_column(table.column_names.index(column), column, pad)
    else:
        table = table.append_column(column, pad)
    # Without the Arrow schema, a reader gets plain strings: the dictionary is unpacked per row.
    pq.write_table(table, path, compression="zstd", use_dictionary=dictionary, store_schema=False)
    return path


def test_an_unused_column_is_never_read(tmp_path, log_frame):
    path = _padded(log_frame, tmp_path / "padded.parquet")
    assert path.stat().st_size < 2 << 20  # a small file (would unpack to rows x 2 MB)
    frame = read_log(path)
    assert "padding" not in frame.columns
    assert list(frame.columns) == list(log_frame.columns)
    assert np.array_equal(frame["time"].to_numpy(), log_frame["time"].to_numpy())


def test_a_used_column_too_large_once_uncompressed_is_refused_from_the_footer(tmp_path, log_frame):
    path = _padded(log_frame, tmp_path / "zmp.parquet", column="zmp_x", dictionary=False)
    with pytest.raises(ScenarioError, match=r"column zmp_x: .* bytes once uncompressed") as info:
        read_log(path)
    assert f"at most {MAX_LOG_COLUMN_BYTES_PER_ROW} a row" in info.value.reason


def test_unused_csv_columns_are_left_out(tmp_path, log_frame):
    frame = log_frame.copy()
    frame["note"] = "free text, never read"
    frame.to_csv(tmp_path / "log.csv", index=False)
    read = read_log(tmp_path / "log.csv")
    assert "note" not in read.columns and list(read.columns) == list(log_frame.columns)


@pytest.mark.parametrize("kind", ["fifo", "folder"])
def test_a_log_that_is_not_a_regular_file_is_refused_at_once(tmp_path, capsys, kind):
    path = tmp_path / "log.csv"
    os.mkfifo(path) if kind == "fifo" else path.mkdir()
    out: dict[str, object] = {}

    def run():
        out["result"] = run_cli(capsys, "check-log", str(path), "--scenario", SCENARIO, "--json")

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(30)
    assert not thread.is_alive(), "check-log waits on the file"
    rc, stdout, err = out["result"]
    assert_one_line_error(rc, err, "log.csv", "FIFO" if kind == "fifo" else "a folder")
    assert stdout == ""


def _child(script: str, path, tag: str) -> list[int]:
    """Run ``script`` on ``path`` in a fresh interpreter; the integers it prints after ``tag``."""
    proc = subprocess.run(
        [sys.executable, "-c", script, str(path)],
        env={**os.environ, "PYTHONPATH": SRC},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return [int(x) for x in proc.stdout.split(tag)[1].split()]


READ = r"""
import resource, sys
from impact_balance.logs import read_log
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
frame = read_log(sys.argv[1])
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("PEAK_KB", before, after, len(frame.columns))
"""


@pytest.mark.slow
def test_reading_a_padded_parquet_stays_under_500_mb(tmp_path, log_frame):
    """A 30 kB log that unpacks to 400 MB of strings: read in a few MB (1 GB before).

    The growth of the reader's peak is measured: the imports alone take ~370 MB standalone
    (more when run amid the suite), which is not the log's doing; 100 MB of growth keeps the
    whole under 500 MB.
    """
    path = _padded(log_frame, tmp_path / "padded.parquet")
    before, after, columns = _child(READ, path, "PEAK_KB")
    assert columns == len(log_frame.columns)
    print(f"peak {before / 1024:.0f} MB after the imports, {after / 1024:.0f} MB after the read")
    assert after - before < 100 * 1024, f"reading grew the peak by {(after - before) / 1024:.0f} MB"


THREADS = r"""
import os, sys
from impact_balance.logs import read_log
threads = lambda: len(os.listdir("/proc/self/task"))
before = threads()
read_log(sys.argv[1])
print("THREADS", before, threads())
"""


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="counts threads in /proc")
def test_reading_a_parquet_log_starts_no_thread(tmp_path, log_frame):
    """No reader thread is left to run at exit (apache/arrow#34314: SIGABRT at interpreter exit)."""
    path = tmp_path / "log.parquet"
    pq.write_table(pa.Table.from_pandas(log_frame, preserve_index=False), path)
    before, after = _child(THREADS, path, "THREADS")
    assert after == before
