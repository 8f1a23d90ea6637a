"""The compiled posture's finiteness test is the per-field check's: it fails exactly where that
raises."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.analysis import analyze as pipeline
from impact_balance.exceptions import NonFiniteResultError
from impact_balance.geometry.polygon import Polygon

special = st.sampled_from([np.nan, np.inf, -np.inf, 1e155, -1e200, 1e308, 0.0, 1.0])
number = st.floats(-10.0, 10.0) | special


def arrays(shape):
    size = int(np.prod(shape))
    return st.lists(number, min_size=size, max_size=size).map(
        lambda v: np.array(v, dtype=float).reshape(shape)
    )


@settings(max_examples=400, deadline=None)
@given(
    com=arrays((3,)),
    omega=number,
    zmp=arrays((4, 2)),
    velocity=arrays((3, 2)),
    point=arrays((3,)),
    W=arrays((3, 3)),
    impulse=arrays((4, 3)),
)
def test_the_compiled_test_fails_exactly_where_the_check_raises(
    com, omega, zmp, velocity, point, W, impulse
):
    stance = SimpleNamespace(com=com)
    areas = SimpleNamespace(omega=omega, zmp_area=Polygon(zmp), com_velocity_area=Polygon(velocity))
    model = SimpleNamespace(point=point, W=W, impulse_rates=impulse)
    checks = pipeline._area_checks(stance, areas) + pipeline._impact_checks(model)
    try:
        pipeline._check_finite(checks)
        raised = False
    except NonFiniteResultError:
        raised = True
    assert pipeline._posture_finite(stance, areas, model) is not raised


def test_huge_vertices_fail_on_their_squared_size():
    stance = SimpleNamespace(com=np.zeros(3))
    areas = SimpleNamespace(
        omega=3.0,
        zmp_area=Polygon(np.array([[0.0, 0.0], [1e155, 0.0], [0.0, 1.0]])),
        com_velocity_area=Polygon(np.eye(3)[:, :2]),
    )
    model = SimpleNamespace(point=np.zeros(3), W=np.eye(3), impulse_rates=np.ones((2, 3)))
    assert not pipeline._posture_finite(stance, areas, model)
    with pytest.raises(NonFiniteResultError, match="zmp_area"):
        pipeline._check_finite(pipeline._area_checks(stance, areas))


def test_strided_arrays_are_checked_alike():
    rows = np.arange(24.0).reshape(4, 6)
    stance = SimpleNamespace(com=rows[0, ::2])  # strided views, a transposed W
    areas = SimpleNamespace(
        omega=3.0,
        zmp_area=Polygon(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])),
        com_velocity_area=Polygon(np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])),
    )
    W = np.eye(3).T
    model = SimpleNamespace(point=rows[1, 1::2], W=W, impulse_rates=rows[:, :3])
    assert pipeline._posture_finite(stance, areas, model)
    rows[3, 2] = np.inf  # in the impulse rates' view
    assert not pipeline._posture_finite(stance, areas, model)
    checks = pipeline._area_checks(stance, areas) + pipeline._impact_checks(model)
    with pytest.raises(NonFiniteResultError, match=r"impact\.impulse_vertices"):
        pipeline._check_finite(checks)
