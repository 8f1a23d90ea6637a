"""Sole and hand sizes of the bundled robots, measured on their meshes (docs/robots.md).

Run from the repository root:

    PYTHONPATH=src python examples/robot_sizes.py

For each robot it reads the URDF's collision and visual geometry with pinocchio, the mesh files with
:func:`impact_balance.robot.meshes.read_mesh`, and expresses every vertex of the links that move
with the foot (or hand) frame in that frame, at the robot's standing configuration:

- sole: the vertices within 5 mm of the lowest one (along the frame's z axis) form the
  sole; their bounding rectangle gives the contact ``size`` [length along x, width along y]
  and the ``offset.position`` of its centre (z = the sole plane);
- hand: the bounding box of every vertex moving with the hand frame, in that frame.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from impact_balance.robot.meshes import read_mesh
from impact_balance.robot.robot import BUNDLED_ROBOTS, load_robot

#: (sole frame, hand frame) of each bundled robot (left side; the right side is symmetric).
FRAMES = {
    "talos": ("left_sole_link", "gripper_left_base_link"),
    "g1": ("left_ankle_roll_link", "left_rubber_hand"),
    "romeo": ("l_sole", "l_wrist"),
    "icub": ("l_sole", "l_hand"),
    "jvrc1": ("l_ankle", "l_wrist"),
}
SOLE_BAND = 0.005


def _vertices_in(robot, frame: str, kind: pin.GeometryType) -> np.ndarray:
    """Every collision vertex of the bodies moved by ``frame``'s parent joint, in ``frame``, m."""
    model = robot.model
    geometry = pin.buildGeomFromUrdf(
        model,
        str(robot.urdf_path),
        kind,
        package_dirs=[str(p) for p in robot.urdf_path.resolve().parents],
    )
    data, gdata = model.createData(), geometry.createData()
    q = robot.configuration()
    pin.framesForwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, geometry, gdata)
    fid = model.getFrameId(frame)
    joint = model.frames[fid].parentJoint
    to_frame = data.oMf[fid].inverse()
    points = []
    for i, obj in enumerate(geometry.geometryObjects):
        if obj.parentJoint != joint:
            continue
        if not (obj.meshPath and "/" in obj.meshPath):
            continue  # primitive shapes (G1's foot spheres are described in its scenario)
        vertices = read_mesh(obj.meshPath)[0] * np.asarray(obj.meshScale)
        M = to_frame * gdata.oMg[i]
        points.append(vertices @ M.rotation.T + M.translation)
    return np.vstack(points) if points else np.zeros((0, 3))


def sizes(name: str, kind: pin.GeometryType = pin.GeometryType.COLLISION) -> dict:
    robot = load_robot(name)
    sole, hand = FRAMES[name]
    out = {"robot": name, "mass": robot.mass, "sole_frame": sole, "hand_frame": hand}
    v = _vertices_in(robot, sole, kind)
    if len(v):
        bottom = v[v[:, 2] <= v[:, 2].min() + SOLE_BAND]
        lo, hi = bottom[:, :2].min(axis=0), bottom[:, :2].max(axis=0)
        out["sole_size"] = (hi - lo).tolist()
        out["sole_centre"] = [*(0.5 * (lo + hi)).tolist(), float(v[:, 2].min())]
    h = _vertices_in(robot, hand, kind)
    if len(h):
        out["hand_box"] = [h.min(axis=0).tolist(), h.max(axis=0).tolist()]
    return out


def main() -> None:
    for name, kind in (
        (n, k)
        for k in (pin.GeometryType.COLLISION, pin.GeometryType.VISUAL)
        for n in BUNDLED_ROBOTS
    ):
        print(f"[{str(kind).rsplit('.', 1)[-1].lower()}] ", end="")
        s = sizes(name, kind)
        sole = (
            (
                f"sole {s['sole_size'][0]:.3f} x {s['sole_size'][1]:.3f} m, centre "
                f"({', '.join(f'{x:+.3f}' for x in s['sole_centre'])}) in {s['sole_frame']}"
            )
            if "sole_size" in s
            else "sole: no mesh"
        )
        hand = ""
        if "hand_box" in s:
            lo, hi = map(np.asarray, s["hand_box"])
            hand = (
                f"; hand box {' x '.join(f'{x:.3f}' for x in hi - lo)} m, x [{lo[0]:+.3f}, "
                f"{hi[0]:+.3f}] y [{lo[1]:+.3f}, {hi[1]:+.3f}] z [{lo[2]:+.3f}, {hi[2]:+.3f}] in "
                f"{s['hand_frame']}"
            )
        print(f"{name} ({s['mass']:.2f} kg): {sole}{hand}")


if __name__ == "__main__":
    main()
