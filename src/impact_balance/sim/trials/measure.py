"""What a trial measured, against what the impact model predicts.

Measured, across the impact (from the last step before the impact force appears to the
separation, or 20 ms later if the limb keeps pressing, see :func:`impact_window`):
- the impulse at the impact point: the integrated contact force on the robot, N s, world;
- the CoM velocity jump (xy), m/s;
- the approach speed (``-n . v`` of the impact point just before) and the restitution
  (separation speed ``n . v`` just after, over the approach speed, clamped at 0);
- the slip: the tangential speed of the impact point just after, m/s.

Predicted: the impact model (:func:`impact_balance.impact.model.impact_model`) at the stance, with
the restitution range set to the measured value ``[e, e]`` and evaluated at the measured
approach speed, for both inertia models (``composite``: the robot as one rigid body;
``joint_space``: ``J M^-1 J^T``, every joint free, ``M`` including the servos' armature).
Its CoM velocity jumps span a polygon; the distance of the measured jump to it (0 inside)
says how far the model is from the simulation.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from impact_balance.contacts.stance import Stance
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import INERTIA_MODELS, impact_model
from impact_balance.json_values import json_number
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.impact_trial import TrialRecord

__all__ = ["Prediction", "TrialResult", "distance_to_hull", "impact_window", "measure"]

#: A force below this fraction of the peak counts as zero.
_FORCE_FLOOR = 1e-6
#: Longest impact, s: a servo-held limb may keep pressing on the surface after the impact.
MAX_IMPACT_DURATION = 0.02


@dataclass(frozen=True)
class Prediction:
    """The impact model's CoM velocity jumps at the measured speed and restitution.

    Attributes:
        inertia: "composite" or "joint_space".
        com_velocity_jumps: (2N, 2) vertices, m/s (rows 2i, 2i+1: cone edge i, both at e).
        distance: Distance from the measured jump to their convex hull, m/s (0 inside).
    """

    inertia: str
    com_velocity_jumps: np.ndarray
    distance: float

    @property
    def relative_distance(self) -> float:
        """``distance`` over the size of the predicted jumps (their largest norm)."""
        size = float(np.linalg.norm(self.com_velocity_jumps, axis=1).max())
        return self.distance / size if size > 0 else float("nan")


@dataclass
class TrialResult:
    """One trial's measurement and the predictions (see the module docstring).

    Attributes:
        approach_speed: Commanded approach speed, m/s.
        joints: Joint model.
        approach_speed_measured: Normal approach speed of the impact point just before, m/s.
        restitution_measured: Separation over approach normal speed (>= 0).
        impulse_measured: Impulse on the robot at the impact point, N s, world (3).
        com_velocity_jump_measured: CoM velocity jump across the impact, m/s (2).
        slip_speed: Tangential speed of the impact point just after the impact, m/s.
        impact_time: (start, end) of the impact, s.
        contacts_kept: Every sustained contact kept touching its support without sliding
            more than 1 cm (``servo``); None for ``rigid``, whose robot floats.
        predicted: Prediction per inertia model.
        saturated_joints: ``servo``: joints whose torque reached its effort limit during the
            impact (empty for ``rigid``).
        sim_time_ratio: Simulated time over wall-clock time.
        sustained_impulses: Impulse on the robot at each sustained contact over the impact, its force
            before the impact subtracted, N s, world (by contact name): what the paper neglects.
        armature: Where the joints' rotor inertia came from (``servo``).
        hold: The rigid-impact hold (``--rigid-impact``), or None.
        record: The time series.
    """

    approach_speed: float
    joints: str
    approach_speed_measured: float
    restitution_measured: float
    impulse_measured: np.ndarray
    com_velocity_jump_measured: np.ndarray
    slip_speed: float
    impact_time: tuple[float, float]
    contacts_kept: bool | None
    predicted: dict[str, Prediction]
    saturated_joints: list[str]
    sim_time_ratio: float
    sustained_impulses: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    armature: str = ""
    hold: dict | None = None
    record: TrialRecord | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (strict: no NaN)."""

        num = json_number
        return {
            "approach_speed": num(self.approach_speed),
            "joints": self.joints,
            "approach_speed_measured": num(self.approach_speed_measured),
            "restitution_measured": num(self.restitution_measured),
            "impulse_measured": [num(x) for x in self.impulse_measured],
            "com_velocity_jump_measured": [num(x) for x in self.com_velocity_jump_measured],
            "slip_speed": num(self.slip_speed),
            "impact_time": [num(x) for x in self.impact_time],
            "predicted": {
                name: {
                    "com_velocity_jumps": [[num(x) for x in row] for row in p.com_velocity_jumps],
                    "distance": num(p.distance),
                    "relative_distance": num(p.relative_distance),
                }
                for name, p in self.predicted.items()
            },
            "contacts_kept": self.contacts_kept,
            "saturated_joints": list(self.saturated_joints),
            "sustained_impulses": {
                k: [num(x) for x in v] for k, v in self.sustained_impulses.items()
            },
            "armature": self.armature,
            "rigid_hold": self.hold,
            "sim_time_ratio": num(self.sim_time_ratio),
        }


def distance_to_hull(point: np.ndarray, vertices: np.ndarray) -> float:
    """Euclidean distance from ``point`` to the convex hull of ``vertices`` (2D), 0 inside."""
    point = np.asarray(point, dtype=float)
    hull = Polygon.from_points(np.asarray(vertices, dtype=float), tol=1e-12)
    v = hull.vertices
    if len(v) >= 3 and hull.contains(point[None, :], tol=0.0).all():
        return 0.0
    if len(v) == 0:
        return float("nan")
    if len(v) == 1:
        return float(np.linalg.norm(point - v[0]))
    best = np.inf
    for a, b in zip(v, np.roll(v, -1, axis=0)):
        ab = b - a
        t = np.clip((point - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(point - (a + t * ab))))
    return best


