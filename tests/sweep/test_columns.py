"""Statuses and verdicts written to sweep files: their values and order are the format."""

from __future__ import annotations

import pytest

pytest.importorskip("pyarrow", reason="needs the sweep extra (pyarrow)")

import pyarrow as pa

from impact_balance.sweep.columns import EVALUATED, RESULT_COLUMNS, STATUSES, VERDICTS
from impact_balance.sweep.summary import EVALUATED as SUMMARY_EVALUATED


def test_statuses_as_written_in_the_files():
    assert STATUSES == (
        "ok",
        "unbounded",
        "already_falling",
        "cannot_balance",
        "invalid",
        "unreachable",
        "error",
    )
    assert EVALUATED == STATUSES[:4]
    assert SUMMARY_EVALUATED is EVALUATED


def test_verdicts_as_written_in_the_files():
    assert VERDICTS == ("balanced", "falling", "cannot balance")


def test_status_and_verdict_columns_are_strings():
    types = {name: typ for name, typ, _ in RESULT_COLUMNS}
    assert types["status"] == pa.string() and types["verdict"] == pa.string()
