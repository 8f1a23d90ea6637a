"""Governor.limit's CoM speed check: refused exactly when |J v| exceeds MAX_SPEED.

The tick skips the exact product when a bound settles it; the outcome must be the exact
check's, near the boundary too, on new postures and on reused ones.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.constants import MAX_SPEED
from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor


@pytest.fixture(scope="module")
def governor() -> Governor:
    return Governor("palm_push_two_feet")


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    ratio=st.one_of(st.floats(0.0, 3.0), st.floats(1.0 - 1e-9, 1.0 + 1e-9)),
    move=st.booleans(),
)
def test_refused_exactly_when_the_com_speed_is_above_the_bound(governor, seed, ratio, move):
    rng = np.random.default_rng(seed)
    q = governor.configuration.copy()
    if move:  # a new posture, whose Jacobian the bound has not seen
        q[7:] += rng.uniform(-0.01, 0.01, size=q.size - 7)
    J = governor._evaluator.kinematics(q).com_jacobian  # an independent evaluation
    direction = rng.normal(size=governor.nv)
    speed = float(np.linalg.norm(J @ direction))
    v = direction * (ratio * MAX_SPEED / speed)
    com_speed_squared = float((J @ v) @ (J @ v))
    if com_speed_squared <= MAX_SPEED * MAX_SPEED:
        answer = governor.limit(q, v)
        np.testing.assert_allclose(answer.com_velocity, J @ v, rtol=1e-12, atol=1e-12)
    else:
        with pytest.raises(GovernorError, match="CoM speed above"):
            governor.limit(q, v)


def test_a_slow_velocity_after_a_fast_one_at_the_same_posture_is_answered(governor):
    q = governor.configuration
    v = np.zeros(governor.nv)
    v[0] = 2.0 * MAX_SPEED  # the base alone moves the CoM at twice the bound
    with pytest.raises(GovernorError, match="CoM speed above"):
        governor.limit(q, v)
    v[0] = 0.5
    speed = float(np.linalg.norm(governor.limit(q, v).com_velocity))  # base axes: turned
    assert speed == pytest.approx(0.5, rel=1e-9)
