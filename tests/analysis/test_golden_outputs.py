"""`analyze --json --qp` of every bundled scenario, number for number, against the recorded outputs.

The files in ``tests/analysis/data/analyze_golden/`` were written by the command before the
package's redesign; a change that moves a number, a key or a status shows here. ``timings_ms``
is left out (it measures the machine). To record a deliberate change, rerun the command and
review the diff of the data files.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from impact_balance import cli
from impact_balance.scenario import bundled_scenarios

GOLDEN = Path(__file__).parent / "data" / "analyze_golden"


def test_every_bundled_scenario_has_a_recorded_output():
    assert sorted(p.stem for p in GOLDEN.glob("*.json")) == sorted(bundled_scenarios())


@pytest.mark.parametrize("name", sorted(bundled_scenarios()))
def test_analyze_json_is_unchanged(name, capsys):
    assert cli.main(["analyze", name, "--json", "--qp"]) == 0
    out = json.loads(capsys.readouterr().out)
    out.pop("timings_ms")
    expected = json.loads((GOLDEN / f"{name}.json").read_text())
    assert out == expected
