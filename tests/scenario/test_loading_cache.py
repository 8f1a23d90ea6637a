"""Loading caches of scenarios and robots: fast repeated loads that never serve stale or shared
mutable data, and printed timings that say what they measure."""

from __future__ import annotations

import os
import shutil

import impact_balance as ib
from impact_balance.analysis.report import format_timings
from impact_balance.robot.robot import example_robot_data_root
from impact_balance.scenario import load_scenario
from impact_balance.scenario.reader import parse_yaml as _parse

SIMPLE = example_robot_data_root() / "simple_humanoid_description"


def test_parse_cache_hands_out_copies():
    text = "a: {b: [1, 2]}\nc: 3\n"
    first = _parse(text)
    first["a"]["b"].append(99)
    first["c"] = 0
    assert _parse(text) == {"a": {"b": [1, 2]}, "c": 3}


def test_edited_scenario_file_is_reloaded(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("extends: palm_push_two_feet\ncom_velocity: [0.1, 0.0]\n")
    assert load_scenario(path).com_velocity == (0.1, 0.0)
    path.write_text("extends: palm_push_two_feet\ncom_velocity: [0.2, 0.0]\n")
    assert load_scenario(path).com_velocity == (0.2, 0.0)


def test_robot_file_cache_follows_the_file(tmp_path):
    urdf = tmp_path / "robot.urdf"
    shutil.copy(SIMPLE / "urdf" / "simple_humanoid.urdf", urdf)
    first = ib.load_robot(None, urdf)
    assert ib.load_robot(None, urdf) is first  # cached
    stat = urdf.stat()
    os.utime(urdf, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))  # touched, same bytes
    assert ib.load_robot(None, urdf) is first  # the cache follows the content, not the time
    urdf.write_text(urdf.read_text() + "\n<!-- edited -->\n")
    assert ib.load_robot(None, urdf) is not first


def test_timings_say_what_they_measure():
    analysis = ib.analyze("palm_push_two_feet")
    t = analysis.timings
    assert {"scenario_loading", "robot_loading", "total"} <= set(t)
    steps = sum(t[k] for k in ("stance", "constraints", "areas", "impact"))
    assert t["total"] >= steps  # the analysis only: loading is apart
    text = format_timings(
        {"total": 0.0008, "scenario_loading": 0.0003, "robot_loading": 0.25, "kernel_loading": 0.4}
    )
    assert text.startswith("analysis 0.8 ms; not included: scenario loading 0.3 ms")
    assert (
        "robot model loading 250 ms (first use)" in text
        and "kernel loading 400 ms (first call)" in text
    )
    assert format_timings({"total": 0.0008, "robot_loading": 1e-6}) == "analysis 0.8 ms"


def test_scenario_cache_follows_every_file_of_the_chain(tmp_path):
    """The validated scenario is cached by the text of each file of its extends chain: the same
    object while nothing changed; a new one when the file or its parent changes, even with the
    same size and modification time."""
    parent, child = tmp_path / "parent.yaml", tmp_path / "child.yaml"
    parent.write_text("extends: palm_push_two_feet\ncom_velocity: [0.1, 0.0]\n")
    child.write_text("extends: parent.yaml\nplane_height: 0.0\n")
    first = load_scenario(child)
    assert load_scenario(child) is first and first.com_velocity == (0.1, 0.0)
    stat = parent.stat()
    parent.write_text("extends: palm_push_two_feet\ncom_velocity: [0.2, 0.0]\n")  # same size
    os.utime(parent, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # and the same time stamp
    second = load_scenario(child)
    assert second is not first and second.com_velocity == (0.2, 0.0)
    # A broken parent is reported as before (the cache never hides an error).
    parent.write_text("extends: palm_push_two_feet\ncom_velocity: [0.2]\n")
    import pytest

    with pytest.raises(ib.ScenarioError, match="com_velocity"):
        load_scenario(child)


def test_bundled_name_and_loaded_scenario_analyse_alike():
    by_name = ib.analyze("palm_push_ramp")
    loaded = ib.analyze(ib.load_scenario("palm_push_ramp"))
    assert ib.load_scenario("palm_push_ramp") is ib.load_scenario("palm_push_ramp")
    assert (
        by_name.to_dict()["impact"]["max_contact_velocity"]
        == loaded.to_dict()["impact"]["max_contact_velocity"]
    )
