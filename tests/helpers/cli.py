"""Running ``impact-balance`` in tests: in process, in a real process, and checking its output.

One version of each helper, the strictest the tests need: an exception other than argparse's
``SystemExit`` escapes :func:`run_cli` (a traceback fails the test); :func:`run_process` runs
this worktree's sources (``PYTHONPATH`` is ``src``) without ``IMPACT_BALANCE_DEBUG`` unless the
test sets it; :func:`assert_one_line_error` wants exit status 2 and exactly one line
``impact-balance: error: ...``; :func:`strict_json` refuses NaN and Infinity.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

from impact_balance import cli

__all__ = ["SRC", "assert_one_line_error", "run_cli", "run_process", "strict_json"]

#: The worktree's sources, put first on the path of every child process.
SRC = str(Path(__file__).resolve().parents[2] / "src")


def run_cli(capsys: Any, *argv: str) -> tuple[int, str, str]:
    """``impact-balance ARGV`` in process: (exit status, stdout, stderr).

    argparse's usage errors (``SystemExit``, one line, status 2) give their status; any other
    exception escapes and fails the test.
    """
    try:
        rc = cli.main(list(argv))
    except SystemExit as exc:
        rc = int(exc.code) if exc.code is not None else 0
    out, err = capsys.readouterr()
    return rc, out, err


def run_process(
    *argv: str,
    exe: list[str] | None = None,
    cwd: Path | None = None,
    env: dict[str, str] | None = None,
    stdout: Any = subprocess.PIPE,
    timeout: float = 300,
) -> subprocess.CompletedProcess[str]:
    """``impact-balance ARGV`` in a child process (``python -m impact_balance`` unless ``exe``).

    The child imports this worktree's ``src``; ``IMPACT_BALANCE_DEBUG`` is removed from its
    environment unless ``env`` sets it. stderr is always captured, stdout unless ``stdout``
    says where it goes.
    """
    environ = {**os.environ, "PYTHONPATH": SRC, **(env or {})}
    if "IMPACT_BALANCE_DEBUG" not in (env or {}):
        environ.pop("IMPACT_BALANCE_DEBUG", None)
    return subprocess.run(
        [*(exe or [sys.executable, "-m", "impact_balance"]), *argv],
        cwd=cwd,
        env=environ,
        stdout=stdout,
        stderr=subprocess.PIPE,
        text=True,
        timeout=timeout,
    )


def assert_one_line_error(rc: int, err: str, *needles: str) -> str:
    """Exit status 2, no traceback, one line ``impact-balance: error: ...`` holding ``needles``."""
    assert rc == 2, f"exit status {rc}, stderr {err!r}"
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}: {err!r}"
    line = lines[0]
    assert line.startswith("impact-balance: error: "), line
    for needle in needles:
        assert needle in line, f"{needle!r} not in {line!r}"
    return line


def strict_json(text: str) -> Any:
    """``json.loads`` refusing NaN, Infinity and -Infinity (not JSON)."""

    def refuse(constant: str) -> Any:
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)