def impact_window(
    record: TrialRecord, max_duration: float = MAX_IMPACT_DURATION
) -> tuple[int, int]:
    """Indices (before, end) of the impact: the force of sample k acts from sample k to k + 1.

    ``before`` is the last sample without impact force; ``end`` the first sample where it is
    zero again (separation), or ``max_duration`` after the impact began if the limb keeps
    pressing. So the impulse is the sum of the forces of samples ``before .. end - 1`` times
    the step, and it changes the velocities from sample ``before`` to sample ``end``.
    """
    force = np.linalg.norm(record.forces["impact"], axis=1)
    peak = force.max(initial=0.0)
    if peak <= 0.0:
        raise ValueError("no impact")
    touching = force > _FORCE_FLOOR * peak
    first = int(np.flatnonzero(touching)[0])
    before = max(first - 1, 0)
    last = min(len(force) - 1, int(np.searchsorted(record.time, record.time[first] + max_duration)))
    released = np.flatnonzero(~touching[first:last])
    end = first + int(released[0]) if released.size else last
    return before, end


def _stance_with_armature(sim: SimModel) -> Stance:
    """The stance, on a copy of the robot model carrying the simulated joints' armature
    (pinocchio's ``crba`` adds ``model.armature`` to the mass matrix), so that ``joint_space``
    predicts for the simulated robot. The shared robot model is never modified.
    """
    if sim.joints != "servo" or np.array_equal(
        sim.armature, np.asarray(sim.robot.model.armature)[sim.v_index]
    ):
        return sim.stance
    model = pin.Model(sim.robot.model)
    model.armature[sim.v_index] = sim.armature
    robot = dataclasses.replace(sim.robot, model=model)
    return Stance(robot, sim.stance.q, [c.spec for c in sim.stance.contacts])


def measure(sim: SimModel, record: TrialRecord, approach_speed: float) -> TrialResult:
    """Measurement and predictions of one trial (see the module docstring)."""
    from impact_balance.exceptions import SimulationError

    spec = sim.scenario.impact.spec()
    n = np.asarray(spec.normal, dtype=float) / np.linalg.norm(spec.normal)
    try:
        before, end = impact_window(record)
    except ValueError:
        raise SimulationError(
            "--duration",
            round(record.simulated_time, 4),
            "the impact point never reached the surface in that time",
        ) from None
    if record.time[before] < record.approach_start:
        # Not the commanded approach's impact (e.g. a joint snapped back into its range while settling).
        raise SimulationError(
            "impact",
            spec.frame,
            f"the impact point touched the surface at {record.time[before]:.3f} s, before "
            f"the approach began ({record.approach_start:.3f} s): the limb was not held at its start pose",
        )
    dt = sim.model.opt.timestep
    impulse = record.forces["impact"][before:end].sum(axis=0) * dt
    jump = (record.com_velocity[end] - record.com_velocity[before])[:2]
    v_before, v_after = record.impact_velocity[before], record.impact_velocity[end]
    approach = float(-n @ v_before)
    restitution = max(0.0, float(n @ v_after)) / approach if approach > 0 else float("nan")
    slip = float(np.linalg.norm(v_after - (n @ v_after) * n))
    predicted = {}
    stance = _stance_with_armature(sim)
    for inertia in INERTIA_MODELS:
        model_spec = dataclasses.replace(
            spec, restitution=(restitution, restitution), inertia=inertia
        )
        model = impact_model(stance if inertia == "joint_space" else sim.stance, model_spec)
        jumps = model.com_velocity_jumps(approach)[:, :2]
        predicted[inertia] = Prediction(inertia, jumps, distance_to_hull(jump, jumps))
    kept = None
    if sim.joints != "rigid":
        start = int(np.searchsorted(record.time, record.approach_start))
        contact_forces = [
            f for name, f in record.forces.items() if name != "impact"
        ]  # in contact order
        normal_forces = np.array(
            [f[start:] @ c.normal for f, c in zip(contact_forces, sim.stance.contacts)]
        )
        moved = np.linalg.norm(
            record.contact_positions[start:] - record.contact_positions[start], axis=2
        ).max()
        kept = bool((normal_forces > 0.0).all() and moved < 0.01)
    saturated: list[str] = []
    if sim.joints == "servo" and record.actuator_force.size:
        limits = sim.model.actuator_forcerange[sim.actuator_ids, 1]
        peak = np.abs(record.actuator_force[before : end + 1]).max(axis=0)
        limited = sim.model.actuator_forcelimited[sim.actuator_ids].astype(bool)
        saturated = [
            name
            for name, p, lim, on in zip(sim.joint_names, peak, limits, limited)
            if on and p >= lim * (1 - 1e-6)
        ]
    ratio = record.simulated_time / record.wall_time if record.wall_time > 0 else float("nan")
    sustained = {
        name: (f[before:end] - f[before]).sum(axis=0) * dt
        for name, f in record.forces.items()
        if name != "impact"
    }
    return TrialResult(
        approach_speed=approach_speed,
        joints=sim.joints,
        approach_speed_measured=approach,
        restitution_measured=restitution,
        impulse_measured=impulse,
        com_velocity_jump_measured=jump,
        slip_speed=slip,
        impact_time=(float(record.time[before]), float(record.time[end])),
        contacts_kept=kept,
        predicted=predicted,
        saturated_joints=saturated,
        sim_time_ratio=ratio,
        sustained_impulses=sustained if sim.joints != "rigid" else {},
        armature=sim.armature_source,
        hold=record.hold,
        record=record,
    )
