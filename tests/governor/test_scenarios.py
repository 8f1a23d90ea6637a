"""The governor accepts every scenario analyze() accepts: every bundled scenario and every
contact form the docs show (a frame alone, an offset, a world normal with an angle, a hand on a
table given by its world normal), and answers what analyze() answers for the same state."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.governor import ContactAwareOptions, Governor
from impact_balance.scenario import bundled_scenarios, load_scenario, scenario_from_dict

TALOS_PALM = {"position": [0.051, 0.0, -0.045]}  # the palm's centre in gripper_*_base_link


def with_contact(name: str, contact: dict) -> ib.Scenario:
    """The bundled scenario ``name`` with one more sustained contact."""
    raw = load_scenario(name).model_dump(exclude_none=True, exclude_unset=True)
    raw["contacts"] = [*raw["contacts"], contact]
    return scenario_from_dict(raw)


#: Every contact form of README's "Scenario files" and docs/conventions.md.
CONTACT_FORMS = {
    "frame only": ("palm_push_two_feet", {"frame": "gripper_left_base_link", "friction": 0.5,
                                          "size": [0.08, 0.08]}),
    "offset": ("palm_push_two_feet", {"frame": "gripper_left_base_link", "friction": 0.5,
                                      "size": [0.08, 0.08],
                                      "offset": {**TALOS_PALM, "rpy": [0.0, -1.5708, 0.0]}}),
    "world normal": ("palm_push_two_feet", {"frame": "gripper_left_base_link", "friction": 0.5,
                                            "size": [0.08, 0.08], "offset": TALOS_PALM,
                                            "normal": [0, 0, 1]}),
    "world normal with angle": ("palm_push_ramp", {"frame": "gripper_left_base_link",
                                                   "friction": 0.5, "size": [0.08, 0.06],
                                                   "offset": TALOS_PALM,
                                                   "normal": [0.1, 0.2, 2.0], "angle": 0.4}),
    "G1 hand on a table": ("g1_two_feet", {"frame": "left_rubber_hand", "friction": 0.5,
                                           "size": [0.08, 0.06], "normal": [0, 0, 1]}),
}  # fmt: skip


def assert_governor_is_analyze(scenario: ib.Scenario) -> Governor:
    """The governor of ``scenario`` answers analyze()'s maximum at the scenario's own state."""
    governor = Governor(scenario)
    analysis = ib.analyze(scenario)
    limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    assert limit.status == analysis.impact.com.status
    assert limit.max_contact_velocity == pytest.approx(
        analysis.impact.max_contact_velocity, abs=1e-9
    )
    np.testing.assert_allclose(governor.configuration, analysis.stance.q, atol=0.0)
    return governor


@pytest.mark.parametrize("name", sorted(bundled_scenarios()))
def test_every_bundled_scenario_builds_a_governor_that_is_analyze(name):
    assert_governor_is_analyze(load_scenario(name))


@pytest.mark.parametrize("form", sorted(CONTACT_FORMS))
def test_every_documented_contact_form_builds_a_governor_that_is_analyze(form):
    name, contact = CONTACT_FORMS[form]
    scenario = with_contact(name, contact)
    governor = assert_governor_is_analyze(scenario)
    # The contact as the governor holds it is analyze()'s: same frame, normal and centre.
    resolved = ib.analyze(scenario).stance.contacts[-1]
    held = governor.posture.stance.contacts[-1]
    np.testing.assert_allclose(held.rotation, resolved.rotation, atol=1e-12)
    np.testing.assert_allclose(held.position, resolved.position, atol=1e-12)
    if "normal" in contact:
        n = np.asarray(contact["normal"], dtype=float)
        np.testing.assert_allclose(held.normal, n / np.linalg.norm(n), atol=1e-12)


def test_a_world_normal_contact_stays_fixed_in_its_frame_at_another_posture():
    # Resolved once at the scenario's stance, as analyze() resolves it: at another posture the
    # contact turns with its frame, and scenario_at() writes it so that analyze() agrees.
    scenario = with_contact(*CONTACT_FORMS["G1 hand on a table"])
    governor = Governor(scenario)
    model = governor.robot.model
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = governor.configuration.copy()
        q[7:] += rng.uniform(-0.03, 0.03, model.nq - 7)
        v = rng.normal(0.0, 0.2, model.nv)
        limit = governor.limit(q, v)
        data = model.createData()
        pin.centerOfMass(model, data, q, v)
        replay = governor.scenario_at(q, data.vcom[0])
        assert "normal" not in replay.contacts[-1].model_dump(exclude_none=True)
        analysis = ib.analyze(replay)
        assert limit.max_contact_velocity == pytest.approx(
            analysis.impact.max_contact_velocity, abs=1e-9
        )
        pin.framesForwardKinematics(model, data, q)
        frame = data.oMf[model.getFrameId("left_rubber_hand")].rotation
        start = Governor(scenario).posture.stance.contacts[-1]  # the frame turned, the contact too
        np.testing.assert_allclose(
            governor.posture.stance.contacts[-1].rotation,
            frame @ governor.contacts[-1].offset.rotation,
            atol=1e-12,
        )
        assert not np.allclose(analysis.stance.contacts[-1].normal, start.normal, atol=1e-6)


def test_the_contact_aware_worker_resolves_the_contacts_as_the_governor_does():
    scenario = with_contact(*CONTACT_FORMS["G1 hand on a table"])
    synchronous = Governor(scenario, contact_aware=True)
    expected = synchronous.limit_com(synchronous.configuration, scenario.com_velocity)
    with Governor(scenario, contact_aware=ContactAwareOptions(asynchronous=True)) as governor:
        limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    assert limit.rates_age == 0
    assert limit.max_contact_velocity == pytest.approx(expected.max_contact_velocity, abs=1e-12)
    assert limit.binding == expected.binding
