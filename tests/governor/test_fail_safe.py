"""The governor fails safe: a stopped or killed contact-aware worker never leaves an optimistic
stale cap (real SIGSTOP and SIGKILL on G1 with an arm moving), and its inputs are checked like
analyze()'s."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import GovernorError
from impact_balance.governor import ContactAwareOptions, Governor, WorkerError
from impact_balance.governor.governor import JOINT_LIMIT_TOLERANCE

SCENARIO = "g1_two_feet"
MARGIN = 0.022
STEP = 0.003  # rad per posture: 1.5 rad/s at 500 Hz


def arm_postures(governor: Governor, count: int, step: float = STEP) -> list[np.ndarray]:
    """The scenario's posture with the right shoulder pitching forward by ``step`` a posture."""
    slot = governor.robot.joint_slot("right_shoulder_pitch_joint")
    out = []
    for k in range(1, count + 1):
        q = governor.configuration.copy()
        q[slot.idx_q] = np.clip(q[slot.idx_q] - step * k, slot.lower, slot.upper)
        out.append(q)
    return out


@pytest.fixture(scope="module")
def fresh() -> Governor:
    """Contact-aware rates recomputed at every posture, in the tick: the reference."""
    return Governor(SCENARIO, contact_aware=ContactAwareOptions(every=1), velocity_margin=MARGIN)


@pytest.fixture(scope="module")
def floating() -> Governor:
    return Governor(SCENARIO, velocity_margin=MARGIN)


def asynchronous(**options) -> Governor:
    return Governor(
        SCENARIO,
        contact_aware=ContactAwareOptions(asynchronous=True, **options),
        velocity_margin=MARGIN,
    )


def gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


def stopped_run(governor: Governor, postures: list[np.ndarray]) -> list:
    """Answers of ``postures`` after SIGSTOP of the worker (continued and closed after)."""
    v = np.zeros(governor.nv)
    governor.limit(governor.configuration, v)  # the rates are the scenario posture's
    pid = governor._worker.pid
    os.kill(pid, signal.SIGSTOP)
    answers = []
    try:
        for q in postures:
            try:
                answers.append(governor.limit(q, v))
            except GovernorError as exc:
                answers.append(exc)
    finally:
        os.kill(pid, signal.SIGCONT)
        governor.close()
    assert gone(pid)
    return answers


def test_a_stopped_worker_never_gives_a_cap_above_a_fresh_governors(fresh):
    postures = arm_postures(fresh, 30)
    answers = stopped_run(asynchronous(max_age=5), postures)
    v = np.zeros(fresh.nv)
    stale = 0
    for k, (q, answer) in enumerate(zip(postures, answers, strict=True), start=1):
        expected = fresh.limit(q, v)
        reference = -2.0 * expected.normal + np.array([0.1, 0.1, 0.1])  # 2 m/s at the wall
        assert expected.binding == "contact_aware"  # the contact-aware model binds on G1
        assert answer.max_contact_velocity <= 1.01 * expected.max_contact_velocity
        assert answer.rates_age == k
        assert answer.stale is (k > 5)
        approach = -answer.normal @ answer.cap(reference)
        assert approach <= 1.01 * expected.ceiling + 1e-12
        if answer.stale:
            stale += 1
            assert answer.max_contact_velocity == 0.0 and answer.safe_interval is None
            assert approach == pytest.approx(0.0, abs=1e-12)
    assert stale == 25


def test_stale_rates_give_the_floating_answer_when_asked(floating):
    postures = arm_postures(floating, 8)
    answers = stopped_run(asynchronous(max_age=2, on_stale="floating"), postures)
    v = np.zeros(floating.nv)
    for k, (q, answer) in enumerate(zip(postures, answers, strict=True), start=1):
        if k > 2:
            expected = floating.limit(q, v)
            assert answer.stale and answer.binding == "floating"
            assert answer.max_contact_velocity == expected.max_contact_velocity
            assert answer.safe_interval == expected.safe_interval
        else:
            assert not answer.stale


def test_stale_rates_raise_when_asked(floating):
    postures = arm_postures(floating, 4)
    answers = stopped_run(asynchronous(max_age=2, on_stale="raise"), postures)
    assert [isinstance(a, GovernorError) for a in answers] == [False, False, True, True]
    assert "older than max_age (2 postures)" in str(answers[2])
    assert answers[2].field == "contact_aware_async"


