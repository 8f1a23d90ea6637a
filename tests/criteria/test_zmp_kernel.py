"""The ZMP criterion's compiled exit against its array formula, to the last digit."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.criteria.linear_exit import first_exit
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.criteria.zmp import zmp_max_contact_velocity
from impact_balance.geometry.polygon import Polygon


def array_formula(zmp_area, impact, com, plane_height, gravity, duration):
    """The criterion as numpy arrays (the formula of paper Experiment 1, written apart)."""
    if zmp_area.is_empty:
        return ContactVelocityLimit(0.0, "cannot_balance")
    G, h = zmp_area.halfplanes
    weight = impact.mass * gravity
    p = impact.point
    M = np.empty((3, len(h)))
    M[:2] = ((plane_height - float(p[2])) / duration) * G.T
    M[2] = (G @ p[:2] - h) / duration
    margins = weight * (h - G @ np.asarray(com, dtype=float)[:2])
    limit = first_exit(margins, impact.impulse_rates @ M)
    fz = impact.impulse_rates[:, 2] / duration
    pulling = fz < 0
    if limit.status != "already_falling" and pulling.any():
        with np.errstate(over="ignore"):
            lift = weight / -fz[pulling]
        j = int(lift.argmin())
        if lift[j] < limit.max_contact_velocity:
            return ContactVelocityLimit(float(lift[j]), "ok", int(np.flatnonzero(pulling)[j]), None)
    return limit


coordinate = st.floats(-0.3, 0.3, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(
    points=st.lists(st.tuples(coordinate, coordinate), min_size=3, max_size=12),
    com=st.tuples(coordinate, coordinate, st.floats(0.3, 1.2)),
    point=st.tuples(coordinate, coordinate, st.floats(-0.2, 1.5)),
    rows=st.lists(
        st.tuples(*[st.floats(-50.0, 50.0, allow_nan=False)] * 3), min_size=1, max_size=8
    ),
    mass=st.floats(1.0, 120.0),
    duration=st.floats(1e-3, 0.05),
    plane=st.floats(-0.1, 0.1),
)
def test_the_compiled_exit_is_the_array_formula(points, com, point, rows, mass, duration, plane):
    area = Polygon.from_points(np.array(points))
    impact = SimpleNamespace(
        mass=mass, point=np.array(point), impulse_rates=np.array(rows, dtype=float)
    )
    got = zmp_max_contact_velocity(area, impact, np.array(com), plane, 9.81, duration)
    want = array_formula(Polygon.from_points(np.array(points)), impact, com, plane, 9.81, duration)
    assert got == want  # every field, the speed to the last digit


def test_lift_off_and_falling_starts_are_the_array_formula():
    square = Polygon.from_points(np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]))
    pulling = np.array([[0.0, 0.0, 5.0], [1.0, 0.0, -40.0], [0.0, 1.0, -80.0]])
    cases = [
        (np.array([0.0, 0.0, 0.9]), pulling),  # lifted before an edge is reached
        (np.array([0.5, 0.0, 0.9]), pulling),  # the CoM outside: already falling
        (np.array([0.0, 0.0, 0.9]), np.array([[0.0, 0.0, -1e-300]])),  # a vanishing pull
    ]
    statuses = set()
    for com, rows in cases:
        impact = SimpleNamespace(mass=60.0, point=np.array([0.3, 0.0, 1.0]), impulse_rates=rows)
        got = zmp_max_contact_velocity(square, impact, com, 0.0, 9.81, 0.01)
        assert got == array_formula(square, impact, com, 0.0, 9.81, 0.01)
        statuses.add((got.status, got.limiting_edge is None))
    assert ("ok", True) in statuses  # the lift-off bound was among them
    assert ("already_falling", True) in statuses


@pytest.mark.parametrize(
    "vertices",
    [np.array([[-0.1, 0.0], [0.1, 0.02]]), np.array([[0.01, -0.02]])],
    ids=["segment", "point"],
)
def test_a_segment_or_a_point_is_the_array_formula(vertices):
    area = Polygon(vertices)
    rows = np.array([[1.0, 0.5, 3.0], [-2.0, 0.0, -30.0], [0.0, -1.0, 2.0]])
    for com in ([0.0, 0.0, 0.9], [0.01, -0.02, 0.9]):
        impact = SimpleNamespace(mass=60.0, point=np.array([0.3, 0.0, 1.0]), impulse_rates=rows)
        got = zmp_max_contact_velocity(area, impact, np.array(com), 0.0, 9.81, 0.01)
        assert got == array_formula(Polygon(vertices), impact, com, 0.0, 9.81, 0.01)
