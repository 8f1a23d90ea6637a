"""``approach --contact-aware-async`` with its worker killed mid-run: one line naming
``contact_aware_async`` and exit 1 (a failure of the machine), never 141 (SIGPIPE) in silence,
and no process left behind."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")


def workers_of(pid: int) -> list[int]:
    """The contact-aware worker processes whose parent is ``pid``."""
    found = []
    for proc in Path("/proc").glob("[0-9]*"):
        try:
            if b"impact_balance.governor.worker" not in (proc / "cmdline").read_bytes():
                continue
            parent = int((proc / "stat").read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):  # a process that ended while we looked
            continue
        if parent == pid:
            found.append(int(proc.name))
    return found


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc (Linux)")
def test_a_killed_worker_ends_approach_with_one_line_and_status_1():
    argv = [
        sys.executable,
        "-m",
        "impact_balance",
        "approach",
        "palm_push_two_feet",
        "--reference",
        "0.01",  # a slow approach (15 s of simulated ticks): the kill falls inside it
        "--contact-aware",
        "--contact-aware-async",
        "--max-time",
        "30",
    ]
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120.0
        found: list[int] = []
        while not found and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.2)
            found = workers_of(process.pid)
        assert found, "the worker process never started"
        time.sleep(2.0)  # into the approach, the governor ticking
        os.kill(found[0], signal.SIGKILL)
        _, err = process.communicate(timeout=300)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == 1, (process.returncode, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "contact_aware_async" in lines[0] and "ended" in lines[0], err
    assert "Traceback" not in err and workers_of(process.pid) == []