def test_rates_age_in_seconds_too():
    governor = asynchronous(max_age_seconds=0.05)
    postures = arm_postures(governor, 3)
    v = np.zeros(governor.nv)
    governor.limit(governor.configuration, v)
    pid = governor._worker.pid
    os.kill(pid, signal.SIGSTOP)
    try:
        # The rates of the posture the robot holds are exact, however old: never stale.
        time.sleep(0.1)
        held = governor.limit(governor.configuration, v)
        assert held.rates_age == 0 and held.rates_age_seconds == 0.0 and not held.stale
        first = governor.limit(postures[0], v)
        assert first.rates_age == 1 and not first.stale
        time.sleep(0.1)
        later = governor.limit(postures[1], v)
        assert later.rates_age == 2 and later.rates_age_seconds >= 0.1
        assert later.stale and later.max_contact_velocity == 0.0
    finally:
        os.kill(pid, signal.SIGCONT)
        governor.close()
    assert gone(pid)


def test_a_killed_worker_is_a_governor_error_on_every_tick():
    governor = asynchronous()
    postures = arm_postures(governor, 2)
    v = np.zeros(governor.nv)
    before = governor.limit(governor.configuration, v)
    pid = governor._worker.pid
    os.kill(pid, signal.SIGKILL)
    # Until the process has ended (its socket then hangs up): a killed process ends when it is
    # next scheduled, which a loaded machine can delay past a fixed sleep (CI: 0.2 s was not).
    governor._worker._process.wait(timeout=30)
    try:
        for q in (governor.configuration, postures[0], postures[1], postures[1]):
            with pytest.raises(WorkerError, match="worker process ended") as info:
                governor.limit(q, v)
            assert isinstance(info.value, GovernorError)
            assert info.value.field == "contact_aware_async" and info.value.exit_status == 1
    finally:
        governor.close()
    assert gone(pid)
    # Closed, the governor recomputes the rates in the tick, as without a worker.
    after = governor.limit(governor.configuration, v)
    assert after.max_contact_velocity == pytest.approx(before.max_contact_velocity, rel=1e-9)
    assert not after.stale


