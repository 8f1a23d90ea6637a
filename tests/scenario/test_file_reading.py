"""Scenario files are read once, by the one file-reading rule, and parsed from the bytes read.

- each file of an ``extends`` chain is read exactly once per load, and the scenario cache is
  keyed on the digests of those bytes: a file rewritten between two loads (or during one) never
  maps its new content to the old scenario;
- a FIFO, a device or a folder named as a scenario is refused at once;
- a key repeated in a mapping is refused, naming the key and its lines (scenario and sweep
  files, with or without ``--strict``); a mapping of more than ``MAX_KEYS`` keys is refused
  while it is composed.
"""

from __future__ import annotations

import os
import threading
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import ScenarioError
from impact_balance.scenario import load, load_scenario
from impact_balance.scenario.reader import MAX_KEYS, parse_yaml
from tests.helpers.cli import assert_one_line_error, run_cli
from tests.helpers.extras import needs_extra

BASE = "extends: palm_push_two_feet\nimpact:\n  friction: {mu}\n"


def test_each_file_of_the_chain_is_read_once(tmp_path, monkeypatch):
    (tmp_path / "parent.yaml").write_text("extends: palm_push_two_feet\nplane_height: 0.01\n")
    (tmp_path / "child.yaml").write_text("extends: parent.yaml\ncom_velocity: [0.1, 0.0]\n")
    reads: list[str] = []
    original = load.read_text

    def counting(path):
        reads.append(os.path.basename(path))
        return original(path)

    monkeypatch.setattr(load, "read_text", counting)
    scenario = load_scenario(tmp_path / "child.yaml")
    assert scenario.plane_height == 0.01 and scenario.com_velocity == (0.1, 0.0)
    assert reads == ["child.yaml", "parent.yaml", "palm_push_two_feet.yaml"]


def test_a_file_rewritten_between_reads_never_maps_to_the_old_scenario(tmp_path, monkeypatch):
    """The race of issue 30: the key from one read, the scenario from another. Simulated: the
    reader returns the file's content alternating 0.4 and 0.2 on every call."""
    path = tmp_path / "race.yaml"
    path.write_text(BASE.format(mu=0.4))
    contents = [BASE.format(mu=mu) for mu in (0.4, 0.2)]
    calls = {"n": 0}
    original = load.read_text

    def rewritten(p):
        if os.path.basename(p) != "race.yaml":
            return original(p)
        text = contents[calls["n"] % 2]
        calls["n"] += 1
        return text

    monkeypatch.setattr(load, "read_text", rewritten)
    seen = []
    for _ in range(6):
        before = calls["n"]
        scenario = load_scenario(path)
        assert calls["n"] == before + 1  # one read per load
        expected = 0.4 if before % 2 == 0 else 0.2
        seen.append(scenario.impact.friction)
        assert scenario.impact.friction == expected  # what was read is what was parsed
    assert seen == [0.4, 0.2] * 3  # and the cache never mixes them


def test_the_cache_follows_the_bytes_of_every_file_of_the_chain(tmp_path):
    parent = tmp_path / "parent.yaml"
    child = tmp_path / "child.yaml"
    child.write_text("extends: parent.yaml\nplane_height: 0.02\n")
    for mu in (0.4, 0.2, 0.4):
        parent.write_text(BASE.format(mu=mu))
        assert load_scenario(child).impact.friction == mu


def test_a_fifo_scenario_is_refused_at_once(tmp_path, capsys):
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    (tmp_path / "child.yaml").write_text("extends: pipe.yaml\n")
    for name in ("pipe.yaml", "child.yaml"):
        done: dict[str, object] = {}

        def run(name=name, done=done):
            try:
                load_scenario(tmp_path / name)
            except ScenarioError as exc:
                done["error"] = exc

        thread = threading.Thread(target=run, daemon=True)
        thread.start()
        thread.join(5)
        assert not thread.is_alive(), f"{name}: the load waited on a FIFO"
        assert "FIFO" in str(done["error"])
    rc, out, err = run_cli(capsys, "analyze", str(fifo), "--json")
    assert_one_line_error(rc, err, "pipe.yaml", "FIFO")
    assert out == ""


# -- duplicate keys and key counts ----------------------------------------------------------
def test_a_duplicated_key_is_refused_with_its_line(tmp_path, capsys):
    path = tmp_path / "dup.yaml"
    path.write_text("extends: palm_push_two_feet\ngravity: 9.81\ngravity: 1.0\n")
    for extra in ((), ("--strict",)):
        rc, out, err = run_cli(capsys, "analyze", str(path), "--json", *extra)
        assert_one_line_error(rc, err, "dup.yaml", "duplicate key 'gravity'", "line 3")
        assert out == ""
    with pytest.raises(ScenarioError, match="duplicate key 'friction' at line 4"):
        parse_yaml("impact:\n  friction: 0.4\n  restitution: [0, 0]\n  friction: 0.2\n")
    with pytest.raises(ScenarioError, match="duplicate key 'x' at line 1"):
        parse_yaml("a: {x: 1, x: 2}\n")  # a flow mapping, one line
    # Not duplicates: equal keys in different mappings, a merge key overridden.
    assert parse_yaml("a: {x: 1}\nb: {x: 1}\n") == {"a": {"x": 1}, "b": {"x": 1}}
    assert parse_yaml("a: &a {x: 1}\nb:\n  <<: *a\n  x: 2\n")["b"] == {"x": 2}


@needs_extra("sweep")
def test_a_duplicated_key_in_a_sweep_file_is_refused(tmp_path):
    from impact_balance.exceptions import SweepError
    from impact_balance.sweep.spec import load_sweep_spec

    path = tmp_path / "s.yaml"
    path.write_text("base: palm_push_two_feet\nseed: 1\nseed: 2\n")
    with pytest.raises(SweepError, match="duplicate key 'seed' at line 3"):
        load_sweep_spec(path)


@settings(max_examples=30, deadline=None)
@given(
    keys=st.lists(
        st.text("abcdefghij_", min_size=1, max_size=8), min_size=1, max_size=8, unique=True
    ),
    data=st.data(),
)
def test_any_repeated_key_is_refused_and_distinct_keys_are_kept(keys, data):
    lines = [f"{k}: {i}" for i, k in enumerate(keys)]
    assert parse_yaml("\n".join(lines) + "\n") == {k: i for i, k in enumerate(keys)}
    again = data.draw(st.sampled_from(keys))
    where = data.draw(st.integers(0, len(lines)))
    text = "\n".join([*lines[:where], f"{again}: 99", *lines[where:]]) + "\n"
    with pytest.raises(ScenarioError, match=f"duplicate key '{again}'"):
        parse_yaml(text)


def test_a_mapping_of_too_many_keys_is_refused_while_composed():
    text = "\n".join(f"k{i}: 1" for i in range(60_000)) + "\n"  # ~0.5 MB
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError, match=f"more than {MAX_KEYS} keys"):
        parse_yaml(text)
    assert time.perf_counter() - t0 < 2.0
    assert len(parse_yaml("\n".join(f"k{i}: 1" for i in range(MAX_KEYS)) + "\n")) == MAX_KEYS
