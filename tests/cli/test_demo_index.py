"""The demo's figure index: one line per figure, saying what it shows."""

from __future__ import annotations

from pathlib import Path

from impact_balance.cli.demo import DEMO_SCENARIOS, FIGURE_SUFFIXES, describe_figure, write_index


def test_every_figure_of_the_demo_is_described(tmp_path):
    names = [f"{s}{suffix}" for s in DEMO_SCENARIOS for suffix in FIGURE_SUFFIXES]
    names += ["friction_comparison.png", "phase_portrait.png"]
    lines = {name: describe_figure(name) for name in names}
    assert all(text != "figure" for text in lines.values())
    assert describe_figure("kick_one_foot_stance.png").startswith("kick_one_foot: ")
    assert describe_figure("unknown.png") == "figure"
    paths = [tmp_path / n for n in names]
    index = write_index(tmp_path, paths)
    assert index == tmp_path / "index.md"
    rows = [r for r in index.read_text().splitlines() if r.startswith("- [")]
    assert [r.split("]")[0][3:] for r in rows] == names  # in the order written
    for row, name in zip(rows, names, strict=True):
        assert row == f"- [{name}]({name}): {lines[name]}"
        assert Path(row.split("(")[1].split(")")[0]).name == name
