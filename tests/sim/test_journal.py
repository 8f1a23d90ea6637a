"""Trial journals: every line carries its digest and checksum; a damaged, foreign, edited or
unknown line is named and its trial runs again; only regular files, read with a bound."""

from __future__ import annotations

import json
import os
import threading

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.exceptions import EnvironmentFailure, SimulationError
from impact_balance.sim.studies import journal as journal_module
from impact_balance.sim.studies.journal import TrialJournal
from tests.helpers.cli import assert_one_line_error, run_cli

BALANCED = {"summary": {"outcome": "balanced", "x": 1.5}, "trajectory": {"time": [0.0]}}
FELL = {"summary": {"outcome": "fell"}, "trajectory": {}}


def _journal(path, digest="d", entries=((0.25, BALANCED), (0.5, FELL))):
    journal = TrialJournal.open(path, digest, {"command": "validate"})
    for speed, entry in entries:
        journal.add({"speed": speed}, entry)
    journal.close()
    return path


def _lines(path):
    return path.read_text().splitlines()


def _rewrite(path, number, line):
    lines = _lines(path)
    lines[number - 1] = line
    path.write_text("\n".join(lines) + "\n")


def test_every_line_carries_the_digest_and_a_checksum(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    records = [json.loads(line) for line in _lines(path)]
    assert all(r["digest"] == "d" and len(r["checksum"]) == 64 for r in records)
    again = TrialJournal.open(path, "d")
    assert again.get({"speed": 0.25}) == BALANCED and again.get({"speed": 0.5}) == FELL
    assert again.skipped_lines == 0 and again.problems == []
    again.close()


def test_an_edited_outcome_is_named_and_not_reused(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    _rewrite(path, 2, _lines(path)[1].replace('"balanced"', '"fell"'))
    again = TrialJournal.open(path, "d")
    assert again.get({"speed": 0.25}) is None and again.get({"speed": 0.5}) == FELL
    assert again.problems == [
        "line 2: checksum does not match (damaged or edited); its trial runs again"
    ]
    again.close()


def test_an_unknown_outcome_is_named_even_with_a_matching_checksum(tmp_path):
    path = _journal(
        tmp_path / "j.jsonl", entries=[(0.25, {"summary": {"outcome": "bogus"}, "trajectory": {}})]
    )
    again = TrialJournal.open(path, "d")
    assert again.entries == {} and "unknown outcome 'bogus'" in again.problems[0]
    again.close()


def test_a_foreign_journal_behind_a_damaged_header_is_not_reused(tmp_path):
    path = _journal(tmp_path / "j.jsonl", digest="two_feet")
    _rewrite(path, 1, "xx")
    again = TrialJournal.open(path, "ramp")
    assert again.entries == {} and again.skipped_lines == 3
    assert "not a journal header" in again.problems[0]
    assert all("another scenario" in p for p in again.problems[1:])
    again.add({"speed": 0.25}, BALANCED)  # the trial ran again: kept, and reused next time
    again.close()
    third = TrialJournal.open(path, "ramp")
    assert third.get({"speed": 0.25}) == BALANCED
    third.close()


@pytest.mark.parametrize("header", ["[1, 2]", "3", '"text"', "null", "{}", "1e999", "[[[["])
def test_a_header_that_is_not_an_object_is_damage_not_an_internal_error(tmp_path, header):
    path = _journal(tmp_path / "j.jsonl")
    _rewrite(path, 1, header)
    again = TrialJournal.open(path, "d")
    assert len(again.entries) == 2 and "not a journal header" in again.problems[0]
    again.close()


def test_a_readable_header_of_another_digest_refuses_the_file(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    with pytest.raises(SimulationError, match="digest"):
        TrialJournal.open(path, "another")


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    line=st.one_of(
        st.text(max_size=40),
        st.builds(
            json.dumps,
            st.recursive(
                st.none() | st.booleans() | st.floats() | st.text(max_size=5),
                lambda c: (
                    st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=5), c, max_size=3)
                ),
                max_leaves=8,
            ),
        ),
    )
)
def test_any_damaged_line_is_named_never_reused_nor_an_error(tmp_path_factory, line):
    path = _journal(tmp_path_factory.mktemp("j") / "j.jsonl")
    lines = _lines(path)
    path.write_text(
        "\n".join([*lines[:2], line.replace("\n", " ").replace("\r", " "), lines[2]]) + "\n"
    )
    again = TrialJournal.open(path, "d")
    assert len(again.entries) == 2
    if line.strip():
        assert again.skipped_lines == 1 and again.problems[0].startswith("line 3: ")
    again.close()


