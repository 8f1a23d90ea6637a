"""The governor: its per-tick answer is analyze()'s for the same state; the fast path, the cap,
thread safety, bad arguments."""

from __future__ import annotations

import threading

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor
from impact_balance.scenario import load_scenario


def states(governor: Governor, count: int, seed: int = 0):
    """``count`` (q, v) pairs near the scenario's posture: joints moved by up to 0.05 rad, the base
    by a few cm, joint and base velocities of a moving robot (pinocchio's base-frame convention)."""
    rng = np.random.default_rng(seed)
    model = governor.robot.model
    out = []
    for _ in range(count):
        q = governor.configuration.copy()
        for name in governor.robot.joint_names:
            slot = governor.robot.joint_slot(name)
            if slot.nq == 1:
                q[slot.idx_q] = np.clip(
                    q[slot.idx_q] + rng.uniform(-0.05, 0.05), slot.lower, slot.upper
                )
        q[:3] += rng.uniform(-0.03, 0.03, 3)
        v = rng.normal(0.0, 0.3, model.nv)
        v[:3] = rng.normal(0.0, 0.1, 3)
        out.append((q, v))
    return out


def analyze_at(governor: Governor, q, v):
    """analyze() of the equivalent scenario: the posture q and the model's CoM velocity J_com v."""
    model = governor.robot.model
    data = model.createData()
    pin.centerOfMass(model, data, q, v)
    return ib.analyze(governor.scenario_at(q, data.vcom[0]))


@pytest.mark.parametrize(
    "name, inertia, margin, friction",
    [
        ("palm_push_two_feet", "composite", 0.0, None),
        ("palm_push_ramp", "composite", 0.01, None),
        ("kick_one_foot", "joint_space", 0.0, None),
        ("g1_two_feet", "composite", 0.005, None),
        (
            "palm_push_ramp",
            "composite",
            0.01,
            2.5,
        ),  # a friction above 1: the friction-normalised path
    ],
)
def test_each_tick_is_analyze_of_the_same_state(name, inertia, margin, friction):
    scenario = load_scenario(name)
    contacts = (
        scenario.contacts
        if friction is None
        else [c.model_copy(update={"friction": friction}) for c in scenario.contacts]
    )
    scenario = scenario.model_copy(
        update={
            "zmp_margin": margin,
            "contacts": contacts,
            "impact": scenario.impact.model_copy(update={"inertia": inertia}),
        }
    )
    governor = Governor(scenario)
    for q, v in states(governor, 6):
        limit = governor.limit(q, v)
        a = analyze_at(governor, q, v)
        assert limit.posture_reused is False
        assert limit.status == a.impact.com.status
        assert limit.max_contact_velocity == pytest.approx(a.impact.max_contact_velocity, abs=1e-9)
        assert limit.limiting_vertex == a.impact.com.limiting_vertex
        expected = a.impact.safe_interval
        assert (limit.safe_interval is None) == (expected is None)
        if expected is not None:
            assert limit.safe_interval == pytest.approx(expected, abs=1e-9)
        assert np.allclose(limit.point, a.impact.model.point, atol=1e-12)


def test_zmp_governor_is_analyzes_zmp_criterion():
    governor = Governor("palm_push_ramp", criterion="zmp")
    for q, v in states(governor, 4, seed=1):
        limit = governor.limit(q, v)
        a = analyze_at(governor, q, v)
        assert limit.criterion == "zmp"
        assert limit.max_contact_velocity == pytest.approx(
            a.impact.zmp_max_contact_velocity, abs=1e-9
        )


def test_velocity_only_ticks_reuse_the_posture_and_agree_with_a_fresh_governor():
    governor = Governor("palm_push_two_feet")
    (q, v0), (_, v1), (_, v2) = states(governor, 3, seed=2)
    first = governor.limit(q, v0)
    again = governor.limit(q, v1)
    assert not first.posture_reused and again.posture_reused
    fresh = Governor("palm_push_two_feet").limit(q, v1)
    assert again.max_contact_velocity == pytest.approx(fresh.max_contact_velocity, abs=1e-12)
    assert again.safe_interval == pytest.approx(fresh.safe_interval, abs=1e-12)
    # A tolerance reuses a posture that moved less than it; any change is new without one.
    tolerant = Governor("palm_push_two_feet", posture_tolerance=1e-3)
    tolerant.limit(q, v0)
    moved = q.copy()
    moved[7] += 5e-4
    assert tolerant.limit(moved, v2).posture_reused
    assert not governor.limit(moved, v2).posture_reused


