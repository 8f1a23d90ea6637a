"""The sweep evaluator takes analyze()'s path: the compiled posture where it answers (a stance's
areas, and its first point's impact model and criterion), the steps where it does not; its rows
are the steps' rows, and analyze()'s answers, to the last digit."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("pyarrow", reason="needs the logs or sweep extra (pyarrow)")

import pyarrow as pa

import impact_balance.sweep.evaluate as evaluate
from impact_balance import analyze
from impact_balance.analysis import analyze as pipeline
from impact_balance.scenario import load_scenario
from impact_balance.sweep import Evaluator, make_plan, sweep_spec_from_dict

PLANS = {
    "impact and CoM velocity": (
        "palm_push_two_feet",
        [
            {"path": "impact.friction", "values": [0.0, 0.3, 1.4]},  # 1.4: a refused model
            {"path": "impact.restitution[1]", "values": [0.0, 0.7]},
            {"path": "com_velocity[0]", "values": [0.0, 0.05, 0.4]},
        ],
    ),
    "stance dimensions": (
        "palm_push_two_feet",
        [
            {"path": "zmp_margin", "values": [0.0, 0.02, 0.3]},  # 0.3: no area left
            {"path": "velocity_margin", "values": [0.0, 0.03]},
            {"path": "contacts[0].friction", "values": [0.7, 1.3]},  # 1.3: the steps
        ],
    ),
    "inertia models": (
        "kick_one_foot",
        [
            {"path": "impact.inertia", "values": ["composite", "joint_space"]},
            {"path": "torque_limits", "values": [True, False]},
            {"direction": "impact.normal", "azimuth": {"values": [0.0, 40.0]}},
        ],
    ),
}


def _table(base, axes, chunk_size=5) -> pa.Table:
    plan = make_plan(sweep_spec_from_dict({"base": base, "axes": axes, "chunk_size": chunk_size}))
    ev = Evaluator(plan)
    return pa.concat_tables([ev.evaluate_chunk(c) for c in range(plan.n_chunks)])


@pytest.mark.parametrize("name", list(PLANS))
def test_rows_are_the_steps_rows_to_the_last_digit(name):
    base, axes = PLANS[name]
    compiled = _table(base, axes)
    with mock.patch.object(pipeline, "_compiled_posture", return_value=None):
        steps = _table(base, axes)
    assert compiled.num_rows > 0 and compiled.equals(steps)
    statuses = set(compiled.column("status").to_pylist())
    assert "ok" in statuses  # answers, not only errors


def test_the_compiled_posture_answers_a_stance_and_its_first_impact():
    """One stance, one impact, three CoM velocities: one compiled call, no impact model by the
    steps (the first point's is reused), no area by the steps."""
    axes = [{"path": "com_velocity[0]", "values": [0.0, 0.05, 0.4]}]
    answers = []

    def recorded(*args, **kwargs):
        answers.append(real(*args, **kwargs))
        return answers[-1]

    real = pipeline.posture_answer
    with (
        mock.patch.object(pipeline, "posture_answer", recorded),
        mock.patch.object(evaluate, "impact_model", wraps=evaluate.impact_model) as model,
        mock.patch.object(pipeline, "_stance_areas", wraps=pipeline._stance_areas) as areas,
    ):
        table = _table("palm_push_two_feet", axes)
    assert table.column("status").to_pylist() == ["ok", "ok", "already_falling"]
    assert len(answers) == 1 and answers[0] is not None
    assert model.call_count == 0 and areas.call_count == 0


def test_a_point_with_another_impact_takes_the_steps_model():
    axes = [{"path": "impact.friction", "values": [0.1, 0.2, 0.3]}]
    with mock.patch.object(evaluate, "impact_model", wraps=evaluate.impact_model) as model:
        table = _table("palm_push_two_feet", axes)
    assert model.call_count == 2  # the first point's is the compiled posture's
    assert table.column("status").to_pylist() == ["ok"] * 3


@settings(max_examples=8, deadline=None)
@given(
    frictions=st.lists(st.floats(0.0, 0.6), min_size=1, max_size=3, unique=True),
    vx=st.floats(-0.1, 0.1),
    margin=st.floats(0.0, 0.05),
)
def test_rows_are_analyze_answers_to_the_last_digit(frictions, vx, margin):
    base = load_scenario("palm_push_two_feet").replace(velocity_margin=margin)
    axes = [
        {"path": "impact.friction", "values": frictions},
        {"path": "com_velocity[0]", "values": [vx]},
    ]
    plan = make_plan(
        sweep_spec_from_dict(
            {"base": base.model_dump(mode="json", exclude={"source"}), "axes": axes}
        )
    )
    table = Evaluator(plan).evaluate_chunk(0)
    for row, mu in zip(table.to_pylist(), frictions, strict=True):
        cfg = base.impact
        assert cfg is not None
        scenario = base.replace(
            impact={**cfg.model_dump(exclude_unset=True), "friction": mu},
            com_velocity=(vx, float(base.com_velocity[1])),
        )
        ref = analyze(scenario)
        assert ref.impact is not None
        assert row["max_contact_velocity"] == ref.impact.com.max_contact_velocity
        assert row["zmp_max_contact_velocity"] == ref.impact.zmp.max_contact_velocity
        assert row["com_velocity_area"] == ref.areas.com_velocity_area.area
        np.testing.assert_array_equal(
            [row["impact_x"], row["impact_y"], row["impact_z"]], ref.impact.model.point
        )
