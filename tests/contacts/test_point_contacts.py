"""Point contacts (``size: [0, 0]``): a force cone at the point, no torque.

Independent references: a point's wrenches are ``[f; 0]`` with ``f`` in the friction pyramid;
with enough friction the ZMP support area of point feet on a plane is the convex hull of the
points (the ZMP is a convex combination of the points where the vertical forces act); with
less friction, its support function is an LP over the point forces alone (3 per point, no
torque variable), solved here with scipy, and the CoM velocity area is ``omega (zmp - c_xy)``
with ``omega = sqrt(g / c_z)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

from impact_balance.balance.areas import areas_from_polytope
from impact_balance.constants import GRAVITY
from impact_balance.contacts.cwc import cwc_faces
from impact_balance.contacts.stance import Contact, ContactSpec
from impact_balance.contacts.wrench_polytope import contact_polytope
from tests.helpers.quadrupeds import four_point_feet

FAST = settings(max_examples=30, deadline=None)
MASS = 16.0


def _points(positions: np.ndarray, mu: float) -> list[Contact]:
    return [
        Contact(
            ContactSpec(f"p{i}", mu, (0.0, 0.0)), np.eye(3), np.asarray(p, float), np.zeros((6, 1))
        )
        for i, p in enumerate(positions)
    ]


def _support(vertices: np.ndarray, direction: np.ndarray) -> float:
    return float((vertices @ direction).max())


def _lp_zmp_support(positions: np.ndarray, mu: float, com: np.ndarray, d: np.ndarray) -> float:
    """Max d . zmp over point forces in their pyramids, m g up, no moment about the CoM."""
    n = len(positions)
    weight = MASS * GRAVITY
    # Variables f_i (3 each). zmp = c_xy - c_z / (m g) f_xy (plane z = 0).
    cost = np.zeros(3 * n)
    for i in range(n):
        cost[3 * i : 3 * i + 2] = d * com[2] / weight  # minimise -(d . zmp) + const
    A_eq, b_eq = [], []
    row = np.zeros(3 * n)
    row[2::3] = 1.0
    A_eq.append(row)
    b_eq.append(weight)
    for k in range(3):  # sum (p_i - c) x f_i = 0
        row = np.zeros(3 * n)
        for i, p in enumerate(positions):
            e = np.zeros(3)
            e[k] = 1.0
            # e . (r x f) = f . (e x r)
            row[3 * i : 3 * i + 3] = np.cross(e, p - com)
        A_eq.append(row)
        b_eq.append(0.0)
    A_ub = []
    for i in range(n):
        for axis in (0, 1):
            for sign in (1.0, -1.0):
                row = np.zeros(3 * n)
                row[3 * i + axis] = sign
                row[3 * i + 2] = -mu
                A_ub.append(row)
    res = linprog(
        cost,
        A_ub=np.array(A_ub),
        b_ub=np.zeros(len(A_ub)),
        A_eq=np.array(A_eq),
        b_eq=np.array(b_eq),
        bounds=[(None, None)] * (3 * n),
    )
    assert res.status == 0, res.message
    return float(d @ com[:2] - res.fun)


@given(
    f=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(0.01, 10)),
    tau=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)),
    mu=st.floats(0.1, 1.5),
)
@FAST
def test_a_point_cone_is_the_force_pyramid_and_no_torque(f, tau, mu):
    faces = cwc_faces(mu, 0.0, 0.0)
    force = np.array(f)
    in_pyramid = abs(force[0]) <= mu * force[2] and abs(force[1]) <= mu * force[2]
    assert bool((faces @ np.concatenate([force, np.zeros(3)]) <= 1e-12).all()) == in_pyramid
    torque = np.array(tau)
    if np.abs(torque).max() > 1e-9:
        assert (faces @ np.concatenate([force, torque]) > 0).any()


@given(
    xy=st.lists(st.tuples(st.floats(-0.4, 0.4), st.floats(-0.4, 0.4)), min_size=3, max_size=4),
    height=st.floats(0.2, 1.0),
)
@FAST
def test_point_feet_zmp_area_is_their_hull_with_ample_friction(xy, height):
    positions = np.array([[x, y, 0.0] for x, y in xy])
    hull_area = ConvexHull(positions[:, :2], qhull_options="QJ").volume
    if hull_area < 0.01:
        return  # a sliver: nothing to compare
    inside = positions[:, :2].mean(axis=0)
    com = np.array([inside[0], inside[1], height])
    areas = areas_from_polytope(contact_polytope(_points(positions, 50.0), MASS, com))
    assert areas.zmp_area.area == pytest.approx(hull_area, rel=1e-6, abs=1e-9)
    for angle in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        d = np.array([np.cos(angle), np.sin(angle)])
        assert _support(areas.zmp_area.vertices, d) == pytest.approx(
            _support(positions[:, :2], d), abs=1e-7
        )


@pytest.mark.parametrize("mu", [0.3, 0.7])
def test_point_feet_areas_match_an_lp_over_forces(mu):
    positions = np.array([[0.17, 0.16, 0.0], [0.17, -0.16, 0.0], [-0.21, 0.0, 0.0]])
    com = np.array([0.0, 0.02, 0.3])
    areas = areas_from_polytope(contact_polytope(_points(positions, mu), MASS, com))
    omega = np.sqrt(GRAVITY / com[2])
    assert areas.omega == pytest.approx(omega)
    for angle in np.linspace(0, 2 * np.pi, 16, endpoint=False):
        d = np.array([np.cos(angle), np.sin(angle)])
        zmp = _lp_zmp_support(positions, mu, com, d)
        assert _support(areas.zmp_area.vertices, d) == pytest.approx(zmp, abs=1e-6)
        velocity = omega * (zmp - d @ com[:2])
        assert _support(areas.com_velocity_area.vertices, d) == pytest.approx(velocity, abs=1e-5)
    if mu == 0.3:  # friction cuts the triangle: the LIPM needs horizontal force at the far ZMPs
        hull = ConvexHull(positions[:, :2]).volume
        assert areas.zmp_area.area < hull - 1e-3


def test_go2_on_four_points_analyzes_to_its_feet_hull_without_limits():
    from impact_balance.analysis.analyze import analyze
    from impact_balance.scenario.validate import scenario_from_dict

    raw = four_point_feet("go2", friction=50.0)
    raw["torque_limits"] = False
    scenario = scenario_from_dict(raw)
    analysis = analyze(scenario)
    feet = np.array([c.position[:2] for c in analysis.stance.contacts])
    assert analysis.areas.zmp_area.area == pytest.approx(ConvexHull(feet).volume, rel=1e-6)
    assert all(c.is_point for c in analysis.stance.contacts)
