"""The held-stance maximum contact velocity: the ray of each bound's jump against the area's
half-planes (computed here from the contact-aware model directly), the model run at the answer
reaching the boundary, the fallback to the paper's answer, and its refusals."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from impact_balance import analyze, load_scenario
from impact_balance.analysis.held_stance import HeldStanceLimit, held_stance_max_contact_velocity
from impact_balance.exceptions import ImpactModelError
from impact_balance.impact.contact_aware import contact_impact
from tests.helpers.held_stance import NOT_CONVERGING, ray


@pytest.mark.parametrize(
    ("name", "changes"),
    [
        ("palm_push_two_feet", {}),
        ("g1_two_feet", {"zmp_margin": 0.01}),
        ("jvrc1_kick_one_foot", {"restitution": (0.15, 0.4)}),
        ("palm_push_ramp", {"velocity_margin": 0.02, "com_velocity": (0.03, -0.02)}),
    ],
)
def test_the_answer_is_the_smallest_ray_of_the_two_bounds(name, changes):
    scenario = load_scenario(name)
    if "restitution" in changes:
        impact = scenario.impact.model_copy(update={"restitution": changes.pop("restitution")})
        scenario = scenario.model_copy(update={"impact": impact})
    analysis = analyze(scenario.replace(**changes))
    assert analysis.com_velocity_inside
    answer = held_stance_max_contact_velocity(analysis)
    assert answer.converged and not answer.fell_back and answer.status == "ok"

    spec = analysis.impact.model.spec
    G, h = analysis.areas.com_velocity_area.halfplanes
    h = h - analysis.scenario.velocity_margin
    c0 = analysis.com_velocity[:2]
    rays = {}
    for c in spec.restitution:
        jump = contact_impact(analysis.stance, spec, 1.0, restitution=float(c)).com_velocity_jump
        rays[float(c)] = ray(G, h, c0, jump)
    assert answer.restitution == tuple(float(c) for c in spec.restitution)
    assert answer.max_contact_velocity == pytest.approx(min(rays.values()), rel=1e-9)
    assert answer.binding_restitution == min(rays, key=rays.get)

    # The model itself, run at the answer (and a little faster), reaches the boundary there.
    c = answer.binding_restitution
    s = answer.max_contact_velocity
    at = c0 + contact_impact(analysis.stance, spec, s, restitution=c).com_velocity_jump
    past = c0 + contact_impact(analysis.stance, spec, 1.01 * s, restitution=c).com_velocity_jump
    assert float(np.max(G @ at - h)) == pytest.approx(0.0, abs=1e-8)
    assert float(np.max(G @ past - h)) > 1e-6


def test_a_fixed_point_not_reached_falls_back_to_the_papers_answer():
    scenario = load_scenario(NOT_CONVERGING).replace(zmp_margin=0.01, com_velocity=(0.0, 0.0))
    analysis = analyze(scenario)
    answer = held_stance_max_contact_velocity(analysis)
    assert not answer.converged and answer.fell_back
    assert answer.binding_restitution is None
    assert answer.max_contact_velocity == analysis.impact.max_contact_velocity
    assert answer.status == analysis.impact.status
    # The last iterates alone would answer something else (much faster: optimistic there).
    own = min(
        ray(*analysis.areas.com_velocity_area.halfplanes, np.zeros(2), j) for j in answer.jumps
    )
    assert own > 5 * answer.max_contact_velocity


def test_too_few_iterations_fall_back_and_enough_do_not():
    analysis = analyze("palm_push_two_feet")
    paper = analysis.impact.max_contact_velocity
    cut = held_stance_max_contact_velocity(analysis, max_iterations=1)
    full = held_stance_max_contact_velocity(analysis)
    assert cut.fell_back and not cut.converged and cut.max_contact_velocity == paper
    assert full.converged and not full.fell_back
    assert abs(full.max_contact_velocity - paper) > 0.01  # the two models differ here


def test_the_json_form_is_strict_and_names_every_field():
    analysis = analyze("g1_two_feet")
    answer = held_stance_max_contact_velocity(analysis)
    doc = json.loads(json.dumps(answer.to_dict(), allow_nan=False))
    assert doc == {
        "max_contact_velocity": answer.max_contact_velocity,
        "status": "ok",
        "restitution": list(answer.restitution),
        "jumps": answer.jumps.tolist(),
        "converged": True,
        "fell_back": False,
        "binding_restitution": answer.binding_restitution,
        "iterations": answer.iterations,
    }
    unbounded = HeldStanceLimit(
        math.inf, "unbounded", (0.0, 0.2), np.zeros((2, 2)), True, False, None, 2
    )
    assert json.dumps(unbounded.to_dict(), allow_nan=False).count("null") == 2


def test_an_analysis_without_impact_or_with_joint_space_inertia_is_refused():
    scenario = load_scenario("palm_push_two_feet")
    with pytest.raises(ImpactModelError) as info:
        held_stance_max_contact_velocity(analyze(scenario.model_copy(update={"impact": None})))
    assert info.value.field == "impact"
    joint_space = scenario.impact.model_copy(update={"inertia": "joint_space"})
    with pytest.raises(ImpactModelError) as info:
        held_stance_max_contact_velocity(
            analyze(scenario.model_copy(update={"impact": joint_space}))
        )
    assert info.value.field == "impact.inertia"