def test_a_fifo_journal_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "j.jsonl"
    os.mkfifo(fifo)
    outcome = []
    worker = threading.Thread(target=lambda: outcome.append(_try_open(fifo)), daemon=True)
    worker.start()
    worker.join(5)
    assert not worker.is_alive(), "opening a FIFO journal blocked"
    assert "not a regular file" in outcome[0]


def test_a_link_to_dev_zero_is_refused(tmp_path):
    link = tmp_path / "j.jsonl"
    link.symlink_to("/dev/zero")
    assert "not a regular file" in _try_open(link)


def test_a_journal_larger_than_the_bound_is_refused(tmp_path, monkeypatch):
    path = _journal(tmp_path / "j.jsonl")
    monkeypatch.setattr(journal_module, "MAX_JOURNAL_BYTES", 100)
    assert "larger than 100 bytes" in _try_open(path)


def _try_open(path):
    try:
        TrialJournal.open(path, "d").close()
    except SimulationError as exc:
        return str(exc)
    return "opened"


def test_a_full_disk_names_the_journal(tmp_path, monkeypatch):
    journal = TrialJournal.open(tmp_path / "j.jsonl", "d")

    def full(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(journal_module.os, "fsync", full)
    with pytest.raises(
        EnvironmentFailure, match=r"--journal = .*j\.jsonl.*: No space left on device"
    ) as info:
        journal.add({"speed": 0.25}, BALANCED)
    assert info.value.exit_status == 1
    journal.close()


def test_a_cut_last_line_is_ended_before_the_next_trial(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    with open(path, "a") as fh:
        fh.write('{"digest": "d", "key": {"speed": 0.3')
    again = TrialJournal.open(path, "d")
    assert again.skipped_lines == 1 and "not JSON" in again.problems[0]
    again.add({"speed": 0.375}, FELL)
    again.close()
    third = TrialJournal.open(path, "d")
    assert len(third.entries) == 3 and third.skipped_lines == 1
    third.close()


@pytest.mark.parametrize("command", ["validate", "push-test"])
def test_the_commands_refuse_a_fifo_journal_in_one_line(tmp_path, capsys, command):
    fifo = tmp_path / "j.jsonl"
    os.mkfifo(fifo)
    rc, _, err = run_cli(capsys, command, "palm_push_two_feet", "--journal", str(fifo))
    err = "".join(line for line in err.splitlines(True) if "compiling" not in line)
    assert_one_line_error(rc, err, "--journal", "not a regular file")


def _push(capsys, scenario, journal):
    argv = ["push-test", scenario, "--controller", "ik", "--directions", "2", "--magnitudes", "5"]
    rc, out, err = run_cli(capsys, *argv, "--json", "--journal", str(journal))
    assert rc == 0, err
    return json.loads(out), err


@pytest.mark.slow
def test_push_test_never_reuses_another_scenarios_trials_behind_a_damaged_header(tmp_path, capsys):
    journal = tmp_path / "j.jsonl"
    first, _ = _push(capsys, "palm_push_two_feet", journal)
    assert first["reused_trials"] == 0
    _rewrite(journal, 1, "xx")  # the header cut by a full disk
    ramp, err = _push(capsys, "palm_push_ramp", journal)
    assert ramp["reused_trials"] == 0
    named = [line for line in err.splitlines() if "--journal" in line]
    assert any("line 1: not a journal header" in line for line in named)
    assert sum("another scenario" in line for line in named) == 2
    # an edited outcome is named and rerun; the untouched trial is reused
    lines = _lines(journal)
    _rewrite(journal, len(lines), lines[-1].replace('"balanced"', '"fell"'))
    again, err = _push(capsys, "palm_push_ramp", journal)
    assert again["reused_trials"] == 1 and "checksum does not match" in err
    assert [p["outcome"] for p in again["pushes"]] == [p["outcome"] for p in ramp["pushes"]]