def test_cap_follows_the_safe_interval():
    governor = Governor("palm_push_two_feet")
    q = governor.configuration
    n = governor.posture.impact.normal
    limit = governor.limit(q, np.zeros(governor.nv))
    fast = -2.0 * n + np.array([0.0, 0.1, 0.0])  # 2 m/s towards the wall, a bit sideways
    capped = governor.cap(fast)
    assert -capped @ n == pytest.approx(limit.ceiling, abs=1e-12)
    assert capped[1] == pytest.approx(0.1)  # the tangential part is kept
    slow = -0.1 * n
    assert np.allclose(governor.cap(slow), slow)  # already safe: unchanged
    away = 0.3 * n
    assert np.allclose(governor.cap(away), away)  # moving away: no impact, unchanged
    # A falling start: the CoM velocity outside the area; the cap keeps the approach in the
    # interval of speeds that catch the fall (or removes it when none does).
    falling = governor.limit_com(q, [0.5, 0.0])
    assert falling.status == "already_falling"
    a = ib.analyze(governor.scenario_at(q, [0.5, 0.0]))
    assert (falling.safe_interval is None) == (a.impact.safe_interval is None)
    capped = falling.cap(-0.8 * n)
    if falling.safe_interval is None:
        assert -capped @ n == pytest.approx(0.0, abs=1e-12)
    else:
        lo, hi = falling.safe_interval
        assert lo - 1e-12 <= -capped @ n <= hi + 1e-12


def test_one_instance_from_several_threads_gives_the_serial_answers():
    governor = Governor("palm_push_ramp")
    inputs = states(governor, 12, seed=3)
    serial = [Governor("palm_push_ramp").limit(q, v).max_contact_velocity for q, v in inputs]
    results: dict[int, float] = {}
    errors = []

    def work(indices):
        try:
            for i in indices:
                q, v = inputs[i]
                results[i] = governor.limit(q, v).max_contact_velocity
        except Exception as exc:
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(list(range(k, 12, 4)),)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert [results[i] for i in range(12)] == pytest.approx(serial, abs=1e-12)


@pytest.mark.parametrize(
    "q, v, field",
    [
        ("short", None, "q"),
        (None, "nan", "v"),
        ("quaternion", None, "q"),
    ],
)
def test_bad_arguments_are_one_line_errors(q, v, field):
    governor = Governor("palm_push_two_feet")
    q0, v0 = governor.configuration.copy(), np.zeros(governor.nv)
    if q == "short":
        q0 = q0[:-1]
    if q == "quaternion":
        q0[3:7] = [0.0, 0.0, 0.0, 2.0]
    if v == "nan":
        v0[5] = np.nan
    with pytest.raises(GovernorError) as info:
        governor.limit(q0, v0)
    assert info.value.field == field and "\n" not in str(info.value)
    with pytest.raises(GovernorError):
        Governor("palm_push_two_feet", criterion="speed")
    with pytest.raises(GovernorError, match="call limit"):
        Governor("palm_push_two_feet").cap([0.5, 0.0, 0.0])


def test_gui_shows_the_governors_cap_for_the_stance_being_edited(tmp_path):
    from impact_balance.gui import Session
    from impact_balance.gui.results import results_html

    session = Session("palm_push_two_feet", workspace=tmp_path)
    g = session.governed
    a = session.analysis
    assert g.ceiling == pytest.approx(a.impact.max_contact_velocity, abs=1e-9)
    assert g.reference == pytest.approx(0.8) and g.capped == pytest.approx(
        min(0.8, g.ceiling), abs=1e-9
    )
    first = session._governor
    html = results_html(session, 1.0)
    assert 'id="ib-governor-cap"' in html and f"{g.ceiling:.3f} m/s" in html
    # A posture or CoM velocity edit reuses the governor; the numbers follow.
    assert session.set(("com_velocity",), [0.1, 0.0])
    assert session._governor is first
    assert session.governed.ceiling == pytest.approx(
        session.analysis.impact.max_contact_velocity, abs=1e-9
    )
    assert session.set(("joints", "arm_right_4_joint"), -1.2)
    assert session._governor is first
    assert session.governed.ceiling == pytest.approx(
        session.analysis.impact.max_contact_velocity, abs=1e-9
    )
    # A change of the impact or the contacts builds a new one.
    assert session.set(("impact", "friction"), 0.4)
    assert session._governor is not first
    assert session.governed.ceiling == pytest.approx(
        session.analysis.impact.max_contact_velocity, abs=1e-9
    )
    assert session.set(("impact",), None)
    assert session.governed is None and 'id="ib-governor-cap"' not in results_html(session, 1.0)
