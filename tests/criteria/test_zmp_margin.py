"""The ZMP margin: the ZMP support area shrunk by M, and the CoM velocity area and both criteria
with it."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from impact_balance import analyze, cli
from impact_balance.scenario import load_scenario
from tests.helpers.extras import needs_extra


def with_margin(name: str, margin: float):
    return load_scenario(name).model_copy(update={"zmp_margin": margin})


@pytest.mark.parametrize("name", ["palm_push_two_feet", "palm_push_ramp", "kick_one_foot"])
def test_areas_are_the_inset_of_the_unshrunk_ones(name):
    full = analyze(name)
    shrunk = analyze(with_margin(name, 0.01))
    a, b = full.areas, shrunk.areas
    assert b.zmp_margin == 0.01
    expected = a.zmp_area.inset(0.01)
    assert np.allclose(b.zmp_area.vertices, expected.vertices, atol=1e-12)
    assert np.allclose(b.zmp_area_without_margin.vertices, a.zmp_area.vertices, atol=1e-12)
    # Every ZMP of the shrunk area is 1 cm inside the full one, and the CoM velocity area is omega
    # (Z - c).
    assert np.all(a.zmp_area.margins(b.zmp_area.vertices) >= 0.01 - 1e-12)
    c = b.com[:2]
    assert np.allclose(
        b.com_velocity_area.vertices, b.omega * (b.zmp_area.vertices - c), atol=1e-12
    )


def test_both_criteria_fall_as_the_margin_grows():
    com, zmp = [], []
    for margin in (0.0, 0.005, 0.01, 0.02, 0.04):
        im = analyze(with_margin("palm_push_two_feet", margin)).impact
        com.append(im.max_contact_velocity)
        zmp.append(im.zmp_max_contact_velocity)
    assert all(x > y for x, y in itertools.pairwise(com))
    assert all(x > y for x, y in itertools.pairwise(zmp))


def test_a_margin_larger_than_the_area_is_an_answer():
    a = analyze(with_margin("palm_push_two_feet", 0.5))
    assert not a.areas.can_balance
    assert a.cannot_balance_reason.kind == "zmp_margin"
    assert "0.5 m" in a.cannot_balance_reason.message
    json.loads(json.dumps(a.to_dict(), allow_nan=False))


def test_cli_option_overrides_the_scenario(capsys):
    assert cli.main(["analyze", "palm_push_two_feet", "--zmp-margin", "0.01", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["zmp_margin"] == 0.01
    assert out["impact"]["max_contact_velocity"] == pytest.approx(
        analyze(with_margin("palm_push_two_feet", 0.01)).impact.max_contact_velocity, rel=1e-12
    )
    assert cli.main(["analyze", "palm_push_two_feet", "--zmp-margin", "-0.1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--zmp-margin = -0.1" in err


@needs_extra("sweep")
def test_sweep_axis_over_the_margin():
    import pyarrow as pa

    from impact_balance.sweep import Evaluator, make_plan, sweep_spec_from_dict

    plan = make_plan(
        sweep_spec_from_dict(
            {
                "base": "palm_push_two_feet",
                "axes": [{"path": "zmp_margin", "values": [0.0, 0.01, 0.02]}],
            }
        )
    )
    ev = Evaluator(plan)
    df = pa.concat_tables([ev.evaluate_chunk(c) for c in range(plan.n_chunks)]).to_pandas()
    for _, r in df.iterrows():
        expected = analyze(
            with_margin("palm_push_two_feet", float(r["zmp_margin"]))
        ).impact.max_contact_velocity
        assert r["max_contact_velocity"] == pytest.approx(expected, rel=1e-12)


def test_gui_edit_of_the_margin(tmp_path):
    from impact_balance.gui import Session, svg_view

    session = Session("palm_push_two_feet", workspace=tmp_path)
    before = session.analysis.impact.max_contact_velocity
    assert session.set(("zmp_margin",), 0.01)
    assert session.analysis.areas.zmp_margin == 0.01
    assert session.analysis.impact.max_contact_velocity < before
    assert "shrunk by 1 cm" in svg_view(session.analysis)
    assert not session.set(("zmp_margin",), -1.0)  # refused with a message, state kept
    assert session.analysis.areas.zmp_margin == 0.01


@pytest.mark.parametrize(
    "name, margin", [("palm_push_ramp", 0.01), ("kick_one_foot", 0.02), ("kick_one_foot", 0.5)]
)
def test_com_velocity_area_inset_is_the_area_analyze_gives_with_that_margin(name, margin):
    """The plots' and the governor's dashed outline is the area of the scenario with that margin."""
    plain = analyze(name).areas.com_velocity_area_inset(margin)
    margined = analyze(
        load_scenario(name).model_copy(update={"zmp_margin": margin})
    ).areas.com_velocity_area
    assert plain.is_empty == margined.is_empty
    if not plain.is_empty:
        np.testing.assert_allclose(plain.vertices, margined.vertices, atol=1e-12)
