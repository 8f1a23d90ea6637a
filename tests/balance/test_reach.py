"""The CoM's reach (whole-body IK) and the capture it limits (balance/reach.py)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.analysis.analyze import analyze
from impact_balance.balance.reach import (
    ReachOptions,
    com_reach,
    ray_extent,
    reach_speed_limit,
)
from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.polygon import Polygon
from impact_balance.scenario import load_scenario
from tests.helpers.lipm import stop_distance
from tests.helpers.reach import evenly_spaced_reach, extent_by_bisection


@settings(max_examples=40, deadline=None)
@given(
    extent=st.floats(0.03, 0.3),
    ratio=st.floats(0.05, 0.95),
    omega=st.floats(2.0, 5.0),
)
def test_the_speed_limit_is_where_the_lipm_stops_at_the_reach(extent, ratio, omega):
    # Independent of the formula: integrate the LIPM with the ZMP at the area's extent.
    reach = ratio * extent
    square = Polygon.from_points(np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * omega * extent)
    limit = reach_speed_limit(square, omega, evenly_spaced_reach(np.full(8, reach)), [1.0, 0.0])
    assert stop_distance(0.99 * limit, extent, omega) <= reach + 1e-9
    assert stop_distance(1.01 * limit, extent, omega) > reach


def test_a_reach_beyond_the_area_leaves_the_papers_limit():
    omega, extent = 3.3, 0.1
    square = Polygon.from_points(np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * omega * extent)
    for reach in (extent, 2 * extent):
        limit = reach_speed_limit(square, omega, evenly_spaced_reach(np.full(8, reach)), [0.0, 1.0])
        assert limit == pytest.approx(omega * extent, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    points=st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=3, max_size=12).map(
        np.array
    ),
    angle=st.floats(0, 2 * math.pi),
)
def test_ray_extent_is_the_boundary_found_by_bisection(points, angle):
    cloud = np.vstack([points, [[0.3, 0.3], [-0.3, 0.3], [0.0, -0.3]]])  # the origin inside
    area = Polygon.from_points(cloud)
    u = np.array([math.cos(angle), math.sin(angle)])
    assert ray_extent(area, u) == pytest.approx(extent_by_bisection(area, u), abs=1e-9)


def test_along_is_exact_on_a_sample_and_the_smaller_neighbour_between():
    radii = np.array([0.1, 0.2, 0.05, 0.3])
    reach = evenly_spaced_reach(radii)
    for k, r in enumerate(radii):
        a = k * math.pi / 2
        assert reach.along([math.cos(a), math.sin(a)]) == r
    assert reach.along([1.0, 1.0]) == 0.1
    assert reach.along([-1.0, 0.2]) == 0.05
    assert reach.along([0.3, -1.0]) == 0.1


def test_too_few_directions_is_refused_by_name():
    stance = analyze(load_scenario("palm_push_two_feet")).stance
    with pytest.raises(ScenarioError) as caught:
        com_reach(stance, ReachOptions(directions=3))
    assert caught.value.field == "com_reach.directions"


def test_each_posture_holds_the_contacts_and_puts_the_com_at_its_reach():
    # Checked with pinocchio alone, outside the IK: the CoM where the reach says (height held),
    # every contact frame where the stance has it, every joint within its limits.
    scenario = load_scenario("palm_push_two_feet")
    stance = analyze(scenario).stance
    options = ReachOptions(directions=4, bisections=5)
    reach = com_reach(stance, options)
    model = stance.robot.model
    data = model.createData()
    start = {}
    pin.framesForwardKinematics(model, data, np.asarray(stance.q, dtype=float))
    frames = [c.spec.frame for c in stance.contacts]
    for f in frames:
        start[f] = data.oMf[model.getFrameId(f)].copy()
    com = np.asarray(stance.com, dtype=float)
    assert np.all(reach.radii > 0.0)
    for a, r, q in zip(reach.azimuths, reach.radii, reach.postures, strict=True):
        target = com + r * np.array([math.cos(a), math.sin(a), 0.0])
        c = pin.centerOfMass(model, data, q)
        assert np.linalg.norm(c - target) <= options.com_tolerance
        assert abs(c[2] - reach.height) <= options.com_tolerance
        pin.framesForwardKinematics(model, data, q)
        for f in frames:
            err = pin.log(start[f].actInv(data.oMf[model.getFrameId(f)])).vector
            assert np.linalg.norm(err) <= options.contact_tolerance
        joints = q[7:]
        assert np.all(joints >= model.lowerPositionLimit[7:] - 1e-9)
        assert np.all(joints <= model.upperPositionLimit[7:] + 1e-9)


def test_a_stance_a_rounding_outside_a_joint_limit_is_searched_from_within_it():
    # A stance file's rounded joints can sit 1e-6 rad outside a limit (JVRC-1 on the fourth
    # held-out set), which pink refuses as a start: the search starts from the clamped one.
    from impact_balance.robot.ik import within_limits

    stance = analyze(load_scenario("palm_push_two_feet")).stance
    model = stance.robot.model
    q = np.asarray(stance.q, dtype=float).copy()
    j = 7 + int(np.argmax(model.upperPositionLimit[7:] < 1e9))  # a bounded joint
    q[j] = model.upperPositionLimit[j] + 1e-6
    inside = within_limits(stance.robot, q)
    assert inside[j] == model.upperPositionLimit[j]
    others = np.arange(model.nq) != j
    assert np.array_equal(inside[others], q[others])
    assert np.array_equal(within_limits(stance.robot, stance.q), np.asarray(stance.q))


@pytest.mark.slow
def test_a_search_whose_steps_brush_a_joint_limit_finishes_within_the_limits():
    # JVRC-1 on the fourth held-out set: the QP's steps left a joint 1.03e-6 rad past a limit,
    # which pink refuses at the next step; the search projects each step into the limits.
    from pathlib import Path

    path = (
        Path(__file__).parents[2] / "studies" / "held_out_4" / "jvrc1_wide_ramp_left_hand_side.yaml"
    )
    stance = analyze(load_scenario(str(path)).replace(zmp_margin=0.0)).stance
    reach = com_reach(stance)  # the fourth set's search, which met the limit
    model = stance.robot.model
    assert np.all(reach.radii > 0.0)
    for q in reach.postures:
        assert np.all(q[7:] >= model.lowerPositionLimit[7:] - 1e-12)
        assert np.all(q[7:] <= model.upperPositionLimit[7:] + 1e-12)


def _square(omega: float, extent: float) -> Polygon:
    return Polygon.from_points(np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * omega * extent)


@settings(max_examples=30, deadline=None)
@given(
    radii=st.lists(st.floats(0.01, 0.3), min_size=8, max_size=8),
    jumps=st.lists(
        st.tuples(st.floats(-1, 1), st.floats(-1, 1)).filter(lambda d: math.hypot(*d) > 0.05),
        min_size=1,
        max_size=6,
    ),
)
def test_the_max_speed_from_rest_stops_every_vertex_within_its_reach(radii, jumps):
    # Independent of the formula: each vertex's LIPM integrated along its own direction.
    from impact_balance.balance.reach import reach_max_speed

    omega, extent = 3.3, 0.12
    area = _square(omega, extent)
    reach = evenly_spaced_reach(radii)
    d = np.array(jumps)
    s = reach_max_speed(area, omega, reach, [0.0, 0.0], d, upper=50.0)

    def stops_within(speed: float) -> bool:
        for dj in d:
            v = speed * dj
            u = v / np.linalg.norm(v)
            e = ray_extent(area, u) / omega
            if stop_distance(float(np.linalg.norm(v)), e, omega) > reach.along(u) + 1e-9:
                return False
        return True

    assert stops_within(0.995 * s)
    assert not stops_within(1.01 * s)


def test_the_max_speed_away_from_rest_is_the_first_speed_out_of_reach():
    from impact_balance.balance.reach import reach_max_speed

    omega, extent = 3.3, 0.12
    area = _square(omega, extent)
    reach = evenly_spaced_reach(np.full(8, 0.05))
    start = np.array([0.05, 0.02])
    d = np.array([[0.3, 0.1], [0.2, -0.2]])
    s = reach_max_speed(area, omega, reach, start, d, upper=5.0)
    limit = reach_speed_limit
    for t in np.linspace(0.0, s, 50):  # every speed below it is within reach
        for v in start + t * d:
            assert np.linalg.norm(v) <= limit(area, omega, reach, v) + 1e-9
    out = start + (s + 1e-6) * d
    assert any(np.linalg.norm(v) > limit(area, omega, reach, v) for v in out)
    assert reach_max_speed(area, omega, reach, [10.0, 0.0], d, upper=5.0) == 0.0


@settings(max_examples=40, deadline=None)
@given(
    radii=st.lists(st.floats(0.01, 0.5), min_size=8, max_size=8),
    start=st.tuples(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2)),
    jumps=st.lists(
        st.tuples(st.floats(-1, 1), st.floats(-1, 1)).filter(lambda d: math.hypot(*d) > 0.05),
        min_size=1,
        max_size=6,
    ),
)
def test_the_max_speed_from_a_moving_com_ends_where_a_vertex_leaves_the_reach(radii, start, jumps):
    # Checked with the scalar limit, vertex by vertex: within at the answer, out just above it.
    from impact_balance.balance.reach import reach_max_speed

    omega, extent, upper = 3.3, 0.12, 2.0
    area = _square(omega, extent)
    reach = evenly_spaced_reach(radii)
    c0, d = np.array(start), np.array(jumps)

    def within(speed: float) -> bool:
        return all(
            np.linalg.norm(v) <= reach_speed_limit(area, omega, reach, v) + 1e-9
            for v in c0 + speed * d
            if np.linalg.norm(v) > 1e-9
        )

    s = reach_max_speed(area, omega, reach, c0, d, upper=upper)
    if not within(0.0):
        assert s == 0.0
        return
    assert 0.0 <= s <= upper and within(s)
    if s < upper:
        assert not within(s + 1e-6)
    if min(radii) >= math.sqrt(2) * extent:  # the reach never binds: the square's own exit
        G, h = area.halfplanes
        exits = [
            min((hk - gk @ c0) / (gk @ dj) for gk, hk in zip(G, h, strict=True) if gk @ dj > 1e-12)
            for dj in d
        ]
        assert s == pytest.approx(min(upper, *exits), abs=1e-12)
