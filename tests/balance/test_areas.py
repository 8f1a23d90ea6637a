"""ZMP support area, CoM velocity area and resultant-force area of stances.

Expected values come from (i) statics: with level coplanar contacts and ample friction the
ZMP area is the convex hull of the sole corners; with a single level contact it is the sole
rectangle intersected with the friction square around the CoM; (ii) invariances and
monotonicity; (iii) pypoman's independent Bretl projection of the same polytope; (iv) LP
feasibility with scipy.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from impact_balance.balance.areas import MERGE_TOLERANCE, areas_from_polytope, balance_areas
from impact_balance.contacts.wrench_polytope import (
    contact_polytope,
    torque_limit_rows,
    wrench_polytope,
)
from impact_balance.exceptions import ScenarioError
from impact_balance.projection import project_polytope
from impact_balance.scenario import bundled_scenarios, load_scenario

G = 9.81
MASS = 60.0


def Rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def Ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


# name: list of (position, rotation, mu, size), com
SYNTHETIC = {
    "two_level": (
        [
            ((0.0, 0.1, 0.0), Rz(math.radians(10)), 0.7, (0.2, 0.1)),
            ((0.05, -0.1, 0.0), Rz(math.radians(-5)), 0.7, (0.2, 0.1)),
        ],
        (0.02, 0.01, 0.8),
    ),
    "one_foot": ([((0.0, 0.0, 0.0), np.eye(3), 0.7, (0.2, 0.1))], (0.01, 0.01, 0.8)),
    # right foot on a 30 degree ramp rising along +x, 10 cm higher
    "ramp": (
        [
            ((0.0, 0.1, 0.0), np.eye(3), 0.7, (0.2, 0.1)),
            ((0.3, -0.1, 0.1), Ry(math.radians(-30)), 0.7, (0.2, 0.1)),
        ],
        (0.1, 0.0, 0.8),
    ),
    # two level feet and a hand on a wall in front (contact normal -x), above the CoM
    "wall": (
        [
            ((0.0, 0.1, 0.0), np.eye(3), 0.7, (0.2, 0.1)),
            ((0.0, -0.1, 0.0), np.eye(3), 0.7, (0.2, 0.1)),
            ((0.4, 0.2, 1.3), Ry(math.radians(-90)), 0.2, (0.1, 0.1)),
        ],
        (0.05, 0.0, 0.85),
    ),
    # single foot, CoM 1 m in front: friction decides (see test_far_com_*)
    "far_com": ([((0.0, 0.0, 0.0), np.eye(3), 1.2, (0.2, 0.1))], (1.0, 0.0, 0.8)),
}


def synthetic(make_contact, name, mu_scale=1.0, size_scale=1.0, yaw=0.0, shift=(0.0, 0.0, 0.0)):
    """Contacts and CoM of a named stance, optionally scaled, yawed about world z and shifted."""
    specs, com = SYNTHETIC[name]
    T = Rz(yaw)
    contacts = [
        make_contact(
            T @ np.asarray(p) + shift,
            T @ R,
            mu * mu_scale,
            (size[0] * size_scale, size[1] * size_scale),
        )
        for p, R, mu, size in specs
    ]
    return contacts, T @ np.asarray(com) + shift


def areas_of(make_contact, name, plane_height=0.0, **kw):
    contacts, com = synthetic(make_contact, name, **kw)
    return areas_from_polytope(contact_polytope(contacts, MASS, com), plane_height)


def sole_corners_xy(position, yaw, size):
    """Corners of a level rectangle of full size (L, W) yawed by `yaw` (world xy)."""
    L, W = size
    local = np.array([[L, W], [-L, W], [-L, -W], [L, -W]]) / 2
    c, s = math.cos(yaw), math.sin(yaw)
    return np.asarray(position[:2]) + local @ np.array([[c, s], [-s, c]])


def rotate2(points, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    return np.asarray(points).reshape(-1, 2) @ np.array([[c, s], [-s, c]])


def assert_same_polygon(geo, got, expected, tol, rel_area=1e-6):
    got = np.asarray(got).reshape(-1, 2)
    assert geo.hausdorff(got, expected) <= tol
    a_exp = geo.area(geo.hull(expected))
    assert geo.area(geo.hull(got)) == pytest.approx(a_exp, rel=rel_area, abs=tol * tol)


def assert_nested(geo, inner, outer, tol=1e-8):
    """Every vertex of `inner` lies in `outer` (convex), and the area does not grow."""
    hull = geo.hull(outer.vertices)
    for v in inner.vertices:
        assert geo.distance(v, hull) <= tol
    assert inner.area <= outer.area * (1 + 1e-9) + tol * tol


# (a) analytic: level coplanar contacts, ample friction -----------------------------------
@pytest.mark.parametrize("height", [0.0, 0.1])
def test_level_coplanar_zmp_area_is_hull_of_sole_corners(geo, make_contact, height):
    feet = [
        ((0.0, 0.1), math.radians(10)),
        ((0.05, -0.1), math.radians(-5)),
        ((-0.02, 0.35), math.radians(30)),
    ]
    size = (0.2, 0.1)
    contacts = [make_contact((x, y, height), Rz(a), 5.0, size) for (x, y), a in feet]
    com = np.array([0.02, 0.08, height + 0.8])
    res = areas_from_polytope(contact_polytope(contacts, MASS, com), plane_height=height)
    hull = geo.hull(np.vstack([sole_corners_xy(p, a, size) for p, a in feet]))
    omega = math.sqrt(G / 0.8)
    assert res.omega == pytest.approx(omega, rel=1e-12)
    assert res.zmp_area.bounded and res.can_balance
    assert len(res.zmp_area.vertices) == len(hull)
    assert_same_polygon(geo, res.zmp_area.vertices, hull, tol=1e-7)
    assert res.zmp_area.area == pytest.approx(geo.area(hull), rel=1e-6)
    assert_same_polygon(
        geo, res.com_velocity_area.vertices, omega * (hull - com[:2]), tol=1e-7 * omega
    )
    # force / (m g) = (zmp - c_xy) / (h - c_z)
    assert_same_polygon(
        geo, res.force_area.vertices, (hull - com[:2]) / (height - com[2]), tol=1e-7
    )


def test_areas_are_affine_images_of_the_force_area(geo, make_contact):
    h = -0.05
    res = areas_of(make_contact, "ramp", plane_height=h)
    c = res.com
    omega = math.sqrt(G / (c[2] - h))
    assert res.omega == pytest.approx(omega, rel=1e-12)
    F = res.force_area.vertices
    assert_same_polygon(geo, res.zmp_area.vertices, c[:2] + (h - c[2]) * F, tol=1e-9)
    assert_same_polygon(geo, res.com_velocity_area.vertices, omega * (h - c[2]) * F, tol=1e-9)


def test_plane_must_be_below_the_com(make_contact):
    contacts, com = synthetic(make_contact, "one_foot")
    with pytest.raises(ScenarioError):
        areas_from_polytope(contact_polytope(contacts, MASS, com), plane_height=com[2])


def test_talos_zmp_area_is_close_to_sole_hull(geo, talos_stance):
    """Talos soles are ~0.1 mm off the plane and rolled by 1.7 mrad: the ZMP area (no torque
    limits, friction not binding) matches the hull of the sole corners to ~1e-5 m."""
    res = balance_areas(talos_stance, 0.0, torque_limits=False)
    corners = np.vstack([c.corners() for c in talos_stance.contacts])
    assert np.max(np.abs(corners[:, 2])) < 2e-4
    assert geo.hausdorff(res.zmp_area.vertices, corners[:, :2]) <= 1e-4
    assert res.zmp_area.contains(talos_stance.com[:2])
    assert res.com_velocity_area.contains(np.zeros(2))


# (b) monotonicity -----------------------------------------------------------------------
@pytest.mark.parametrize("name", ["two_level", "ramp", "wall", "far_com"])
def test_more_friction_never_shrinks(geo, make_contact, name):
    areas = [areas_of(make_contact, name, mu_scale=s).force_area for s in (0.7, 1.0, 1.5, 3.0)]
    assert not areas[-1].is_empty
    for small, big in itertools.pairwise(areas):  # (clipping to the same box keeps inclusions)
        assert_nested(geo, small, big)


@pytest.mark.parametrize("name", ["two_level", "one_foot", "ramp", "wall", "far_com"])
def test_bigger_soles_never_shrink(geo, make_contact, name):
    areas = [areas_of(make_contact, name, size_scale=s).force_area for s in (0.5, 1.0, 1.3, 2.0)]
    for small, big in itertools.pairwise(areas):
        assert_nested(geo, small, big)
    assert areas[-1].area > areas[0].area  # the CoP rows matter in every one of these


def _talos_polytope(stance, scale):
    """Talos polytope with every effort limit multiplied by `scale` (None: no torque rows)."""
    base = wrench_polytope(stance, torque_limits=False)
    if scale is None:
        return base
    A_tau, _ = torque_limit_rows(stance)
    idx, limit = stance.robot.actuated_effort_limits()
    g = stance.gravity_torques[idx]
    b_tau = np.concatenate([scale * limit + g, scale * limit - g])
    return replace(base, A=np.vstack([base.A, A_tau]), b=np.concatenate([base.b, b_tau]))


def test_torque_limits_never_grow_the_area(geo, talos_stance):
    free = balance_areas(talos_stance, 0.0, torque_limits=False)
    limited = balance_areas(talos_stance, 0.0, torque_limits=True)
    assert_nested(geo, limited.force_area, free.force_area)
    assert_nested(geo, limited.zmp_area, free.zmp_area)
    # the library's own torque rows are the URDF limits (scale 1)
    same = areas_from_polytope(_talos_polytope(talos_stance, 1.0))
    assert geo.hausdorff(same.force_area.vertices, limited.force_area.vertices) <= 1e-9


def test_tighter_torque_limits_are_nested_and_empty_iff_infeasible(geo, talos_stance):
    previous = areas_from_polytope(_talos_polytope(talos_stance, None)).force_area
    for scale in (1.0, 0.5, 0.35, 0.25, 0.15):
        P = _talos_polytope(talos_stance, scale)
        force = areas_from_polytope(P).force_area
        lp = linprog(
            np.zeros(P.dim),
            A_ub=P.A,
            b_ub=P.b / P.weight,
            A_eq=P.C,
            b_eq=P.d / P.weight,
            bounds=(None, None),
            method="highs",
        )
        assert lp.status in (0, 2)
        assert force.is_empty == (lp.status == 2), f"scale {scale}"
        if previous.is_empty:  # once infeasible, tighter limits stay infeasible
            assert force.is_empty
        else:
            assert_nested(geo, force, previous)
        previous = force


def _independent_talos_polytope(stance, scale):
    """Talos wrench polytope rebuilt without impact_balance.contacts.wrench_polytope: joint torques
    from pinocchio's RNEA with the contact wrenches as external forces, LIPM rows by hand. Returns
    (A, b, C, d, F) in units of m g."""
    import pinocchio as pin

    from impact_balance.contacts.cwc import cwc_faces_world

    model = stance.robot.model
    data = model.createData()
    q = stance.q
    pin.framesForwardKinematics(model, data, q)
    frames = [model.getFrameId(name) for name in ("left_sole_link", "right_sole_link")]
    poses = [data.oMf[f] for f in frames]
    mass = sum(inertia.mass for inertia in model.inertias)
    com = pin.centerOfMass(model, data, q)
    mg = mass * G
    zero = np.zeros(model.nv)

    def torques(w):  # w: stacked [f; tau] at each sole origin, world axes, in units of m g
        fext = pin.StdVec_Force()
        for _ in range(model.njoints):
            fext.append(pin.Force.Zero())
        for k, (f, pose) in enumerate(zip(frames, poses, strict=True)):
            force, moment = w[6 * k : 6 * k + 3] * mg, w[6 * k + 3 : 6 * k + 6] * mg
            world = pin.Force(force, moment + np.cross(pose.translation, force))  # about the origin
            joint = model.frames[f].parentJoint
            fext[joint] = fext[joint] + data.oMi[joint].actInv(world)
        return pin.rnea(model, data, q, zero, zero, fext)

    g = torques(np.zeros(12))
    M = np.column_stack([torques(e) - g for e in np.eye(12)])  # tau = g + M w
    limits = np.asarray(model.effortLimit, dtype=float)
    act = [j for j in range(6, model.nv) if 0 < limits[j] < 1e300]
    lim = scale * limits[act] / mg
    A_tau = np.vstack([M[act], -M[act]]) / mg
    b_tau = np.concatenate([lim - g[act] / mg, lim + g[act] / mg])
    A_cwc = np.zeros((32, 12))
    for k, pose in enumerate(poses):
        A_cwc[16 * k : 16 * k + 16, 6 * k : 6 * k + 6] = cwc_faces_world(
            0.7, 0.1, 0.05, pose.rotation
        )
    C = np.zeros((4, 12))
    F = np.zeros((2, 12))
    for k, pose in enumerate(poses):
        r = pose.translation - com
        C[0, 6 * k + 2] = 1.0  # total f_z = m g
        C[1:, 6 * k : 6 * k + 3] = np.array(
            [[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]
        )  # r x f
        C[1:, 6 * k + 3 : 6 * k + 6] = np.eye(3)
        F[:, 6 * k : 6 * k + 2] = np.eye(2)
    d = np.array([1.0, 0, 0, 0])
    return np.vstack([A_cwc, A_tau]), np.concatenate([np.zeros(32), b_tau]), C, d, F, len(act)


@pytest.mark.parametrize("scale", [1.0, 0.3])
def test_talos_force_area_matches_an_independent_rnea_model(geo, talos_stance, scale):
    """The whole pipeline (stance, torque rows, LIPM rows, projection) against LPs on a
    polytope built with RNEA: each vertex is feasible and nothing lies beyond any edge."""
    A, b, C, d, F, n_limited = _independent_talos_polytope(talos_stance, scale)
    assert n_limited == 32
    force = areas_from_polytope(_talos_polytope(talos_stance, scale)).force_area
    if scale == 1.0:
        lib = balance_areas(talos_stance, 0.0, torque_limits=True).force_area
        assert geo.hausdorff(lib.vertices, force.vertices) <= 1e-9
    v = force.vertices
    assert len(v) >= 3
    for y in v:  # min ||F w - y||_inf over the independent polytope
        c = np.zeros(13)
        c[-1] = 1
        A_ub = np.block([[A, np.zeros((len(A), 1))], [F, -np.ones((2, 1))], [-F, -np.ones((2, 1))]])
        r = linprog(
            c,
            A_ub=A_ub,
            b_ub=np.concatenate([b, y, -y]),
            A_eq=np.hstack([C, np.zeros((4, 1))]),
            b_eq=d,
            bounds=(None, None),
            method="highs",
        )
        assert r.status == 0 and r.fun <= 1e-7
    edges = np.roll(v, -1, axis=0) - v
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    angles = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    for u in np.vstack([normals, np.column_stack([np.cos(angles), np.sin(angles)])]):
        r = linprog(-(F.T @ u), A_ub=A, b_ub=b, A_eq=C, b_eq=d, bounds=(None, None), method="highs")
        assert r.status == 0
        assert abs(-r.fun - np.max(v @ u)) <= 1e-7


# (c) invariance under yaw and horizontal translation --------------------------------------
@settings(max_examples=25, deadline=None)
@given(name=st.sampled_from(["two_level", "ramp", "wall"]), yaw=st.floats(-math.pi, math.pi))
def test_yaw_rotates_the_areas(geo, make_contact, name, yaw):
    ref = areas_of(make_contact, name)
    rot = areas_of(make_contact, name, yaw=yaw)
    for a, b in [
        (ref.force_area, rot.force_area),
        (ref.zmp_area, rot.zmp_area),
        (ref.com_velocity_area, rot.com_velocity_area),
    ]:
        scale = max(1.0, float(np.max(np.abs(a.vertices))))
        assert_same_polygon(geo, b.vertices, rotate2(a.vertices, yaw), tol=1e-7 * scale)
        assert b.area == pytest.approx(a.area, rel=1e-6)


@pytest.mark.parametrize("name", ["ramp", "wall"])
def test_horizontal_translation_moves_only_the_zmp_area(geo, make_contact, name):
    shift = np.array([0.7, -1.3, 0.0])
    ref = areas_of(make_contact, name)
    moved = areas_of(make_contact, name, shift=shift)
    assert_same_polygon(geo, moved.zmp_area.vertices, ref.zmp_area.vertices + shift[:2], tol=1e-7)
    assert_same_polygon(geo, moved.force_area.vertices, ref.force_area.vertices, tol=1e-7)
    assert_same_polygon(
        geo, moved.com_velocity_area.vertices, ref.com_velocity_area.vertices, tol=1e-7
    )


# (d) against pypoman -----------------------------------------------------------------------
def pypoman_force_area(P, scale=1e3):
    """pypoman's Bretl projection of (A, b/mg, C, d/mg) onto F. Its stopping rule is an
    absolute 1e-4 and it drops vertices closer than 1e-2, so project onto scale * F."""
    pytest.importorskip("cdd", reason="needs pycddlib-standalone (the test extra)")
    pytest.importorskip("cvxopt", reason="needs cvxopt (the test extra)")
    pypoman = pytest.importorskip("pypoman", reason="needs pypoman (the test extra, --no-deps)")
    np.random.seed(12345)  # noqa: NPY002 (pypoman draws its first ray from numpy's global generator)
    w = P.weight
    V = pypoman.project_polytope(
        proj=(scale * P.F, np.zeros(2)),
        ineq=(P.A, P.b / w),
        eq=(P.C, P.d / w),
        method="bretl",
        max_radius=1e4 * scale,
    )
    return np.array(V) / scale


@pytest.fixture(
    scope="module", params=["two_level", "one_foot", "ramp", "wall", "talos", "talos_tight"]
)
def stance_polytope(request, make_contact, talos_stance):
    if request.param == "talos":
        return wrench_polytope(talos_stance, torque_limits=True)
    if request.param == "talos_tight":  # effort limits at 30 %: the torque rows are active
        return _talos_polytope(talos_stance, 0.3)
    contacts, com = synthetic(make_contact, request.param)
    return contact_polytope(contacts, MASS, com)


def test_force_and_com_velocity_areas_match_pypoman(geo, stance_polytope):
    P = stance_polytope
    res = areas_from_polytope(P)
    assert res.force_area.bounded and len(res.force_area.vertices) >= 3
    ref = geo.hull(pypoman_force_area(P))
    size = float(np.max(np.linalg.norm(ref - ref.mean(axis=0), axis=1)))
    assert res.force_area.area == pytest.approx(geo.area(ref), rel=1e-6)
    assert geo.hausdorff(res.force_area.vertices, ref) <= 1e-6 * size
    k = math.sqrt(G / P.com[2]) * (0.0 - P.com[2])  # velocity = omega (h - c_z) force / (m g)
    assert res.com_velocity_area.area == pytest.approx(geo.area(ref) * k * k, rel=1e-6)
    assert geo.hausdorff(res.com_velocity_area.vertices, k * ref) <= 1e-6 * size * abs(k)


@pytest.mark.parametrize("torque_limits", [True, False])
@pytest.mark.parametrize("name", sorted(bundled_scenarios()))
def test_walk_and_bretl_agree_on_every_bundled_stance(geo, name, torque_limits):
    """The default projection (the parametric walk) answers by itself, without falling back,
    and equals the LP-per-edge Bretl projection of the same polytope."""
    sc = load_scenario(name)
    P = wrench_polytope(sc.build_stance(), torque_limits, sc.gravity)
    args = (P.A, P.b / P.weight, P.C, P.d / P.weight, P.F)
    walk = project_polytope(*args, method="walk", merge_tol=MERGE_TOLERANCE)
    bretl = project_polytope(*args, method="bretl", merge_tol=MERGE_TOLERANCE)
    assert walk.method == "walk" and bretl.method == "bretl"
    size = float(np.max(np.abs(bretl.polygon.vertices)))
    assert_same_polygon(geo, walk.polygon.vertices, bretl.polygon.vertices, tol=1e-7 * size)
    assert walk.polygon.bounded == bretl.polygon.bounded


# (e) CoM far outside the support: single level contact ------------------------------------
def clip(poly, normal, offset):
    """Sutherland-Hodgman: keep {x : normal . x <= offset} of a convex CCW polygon.

    The crossing point is computed from the two signed distances (of opposite signs, so their
    difference is not zero and the point lies on the edge), also for an edge that lies on the
    line up to rounding.
    """
    out = []
    for i in range(len(poly)):
        P, Q = poly[i], poly[(i + 1) % len(poly)]
        dP, dQ = normal @ P - offset, normal @ Q - offset
        inP, inQ = dP <= 0, dQ <= 0
        if inP:
            out.append(P)
        if inP != inQ:
            out.append(P + dP / (dP - dQ) * (Q - P))
    return np.array(out).reshape(-1, 2)


def single_foot_zmp_area(position, yaw, size, mu, com, slack=0.0):
    """Rectangle of the sole intersected with the friction square: the force through the
    CoM and the ZMP z has f_xy = m g (c - z)_xy / c_z, and |f_x|, |f_y| <= mu m g in sole axes."""
    poly = sole_corners_xy(position, yaw, size)
    height = com[2] - position[2]
    for axis in (
        np.array([math.cos(yaw), math.sin(yaw)]),
        np.array([-math.sin(yaw), math.cos(yaw)]),
    ):
        for sign in (1, -1):  # sign * axis . (z - c) <= mu height
            poly = clip(poly, sign * axis, sign * axis @ com[:2] + mu * height + slack)
            if len(poly) == 0:
                return poly
    return poly


def test_far_com_is_empty_with_low_friction(make_contact):
    # |f_x| / (m g) = (1 - z_x) / 0.8 >= 1.125 everywhere on the sole: mu = 0.3 cannot do it
    res = areas_of(make_contact, "far_com", mu_scale=0.3 / 1.2)
    assert res.zmp_area.is_empty and res.com_velocity_area.is_empty and res.force_area.is_empty
    assert not res.can_balance


def test_far_com_with_ample_friction_zmp_area_is_the_sole(geo, make_contact):
    res = areas_of(make_contact, "far_com", mu_scale=2.0 / 1.2)  # mu 2 >= 1.375
    rect = np.array([[-0.1, -0.05], [0.1, -0.05], [0.1, 0.05], [-0.1, 0.05]])
    omega = math.sqrt(G / 0.8)
    com = np.array([1.0, 0.0])
    assert_same_polygon(geo, res.zmp_area.vertices, rect, tol=1e-7)
    assert_same_polygon(geo, res.com_velocity_area.vertices, omega * (rect - com), tol=1e-7 * omega)
    assert res.can_balance  # a nonempty area ...
    assert not res.com_velocity_area.contains(np.zeros(2))  # ... but not from rest at this CoM
    assert geo.distance(np.zeros(2), geo.hull(omega * (rect - com))) == pytest.approx(
        omega * 0.9, rel=1e-7
    )


def test_far_com_with_limited_friction_clips_the_sole(geo, make_contact):
    # mu 1.2: z_x >= 1 - 0.8 * 1.2 = 0.04
    res = areas_of(make_contact, "far_com")
    expected = np.array([[0.04, -0.05], [0.1, -0.05], [0.1, 0.05], [0.04, 0.05]])
    assert_same_polygon(geo, res.zmp_area.vertices, expected, tol=1e-7)


@settings(max_examples=40, deadline=None)
@given(
    u=st.floats(-6, 6),
    v=st.floats(-6, 6),
    cz=st.floats(0.4, 1.0),
    mu=st.floats(0.1, 1.5),
    yaw=st.floats(-math.pi, math.pi),
    length=st.floats(0.05, 0.3),
    width=st.floats(0.05, 0.3),
)
# Sole edges on the friction square's lines (mu * cz = half the width): the reference's clip.
@example(u=0.0, v=0.0, cz=0.5, mu=0.125, yaw=2.0, length=0.05, width=0.125)
@example(u=0.0, v=0.0, cz=0.5, mu=0.125, yaw=2.0, length=0.25, width=0.125)
def test_single_level_contact_matches_statics(geo, make_contact, u, v, cz, mu, yaw, length, width):
    """CoM at (u, v) half-sizes from the sole centre in sole axes: inside, near or far."""
    position = np.array([0.1, -0.2, 0.05])
    offset = Rz(yaw)[:2, :2] @ np.array([u * length / 2, v * width / 2])
    com = np.array([position[0] + offset[0], position[1] + offset[1], position[2] + cz])
    inner = single_foot_zmp_area(position, yaw, (length, width), mu, com, slack=-1e-6)
    outer = single_foot_zmp_area(position, yaw, (length, width), mu, com, slack=+1e-6)
    assume((len(inner) >= 3 and geo.area(inner) > 1e-8) or len(outer) == 0)  # not borderline
    expected = single_foot_zmp_area(position, yaw, (length, width), mu, com)
    contact = make_contact(position, Rz(yaw), mu, (length, width))
    res = areas_from_polytope(contact_polytope([contact], MASS, com), plane_height=position[2])
    if len(outer) == 0:
        assert res.zmp_area.is_empty and not res.can_balance
        return
    assert_same_polygon(geo, res.zmp_area.vertices, expected, tol=1e-7, rel_area=1e-5)
    omega = math.sqrt(G / cz)
    assert_same_polygon(
        geo,
        res.com_velocity_area.vertices,
        omega * (expected - com[:2]),
        tol=1e-7 * omega,
        rel_area=1e-5,
    )
    margin = geo.distance(com[:2], geo.hull(expected))
    com_inside = margin == 0.0
    if com_inside or margin > 1e-6:  # from rest iff the CoM is above the ZMP area
        assert res.com_velocity_area.contains(np.zeros(2)) == com_inside


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.floats(-2, 2), st.floats(-2, 2)), min_size=1, max_size=12),
    st.floats(-1.5, -0.2),
    st.floats(-3, 3),
    st.floats(-3, 3),
    st.floats(1.0, 8.0),
    st.sampled_from([0.0, 1e-3, 0.02, 0.3]),
    st.booleans(),
)
def test_compiled_maps_give_the_polygon_methods_numbers(points, depth, cx, cy, w, margin, bounded):
    """The compiled areas pipeline's maps (``areas._maps``) are Polygon.affine and
    Polygon.inset, number for number: the governor and analyze() read the same areas."""
    from impact_balance.balance.areas import _maps
    from impact_balance.geometry.polygon import Polygon

    force = Polygon(Polygon.from_points(np.array(points)).vertices, bounded)
    zmp, zmp_bounded, vel, vel_bounded = _maps(
        np.ascontiguousarray(force.vertices), bounded, depth, cx, cy, w, margin
    )
    if force.is_empty:
        want_zmp = want_vel = Polygon.empty()
    elif margin > 0.0:
        want_zmp = force.affine(depth, np.array([cx, cy])).inset(margin)
        want_vel = (
            Polygon.empty() if want_zmp.is_empty else want_zmp.affine(w, -w * np.array([cx, cy]))
        )
    else:
        want_zmp = force.affine(depth, np.array([cx, cy]))
        want_vel = force.affine(w * depth, np.zeros(2))
    np.testing.assert_array_equal(zmp, want_zmp.vertices)
    np.testing.assert_array_equal(vel, want_vel.vertices)
    assert (zmp_bounded, vel_bounded) == (want_zmp.bounded, want_vel.bounded)


@pytest.mark.parametrize("name", ["palm_push_ramp", "g1_two_feet"])
@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_velocity_area_halfplanes_from_the_compiled_pipeline_are_the_polygons_own(name, margin):
    """The CoM velocity area comes with the half-planes the compiled pipeline computed; they
    are the ones the polygon computes itself from its vertices."""
    from impact_balance.geometry.polygon import Polygon

    scenario = load_scenario(name)
    stance = scenario.build_stance()
    areas = areas_from_polytope(wrench_polytope(stance), scenario.plane_height, margin)
    G, h = areas.com_velocity_area.halfplanes
    G2, h2 = Polygon(
        areas.com_velocity_area.vertices.copy(), areas.com_velocity_area.bounded
    ).halfplanes
    assert len(G) >= 3
    np.testing.assert_array_equal(G, G2)
    np.testing.assert_array_equal(h, h2)


@pytest.mark.parametrize("name", ["palm_push_ramp", "g1_two_feet", "kick_one_foot"])
@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_areas_from_arrays_is_areas_from_polytope_number_for_number(name, margin):
    """The governor's one-call path (assembly and projection in one compiled call) gives the
    areas analyze() gets from the assembled polytope, exactly; plain lists are accepted."""
    from impact_balance.balance.areas import areas_from_arrays
    from impact_balance.contacts.cwc import local_faces

    scenario = load_scenario(name)
    stance = scenario.build_stance()
    want = areas_from_polytope(wrench_polytope(stance), scenario.plane_height, margin)
    faces = np.array(
        [local_faces(float(c.spec.friction), c.half_length, c.half_width) for c in stance.contacts]
    ).reshape(-1, 16, 6)
    idx, limit = stance.robot.effort_limits
    arms = np.array([c.local_position for c in stance.contacts]) - stance.com_local
    got = areas_from_arrays(
        faces,
        [c.rotation for c in stance.contacts],
        [list(c.position) for c in stance.contacts],
        arms.tolist(),
        stance.mass,
        stance.com,
        9.81,
        np.concatenate([c.jacobian for c in stance.contacts]),
        list(idx),
        list(limit),
        list(stance.gravity_torques),
        scenario.plane_height,
        margin,
    )
    for which in ("force_area", "zmp_area", "com_velocity_area"):
        np.testing.assert_array_equal(getattr(got, which).vertices, getattr(want, which).vertices)
        assert getattr(got, which).bounded == getattr(want, which).bounded
    assert (got.omega, got.mass, got.n_lp) == (want.omega, want.mass, want.n_lp)