@pytest.mark.slow
def test_a_killed_worker_does_not_end_a_process_with_sigpipe_armed():
    """The command line restores SIGPIPE's default action: a write to a dead worker must raise,
    not kill the controller (``approach --contact-aware-async`` exited 141 without a word)."""
    script = textwrap.dedent(
        f"""
        import os, signal, time
        import numpy as np
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
        from impact_balance.governor import ContactAwareOptions, Governor, WorkerError
        g = Governor({SCENARIO!r}, contact_aware=ContactAwareOptions(asynchronous=True))
        v = np.zeros(g.nv)
        g.limit(g.configuration, v)
        os.kill(g._worker.pid, signal.SIGKILL)
        time.sleep(0.3)
        q = g.configuration.copy()
        q[7:] += 0.001
        for _ in range(3):
            try:
                g.limit(q, v)
            except WorkerError as exc:
                print("refused:", exc)
        g.close()
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 3 and all("the worker process ended" in line for line in lines)


# -- inputs -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def talos() -> Governor:
    return Governor("palm_push_two_feet")


@pytest.mark.parametrize("scenario", [None, 123, 1.5, ["palm_push_two_feet"]])
def test_a_scenario_that_is_not_one_is_a_governor_error(scenario):
    with pytest.raises(GovernorError, match=r"scenario = .*must be a Scenario"):
        Governor(scenario)


def test_a_complex_configuration_is_refused(talos):
    q = talos.configuration.astype(complex)
    with pytest.raises(GovernorError, match=r"q = .*real numbers"):
        talos.limit(q, np.zeros(talos.nv))
    with pytest.raises(GovernorError, match=r"v = .*real numbers"):
        talos.limit(talos.configuration, np.zeros(talos.nv, dtype=complex))
    with pytest.raises(GovernorError, match="com_velocity"):
        talos.limit_com(talos.configuration, np.array([0.1, 0.0], dtype=complex))


@pytest.mark.parametrize("value", [100.0, 1e10, -1e10])
def test_joints_far_beyond_their_limits_are_refused(talos, value):
    q = talos.configuration.copy()
    slot = talos.robot.joint_slot("arm_right_4_joint")
    q[slot.idx_q] = value
    with pytest.raises(GovernorError, match=r"arm_right_4_joint' is outside its limits"):
        talos.limit(q, np.zeros(talos.nv))


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    joint=st.integers(0, 1000),
    excess=st.floats(0.0, 2.0),
    upper=st.booleans(),
)
def test_the_joint_rule_is_the_limits_plus_the_tolerance(talos, joint, excess, upper):
    robot = talos.robot
    names = [
        n
        for n in robot.joint_names
        if robot.joint_slot(n).nq == 1 and robot.joint_slot(n).lower < robot.joint_slot(n).upper
    ]
    slot = robot.joint_slot(names[joint % len(names)])
    q = talos.configuration.copy()
    q[slot.idx_q] = slot.upper + excess if upper else slot.lower - excess
    v = np.zeros(talos.nv)
    if excess > JOINT_LIMIT_TOLERANCE + 1e-12:
        with pytest.raises(GovernorError, match="outside its limits"):
            talos.limit(q, v)
    elif excess < JOINT_LIMIT_TOLERANCE - 1e-12:
        try:
            talos.limit(q, v)
        except GovernorError as exc:  # the joint rule must not refuse it
            assert "outside its limits" not in str(exc)
        except Exception:  # the pipeline may refuse the posture for another reason
            pass


def test_huge_finite_inputs_say_what_is_wrong(talos):
    v = np.zeros(talos.nv)
    q = talos.configuration.copy()
    q[0] = 1e300  # its square overflows
    with pytest.raises(GovernorError, match=r"q\[0\] = 1e\+300: is finite but beyond any"):
        talos.limit(q, v)
    q[0] = 1e5
    with pytest.raises(GovernorError, match=r"q\[0\] = 100000.0: the base position must be within"):
        talos.limit(q, v)
    v[6:] = 1e300  # finite, but its square overflows
    with pytest.raises(GovernorError, match=r"v\[6\] = 1e\+300: is finite but beyond any"):
        talos.limit(talos.configuration, v)
    v[6:] = 1e3  # a CoM speed of thousands of m/s
    with pytest.raises(GovernorError, match="CoM speed above 100 m/s"):
        talos.limit(talos.configuration, v)
    v[:] = 0.0
    v[0] = np.nan
    with pytest.raises(GovernorError, match=r"must be finite \(entry 0\)"):
        talos.limit(talos.configuration, v)


def test_a_quaternion_off_unit_names_the_tolerance(talos):
    q = talos.configuration.copy()
    q[3:7] *= 1.001
    with pytest.raises(GovernorError, match="must be unit \\(within 1e-06\\)"):
        talos.limit(q, np.zeros(talos.nv))


def test_cap_arguments(talos):
    talos.limit(talos.configuration, np.zeros(talos.nv))
    for junk in ("junk", 0.5, {"safe_interval": (0, 1)}):
        with pytest.raises(GovernorError, match=r"limit = .*must be a SpeedLimit"):
            talos.cap([0.0, 0.0, 1.0], limit=junk)
    with pytest.raises(GovernorError, match="speed must be at most 100 m/s"):
        talos.cap([1e300, 0.0, 0.0])
    with pytest.raises(GovernorError, match=r"must be finite \(entry 1\)"):
        talos.cap([0.0, float("inf"), 0.0])
    with pytest.raises(GovernorError, match="real numbers"):
        talos.cap(np.array([1j, 0.0, 0.0]))
    with pytest.raises(GovernorError, match="speed must be at most 100 m/s"):
        talos.limit_com(talos.configuration, [1e200, 0.0])
    assert np.isfinite(talos.cap([99.0, 0.0, 0.0])).all()


@pytest.mark.parametrize(
    "options, field",
    [
        ({"max_age": -1}, "contact_aware.max_age"),
        ({"max_age": 1.5}, "contact_aware.max_age"),
        ({"max_age_seconds": float("nan")}, "contact_aware.max_age_seconds"),
        ({"max_age_seconds": -0.1}, "contact_aware.max_age_seconds"),
        ({"max_age_seconds": "1"}, "contact_aware.max_age_seconds"),
        ({"on_stale": "ignore"}, "contact_aware.on_stale"),
    ],
)
def test_bad_age_options_name_the_field(options, field):
    with pytest.raises(GovernorError) as info:
        ContactAwareOptions(**options)
    assert info.value.field == field
