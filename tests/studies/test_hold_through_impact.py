"""``studies/hold_through_impact.py``: the speed at which a contact's resultant leaves its cone.

``slip_speed`` (a quadratic's root) is checked against a brute-force scan of the speed, and the
least-norm static distribution against the weight it must carry on a bundled stance.
"""

from __future__ import annotations

import math
from types import ModuleType

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tests.helpers.scripts import load_study

pytest.importorskip("qpsolvers")


@pytest.fixture(scope="module")
def script() -> ModuleType:
    return load_study("hold_through_impact")


def _inside(f: np.ndarray, n: np.ndarray, mu: float) -> bool:
    f_n = float(n @ f)
    return f_n > 0 and float(np.linalg.norm(f - f_n * n)) <= mu * f_n


component = st.one_of(st.just(0.0), st.floats(0.01, 50.0), st.floats(-50.0, -0.01))
vec = st.lists(component, min_size=3, max_size=3)


@settings(max_examples=60, deadline=None)
# mu near the growth's |b_t| / |b_n|: the quadratic's leading coefficient is tiny (the cone's
# exit at 1/14 was lost to cancellation and the normal's zero, 1/7, returned).
@example(tangential=[0.0, 0.0, 0.0], growth=[0.0, -7.0, -7.0], normal_load=1.0, mu=1.0 - 1e-13)
@given(tangential=vec, growth=vec, normal_load=st.floats(1.0, 100.0), mu=st.floats(0.1, 1.0))
def test_slip_speed_against_a_scan(
    script: ModuleType,
    tangential: list[float],
    growth: list[float],
    normal_load: float,
    mu: float,
) -> None:
    n = np.array([0.0, 0.0, 1.0])
    static = np.array([tangential[0], tangential[1], 0.0])
    static *= min(1.0, 0.9 * mu * normal_load / max(float(np.linalg.norm(static)), 1e-9))
    static[2] = normal_load  # inside the cone at v = 0
    per_speed = np.array(growth)
    v = script.slip_speed(static, per_speed, n, mu)
    scan = np.linspace(0.0, 20.0, 4001)
    f = static + scan[:, None] * per_speed  # every speed at once
    out = (f[:, 2] <= 0) | (np.linalg.norm(f[:, :2], axis=1) > mu * f[:, 2])
    first_out = float(scan[np.argmax(out)]) if out.any() else math.inf
    if math.isinf(v):
        assert math.isinf(first_out)
    else:
        assert _inside(static + 0.999 * v * per_speed, n, mu) or v < 1e-9
        assert not _inside(static + 1.001 * v * per_speed + 1e-12, n, mu)
        if v < 19.9:
            assert first_out == pytest.approx(v, abs=20.0 / 4000 + 1e-9)


def test_slip_speed_never_for_an_impulse_inside(script: ModuleType) -> None:
    n = np.array([0.0, 0.0, 1.0])
    v = script.slip_speed(np.array([1.0, 0, 10]), np.array([0.5, 0, 10]), n, 0.3)
    assert math.isinf(v)
    # the impulse on the cone's other side: leaves it where (1 + 2v) = 0.3 (10 + 5v)
    v = script.slip_speed(np.array([1.0, 0, 10]), np.array([2.0, 0, 5]), n, 0.3)
    assert v == pytest.approx(2.0 / 0.5)


def test_static_forces_carry_the_weight(script: ModuleType) -> None:
    from impact_balance.analysis.analyze import analyze

    stance = analyze("romeo_two_feet", solve_qp=False).stance
    forces = script.static_corner_forces(stance, 0.65)
    from impact_balance.impact.contact_aware import corner_contacts

    corners = corner_contacts(stance)
    total = sum(f.sum(axis=0) for f in forces)
    moment = sum(
        np.cross(p.arm, f[k])
        for f, contact in zip(forces, corners, strict=True)
        for k, p in enumerate(contact)
    )
    weight = stance.mass * script.G
    assert total == pytest.approx([0.0, 0.0, weight], abs=1e-6 * weight)
    assert np.abs(moment).max() < 1e-6 * weight
    for f, contact in zip(forces, corners, strict=True):
        for k, p in enumerate(contact):
            widest = float(np.linalg.norm(p.generators - p.normal[:, None], axis=0).max())
            assert _inside(f[k] + 1e-9 * p.normal, p.normal, 0.65 * widest + 1e-6)
