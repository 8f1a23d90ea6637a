"""The batch's compiled kinematics (tree_kernel) against pinocchio: the same contact poses,
Jacobians, CoM, m J_com, composite inertia, impact point and omega to rounding; models it cannot
compute are said so, and the batch then calls pinocchio."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impact_balance._jit import HAVE_NUMBA
from impact_balance.balance.lipm import lipm_omega
from impact_balance.governor import Governor, tree_kernel
from impact_balance.governor import batch as batch_module
from impact_balance.governor.batch import BLOCK, _Buffers
from impact_balance.governor.tree_kernel import KinematicTree, tree_postures

SCENARIOS = ("palm_push_two_feet", "kick_one_foot", "g1_two_feet")
_GOVERNORS: dict[str, Governor] = {}


def governor(name: str) -> Governor:
    if name not in _GOVERNORS:
        _GOVERNORS[name] = Governor(name)
    return _GOVERNORS[name]


def random_configurations(model: pin.Model, n: int, seed: int, spread: float) -> np.ndarray:
    """``n`` configurations: joints anywhere in [-spread, spread] rad, the base anywhere within
    2 m of the origin (a few km for one row), any unit base quaternion."""
    rng = np.random.default_rng(seed)
    qs = np.empty((n, model.nq))
    for k in range(n):
        q = pin.neutral(model)
        for j in range(1, model.njoints):
            joint = model.joints[j]
            if joint.shortname() == "JointModelFreeFlyer":
                quat = rng.normal(size=4)
                q[joint.idx_q : joint.idx_q + 3] = rng.uniform(-2.0, 2.0, 3)
                q[joint.idx_q + 3 : joint.idx_q + 7] = quat / np.linalg.norm(quat)
            else:
                q[joint.idx_q] = rng.uniform(-spread, spread)
        qs[k] = q
    if n > 1 and model.joints[1].shortname() == "JointModelFreeFlyer":
        qs[1, :3] = (3e3, -2e3, 5.0)
    return qs


def run_tree(tree: KinematicTree, qs, m, nv, free_flyer, torques, plane=-10.0, gravity=9.81):
    n = len(qs)
    out = {
        "rotations": np.zeros((n, m, 3, 3)),
        "local": np.zeros((n, m, 3)),
        "jacobians": np.zeros((n, 6 * m, nv)) if torques else np.zeros((n, 0, 0)),
        "origins": np.zeros((n, 3)),
        "com_locals": np.zeros((n, 3)),
        "centroidal": np.zeros((n, 6, nv)),
        "point_locals": np.zeros((n, 3)),
        "point_jacobians": np.zeros((n, 3, nv)),
        "inertias": np.zeros((n, 3, 3)),
        "scalars": np.zeros((n, 6)),
    }
    low = tree_postures(
        tree.parents, tree.kinds, tree.idx_q, tree.idx_v, tree.placements, tree.masses,
        tree.levers, tree.inertias, tree.frame_joints, tree.frame_placements, qs, free_flyer,
        torques, plane, gravity, *out.values(),
    )  # fmt: skip
    return low, out


def pinocchio_reference(model, frames, impact_frame, q, free_flyer):
    """The same quantities by pinocchio's own algorithms (independent of ccrba's use in the
    evaluator: the CoM Jacobian by jacobianCenterOfMass, the inertia by ccrba)."""
    data = model.createData()
    q_local = q.copy()
    origin = q[:3].copy() if free_flyer else np.zeros(3)
    if free_flyer:
        q_local[:3] = 0.0
    pin.ccrba(model, data, q_local, np.zeros(model.nv))
    com = pin.centerOfMass(model, data, q_local).copy()
    J_com = pin.jacobianCenterOfMass(model, data, q_local)
    pin.computeJointJacobians(model, data, q_local)
    pin.updateFramePlacements(model, data)
    rotations = [data.oMf[f].rotation.copy() for f in frames]
    points = [data.oMf[f].translation.copy() for f in frames]
    jac = [
        pin.getFrameJacobian(model, data, f, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED) for f in frames
    ]
    point = data.oMf[impact_frame].translation.copy()
    point_jac = pin.getFrameJacobian(
        model, data, impact_frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )[:3]
    mass = float(data.Ig.mass)
    return (
        origin, com, mass * J_com, data.Ig.inertia.copy(), mass, rotations, points, jac, point,
        point_jac,
    )  # fmt: skip


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(SCENARIOS),
    seed=st.integers(0, 2**32 - 1),
    spread=st.sampled_from([0.05, 1.0, 3.1]),
)
def test_tree_kinematics_equal_pinocchios(name, seed, spread):
    g = governor(name)
    e = g._evaluator
    frames = [*e._frames, e._impact_frame]
    tree = KinematicTree.of(e.model, frames)
    assert tree.supported == HAVE_NUMBA  # interpreted, the governor keeps pinocchio
    m, nv = len(e._frames), e.model.nv
    qs = random_configurations(e.model, 5, seed, spread)
    low, out = run_tree(tree, qs, m, nv, e._free_flyer, True)
    assert low == -1
    for p, q in enumerate(qs):
        origin, com, mJ, inertia, mass, rotations, points, jac, point, point_jac = (
            pinocchio_reference(e.model, e._frames, e._impact_frame, q, e._free_flyer)
        )
        np.testing.assert_array_equal(out["origins"][p], origin)
        np.testing.assert_allclose(out["com_locals"][p], com, rtol=0, atol=1e-13)
        np.testing.assert_allclose(out["centroidal"][p][:3], mJ, rtol=0, atol=1e-12 * mass)
        np.testing.assert_allclose(out["inertias"][p], inertia, rtol=0, atol=1e-12 * mass)
        assert out["scalars"][p, 0] == pytest.approx(mass, rel=1e-14)
        for i in range(m):
            np.testing.assert_allclose(out["rotations"][p][i], rotations[i], rtol=0, atol=1e-14)
            np.testing.assert_allclose(out["local"][p][i], points[i], rtol=0, atol=1e-13)
            np.testing.assert_allclose(
                out["jacobians"][p][6 * i : 6 * i + 6], jac[i], rtol=0, atol=1e-13
            )
        np.testing.assert_allclose(out["point_locals"][p], point, rtol=0, atol=1e-13)
        np.testing.assert_allclose(out["point_jacobians"][p], point_jac, rtol=0, atol=1e-13)
        height = out["com_locals"][p][2] + origin[2]
        assert out["scalars"][p, 3] == pytest.approx(lipm_omega(height, -10.0, 9.81), rel=1e-14)


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), torques=st.booleans())
def test_a_random_humanoid_with_offset_frames(seed, torques):
    # pinocchio's random humanoid: rotated joint placements, random inertias; two frames with
    # offsets of their own on distal joints
    pin.seed(seed % 2**31)
    model = pin.buildSampleModelHumanoidRandom()
    rng = np.random.default_rng(seed)
    frames = []
    for k, joint in enumerate((model.njoints - 1, model.njoints // 2, 3)):
        offset = pin.SE3(pin.rpy.rpyToMatrix(*rng.uniform(-3, 3, 3)), rng.uniform(-0.2, 0.2, 3))
        frames.append(model.addFrame(pin.Frame(f"f{k}", joint, 0, offset, pin.FrameType.OP_FRAME)))
    tree = KinematicTree.of(model, frames)
    assert tree.supported == HAVE_NUMBA
    qs = random_configurations(model, 3, seed, 3.0)
    low, out = run_tree(tree, qs, 2, model.nv, True, torques)
    assert low == -1
    for p, q in enumerate(qs):
        _, com, mJ, inertia, mass, rotations, points, jac, point, point_jac = pinocchio_reference(
            model, frames[:2], frames[2], q, True
        )
        np.testing.assert_allclose(out["com_locals"][p], com, rtol=0, atol=1e-12)
        np.testing.assert_allclose(out["centroidal"][p][:3], mJ, rtol=0, atol=1e-11 * mass)
        np.testing.assert_allclose(out["inertias"][p], inertia, rtol=0, atol=1e-11 * mass)
        np.testing.assert_allclose(out["rotations"][p], np.array(rotations), rtol=0, atol=1e-13)
        np.testing.assert_allclose(out["local"][p], np.array(points), rtol=0, atol=1e-12)
        np.testing.assert_allclose(out["point_locals"][p], point, rtol=0, atol=1e-12)
        np.testing.assert_allclose(out["point_jacobians"][p], point_jac, rtol=0, atol=1e-12)
        if torques:
            np.testing.assert_allclose(out["jacobians"][p], np.vstack(jac), rtol=0, atol=1e-12)


def test_the_first_row_below_the_plane_is_returned():
    g = governor("kick_one_foot")
    e = g._evaluator
    tree = KinematicTree.of(e.model, [*e._frames, e._impact_frame])
    qs = np.tile(g.configuration, (4, 1))
    qs[2, 2] -= 5.0
    qs[3, 2] -= 6.0
    low, out = run_tree(tree, qs, 1, e.model.nv, True, True, plane=0.0)
    assert low == 2
    assert out["scalars"][1, 3] > 0.0


def test_other_joints_are_not_supported(monkeypatch):
    model = pin.Model()
    body = pin.Inertia.Random()
    j = model.addJoint(0, pin.JointModelRX(), pin.SE3.Identity(), "a")
    model.appendBodyToJoint(j, body, pin.SE3.Identity())
    assert KinematicTree.of(model, []).supported == HAVE_NUMBA
    with monkeypatch.context() as patch:  # without numba the governor keeps pinocchio
        patch.setattr(tree_kernel, "HAVE_NUMBA", False)
        assert not KinematicTree.of(model, []).supported
    k = model.addJoint(j, pin.JointModelPX(), pin.SE3.Identity(), "b")
    model.appendBodyToJoint(k, body, pin.SE3.Identity())
    assert not KinematicTree.of(model, []).supported


def test_a_batch_without_the_tree_calls_pinocchio_and_agrees(monkeypatch):
    # The same rows with the tree (the bundled robots) and without it (a model it cannot
    # compute): the same answers to 1e-12 m/s
    g = Governor("palm_push_two_feet")
    rng = np.random.default_rng(4)
    qs = np.tile(g.configuration, (BLOCK + 5, 1))
    qs[:, 7:] += rng.uniform(-0.02, 0.02, (len(qs), g.nq - 7))
    vs = rng.normal(0.0, 0.2, (len(qs), g.nv))
    with_tree = g.limits(qs, vs)
    built = []
    original = _Buffers.__init__

    def without_tree(self, e):
        original(self, e)
        built.append(self.tree is not None)
        self.tree = None

    monkeypatch.setattr(batch_module._Buffers, "__init__", without_tree)
    fresh = Governor("palm_push_two_feet")
    without = fresh.limits(qs, vs)
    assert built == [HAVE_NUMBA]
    np.testing.assert_allclose(
        without.max_contact_velocity, with_tree.max_contact_velocity, rtol=0, atol=1e-12
    )
    assert without.status == with_tree.status
    np.testing.assert_allclose(without.point, with_tree.point, rtol=0, atol=1e-12)
    singles = [fresh.limit(q, v).max_contact_velocity for q, v in zip(qs, vs, strict=True)]
    np.testing.assert_allclose(with_tree.max_contact_velocity, singles, rtol=0, atol=1e-12)
