"""What a governor computes once per posture: everything but the CoM velocity.

One posture is one configuration ``q``: the contact poses and Jacobians, the CoM, the
composite inertia and g(q) (pinocchio, in the governor's own Data), the contact-wrench
polytope and its projection (the ZMP support area and the CoM velocity area), the impact
model at the impacting frame, and the criterion's data that do not depend on the CoM velocity.

The steps are the pipeline's own functions at the array level
(:func:`~impact_balance.contacts.stance.frame_point`'s numbers,
:func:`~impact_balance.contacts.wrench_polytope.assemble_polytope`,
:func:`~impact_balance.balance.areas.areas_from_polytope`,
:func:`~impact_balance.impact.model.model_from_inertia_map`,
:class:`~impact_balance.criteria.com.ComCriterion`), so a governor answers what
:func:`~impact_balance.analyze` answers for the same posture (the tests check it to 1e-9);
what a control loop does not read is skipped: the :class:`~impact_balance.contacts.stance.Stance`
and :class:`~impact_balance.contacts.stance.Contact` objects (:attr:`Posture.stance` builds one on
demand), the ZMP criterion in "com" mode, the diagnostics, the cannot-balance diagnosis.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.balance.areas import BalanceAreas, Projected, posture_areas
from impact_balance.balance.lipm import lipm_omega
from impact_balance.contacts.cwc import local_faces
from impact_balance.contacts.stance import ContactSpec, Stance, has_free_flyer
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.posture_answer import posture_answer
from impact_balance.criteria.posture_kernel import constants
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.criteria.zmp import zmp_max_contact_velocity
from impact_balance.exceptions import SolverError
from impact_balance.governor.options import Criterion
from impact_balance.governor.posture_kernel import kinematics_posture_kernel
from impact_balance.governor.tree_kernel import KinematicTree, tree_postures
from impact_balance.impact.angular_momentum import AngularMomentumTerm, angular_momentum_gain
from impact_balance.impact.model import (
    ImpactModel,
    ImpactSpec,
    composite_inertia_map,
    impact_cone,
    joint_space_inertia_map,
    model_from_inertia_map,
)
from impact_balance.projection.walk import MAX_PIVOTS, hint_size
from impact_balance.robot.robot import Robot, Scratch

__all__ = ["NO_HALFPLANES", "Kinematics", "Posture", "PostureEvaluator", "PostureSettings"]

#: :attr:`Posture.exit_arrays`' ``G`` when there are no half-planes (one object, compared by
#: identity).
NO_HALFPLANES = np.zeros((0, 2))
NO_HALFPLANES.setflags(write=False)

_POSITION = pin.KinematicLevel.POSITION
_WORLD = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class PostureSettings:
    """The scenario's data a posture is evaluated with (fixed for a governor).

    Attributes:
        contacts: The sustained contacts (robot frames; their world poses come from q).
        impact: The intended impact (frame, offset, surface normal, friction, restitution,
            inertia model, impact duration for the ZMP criterion).
        plane_height: Height h of the LIPM plane, m.
        gravity: m/s^2.
        torque_limits: Whether the joint torque limits bound the contact wrenches.
        zmp_margin: The ZMP support area is shrunk by this margin, m.
        criterion: "com" or "zmp".
        velocity_margin: The post-impact CoM velocities must lie this far inside the CoM
            velocity area, m/s ("com" criterion;
            :class:`~impact_balance.criteria.com.ComCriterion`).
        angular_momentum_damping_time: tau, s: the "com" criterion counts the centroidal
            angular momentum the impulse leaves (:mod:`impact_balance.impact.angular_momentum`);
            None: the paper's criterion.
    """

    contacts: Sequence[ContactSpec]
    impact: ImpactSpec
    plane_height: float
    gravity: float
    torque_limits: bool
    zmp_margin: float
    criterion: Criterion
    velocity_margin: float = 0.0
    angular_momentum_damping_time: float | None = None


@dataclass(frozen=True)
class Posture:
    """One configuration's areas, impact model and criterion data.

    Frames: world axes; positions in m (world, the free flyer's translation included).

    Attributes:
        key: ``q.tobytes()``: the exact configuration these are for.
        q: The configuration (nq; read-only).
        robot: The robot. settings: What it was evaluated with.
        com: The CoM, m. mass: kg.
        areas: The ZMP support area (shrunk by the ZMP margin) and the CoM velocity area (a
            :class:`~impact_balance.balance.areas.BalanceAreas`, built on first access: a tick reads
            only the CoM velocity area, ``com_criterion.area``).
        impact: The impact model at this posture.
        com_jacobian: (3, nv) map from the generalized velocity (pinocchio's convention: the
            free flyer's linear and angular velocity in the base frame, then the joints) to
            the CoM velocity in world axes, m/s.
        com_criterion: The CoM criterion's half-planes and rates (None in "zmp" mode).
        zmp_limit: The ZMP criterion's answer (None in "com" mode; it does not depend on
            the CoM velocity).

    A posture of the one compiled call (:meth:`PostureEvaluator.evaluate`'s common case) holds
    the call's arrays and makes ``projected``, ``impact`` and ``com_criterion`` on first access
    (:func:`~impact_balance.criteria.posture_answer.posture_answer`'s objects, the same numbers);
    a tick reads only :attr:`exit_arrays`, the impact normal and point, which it has at once.
    """

    key: bytes
    q: np.ndarray
    robot: Robot
    settings: PostureSettings
    com: np.ndarray
    mass: float
    projected: BalanceAreas | Projected = field(repr=False)
    impact: ImpactModel
    com_jacobian: np.ndarray
    com_criterion: ComCriterion | None
    zmp_limit: ContactVelocityLimit | None

    def __getattr__(self, name: str) -> object:
        """``projected``, ``impact`` or ``com_criterion`` of a compiled posture (first access).

        Called only for an attribute the instance does not hold: the three are made together
        from the compiled call's arrays and kept.

        Raises:
            AttributeError: Any other name (or any name on a posture made by the steps).
        """
        made = self.__dict__.get("_made")  # not getattr: no recursion (while unpickling)
        if made is None or name not in _MADE:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        answer = made()
        assert answer is not None  # a compiled posture is made only where the call answered
        parts = dict(zip(_MADE, (answer.projected, answer.impact, answer.criterion), strict=True))
        self.__dict__.update(parts)
        return parts[name]

    @functools.cached_property
    def areas(self) -> BalanceAreas:
        """See the class docstring."""
        projected = self.projected
        return projected.areas() if isinstance(projected, Projected) else projected

    @functools.cached_property
    def exit_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """What a tick's compiled call reads: ``(com_jacobian, G, h, rates)`` of the criterion.

        ``G`` is :data:`NO_HALFPLANES` (and ``h``, ``rates`` empty) without a "com" criterion or
        an area with half-planes.
        """
        criterion = self.com_criterion
        if criterion is None or criterion.G is None or criterion.h is None:
            return self.com_jacobian, NO_HALFPLANES, np.zeros(0), np.zeros((0, 0))
        assert criterion.rates is not None  # made with G and h
        return self.com_jacobian, criterion.G, criterion.h, criterion.rates

    @functools.cached_property
    def impact_point_normal(self) -> tuple[np.ndarray, np.ndarray]:
        """The impact point (3,), world, m, and the surface's unit normal (3,), world.

        The impact model's own arrays (``impact.point``, ``impact.normal``); a compiled posture
        has them without making the model.
        """
        return self.impact.point, self.impact.normal

    @functools.cached_property
    def stance(self) -> Stance:
        """The :class:`~impact_balance.contacts.stance.Stance` at ``q``, for plots and displays.

        Built on first access, in the robot's per-thread Data.
        """
        return Stance(self.robot, self.q, self.settings.contacts)


#: The :class:`Posture` fields a compiled posture makes on first access (``Posture.__getattr__``).
_MADE = ("projected", "impact", "com_criterion")
_new = object.__new__


class Kinematics(NamedTuple):
    """One configuration's kinematics, as :meth:`PostureEvaluator.kinematics` computes them.

    Positions in m, world axes; ``*_local`` in the stance frame (origin at the base position
    ``origin``, the free flyer's translation set to zero).

    Attributes:
        origin: (3,) the stance frame's origin in world, m.
        com_local: (3,) the CoM, stance frame. com: (3,) the CoM, world.
        mass: kg.
        com_jacobian: (3, nv) generalized velocity to CoM velocity (world axes).
        rotations: (m, 3, 3) the contacts' contact-to-world rotations.
        local: (m, 3) the contact points, stance frame.
        jacobians: (6m, nv) their world-aligned Jacobians stacked (linear rows first), or
            (0, 0) without torque limits.
        gravity_torques: (nv,) g(q), N m (zeros without torque limits).
        inertia: (3, 3) the composite rotational inertia about the CoM, kg m^2.
    """

    origin: np.ndarray
    com_local: np.ndarray
    com: np.ndarray
    mass: float
    com_jacobian: np.ndarray
    rotations: np.ndarray
    local: np.ndarray
    jacobians: np.ndarray
    gravity_torques: np.ndarray
    inertia: np.ndarray


class PostureEvaluator:
    """Evaluates postures of one robot with one set of contacts and one impact.

    It has a pinocchio Data of its own and is not thread-safe: its owner, a
    :class:`~impact_balance.governor.Governor`, holds a lock around :meth:`evaluate`.

    What does not depend on q is made once here: frame indices, the contact-frame CWC faces,
    the torque-limited joints, the impact's friction cone, the buffers.
    """

    def __init__(self, robot: Robot, settings: PostureSettings):
        self.robot = robot
        self.settings = settings
        contacts, impact = settings.contacts, settings.impact
        frames = [robot.frame_id(c.frame, f"contacts[{i}].frame") for i, c in enumerate(contacts)]
        impact_frame = robot.frame_id(impact.frame, "impact.frame")
        # A copy of the model with each offset contact or impact point as a frame of its own
        # (made once): pinocchio then gives its pose and Jacobian directly, where shifting the
        # frame's Jacobian to the point in numpy cost ~5 us per point and tick.
        self.model = model = pin.Model(robot.model)
        self._frames = [
            _point_frame(model, fid, c.offset, f"impact_balance_contact_{i}")
            for i, (fid, c) in enumerate(zip(frames, contacts, strict=True))
        ]
        self._impact_frame = _point_frame(
            model, impact_frame, impact.offset, "impact_balance_impact"
        )
        self.scratch = Scratch(model)
        self._free_flyer = has_free_flyer(model)
        # The kinematics in one compiled call (tree_postures) where the model's joints allow it,
        # else pinocchio's; the tree's arrays of one posture (see _placements).
        tree = KinematicTree.of(model, [*self._frames, self._impact_frame])
        self._tree = tree if tree.supported else None
        nv = model.nv
        self._tree_out = _TreeOut(
            np.zeros((1, 3)),
            np.zeros((1, 3)),
            np.zeros((1, 6, nv)),
            np.zeros((1, 3)),
            np.zeros((1, 3, nv)),
            np.zeros((1, 3, 3)),
            np.zeros((1, 6)),
        )
        m = len(contacts)
        self._faces = np.array(
            [
                local_faces(float(c.friction), 0.5 * float(c.size[0]), 0.5 * float(c.size[1]))
                for c in contacts
            ]
        ).reshape(m, 16, 6)
        self._frictions = [float(c.friction) for c in contacts]
        self._scaled = any(mu > 1.0 for mu in self._frictions)  # else friction_scaling is None
        idx, limit = robot.effort_limits
        self._torques = bool(settings.torque_limits and m and idx.size)
        self._idx: npt.NDArray[np.int64] = idx if self._torques else np.zeros(0, dtype=np.int64)
        self._limit: npt.NDArray[np.float64] = limit if self._torques else np.zeros(0)
        self._normal, self._cone = impact_cone(impact)
        # The common case in one compiled call (posture_kernel): the paper's "com" criterion,
        # the composite inertia, unscaled contacts (frictions <= 1).
        self._compiled = (
            settings.criterion == "com"
            and impact.inertia == "composite"
            and settings.angular_momentum_damping_time is None
            and not self._scaled
        )
        lo, hi = impact.restitution
        self._constants = constants(float(settings.zmp_margin), (float(lo), float(hi)))
        self._limit = np.ascontiguousarray(self._limit, dtype=float)
        self._idx = np.ascontiguousarray(self._idx, dtype=np.int64)
        # Buffers, overwritten every posture (the answers keep copies).
        self._q_local = np.zeros(model.nq)
        self._zero_velocity = np.zeros(model.nv)
        self._gravity = np.array(model.gravity.linear, dtype=float)  # m/s^2, world
        # The projection's warm start and chain of bases, carried from one posture to the next
        # (see hint_size).
        self._hint = np.full(hint_size(6 * m), -1, dtype=np.int64)
        # The compiled posture's pinocchio arrays (rotations, points, Jacobians), read in the
        # same call.
        self._buffers = (
            np.empty((m, 3, 3)),
            np.empty((m, 3)),
            np.empty((6 * m, model.nv)) if self._torques else np.zeros((0, 0)),
        )

    def evaluate(self, q: np.ndarray, *, steps: bool = False) -> Posture:
        """Everything the governor needs at configuration ``q`` (nq, float64, contiguous).

        The common case is one compiled call (:mod:`.posture_kernel`), the rest the pipeline's
        steps one by one; ``steps=True`` takes the steps whatever the case (the same numbers:
        to load their compiled code, or to compare).

        Raises what the pipeline raises on a posture it cannot evaluate:
        :class:`~impact_balance.exceptions.ScenarioError` (the CoM at or below the LIPM
        plane), :class:`~impact_balance.exceptions.ImpactModelError` (a friction-cone edge
        that would not separate the contact), :class:`~impact_balance.exceptions.SolverError`
        (a projection that failed).
        """
        settings = self.settings
        if self._compiled and not steps:
            posture = self._compiled_posture(q)
            if posture is not None:
                return posture
        k = self.kinematics(q)
        origin, com_local, mass, com = k.origin, k.com_local, k.mass, k.com
        rotations, local, jacobians = k.rotations, k.local, k.jacobians
        gravity_torques, com_jacobian = k.gravity_torques, k.com_jacobian
        areas = self._areas(
            rotations, local, origin, com_local, mass, com, jacobians, gravity_torques
        )
        impact = self.impact_at(q, k)
        com_criterion = zmp = None
        if settings.criterion == "zmp":
            if isinstance(areas, Projected):
                areas = areas.areas()
            zmp = zmp_max_contact_velocity(
                areas.zmp_area,
                impact,
                com,
                settings.plane_height,
                settings.gravity,
                settings.impact.duration,
            )
        else:
            com_criterion = ComCriterion(
                areas.com_velocity_area,
                impact,
                settings.velocity_margin,
                self._angular_momentum(impact, com),
            )
        return self._posture(q, com, mass, areas, impact, com_jacobian, com_criterion, zmp)

    def _compiled_posture(self, q: np.ndarray) -> Posture | None:
        """:meth:`evaluate`'s answer by pinocchio and one compiled call.

        :func:`~.posture_kernel.kinematics_posture_kernel`, into this evaluator's buffers. None
        when the kernel leaves the posture to :meth:`evaluate`'s steps (a walk not certified,
        an area of fewer than 3 vertices, an impact model they refuse).
        """
        settings = self.settings
        rotations, local, jacobians = self._buffers
        origin, com_local, mass, inertia, Ag = self._placements(q, rotations, local, jacobians)
        com_z = float(com_local[2]) + float(origin[2])
        w = lipm_omega(com_z, settings.plane_height, settings.gravity, field="plane_height")
        point_local, J = self._impact_point_jacobian()
        out = kinematics_posture_kernel(
            self._faces, rotations, local, origin, com_local, Ag, self._gravity, self._torques,
            jacobians, self._idx, self._limit, mass, settings.gravity, settings.plane_height, w,
            self._hint, MAX_PIVOTS, self._constants, point_local, inertia, self._normal,
            self._cone,
        )  # fmt: skip
        if out[0]:  # FALLBACK: posture_answer's None
            return None
        com, com_jacobian, point = out[12:]
        normal = self._normal.copy()  # the impact model's, and every answer's at this posture
        made = functools.partial(
            posture_answer, out, settings.impact, point, normal, self._cone.copy(), J, mass=mass,
            omega=w, com=com, plane_height=settings.plane_height, gravity=settings.gravity,
            zmp_margin=settings.zmp_margin, velocity_margin=settings.velocity_margin,
        )  # fmt: skip
        # The criterion's arrays as posture_answer gives them: h less the velocity margin.
        margin = float(settings.velocity_margin)
        G, h, rates = out[7], out[8], out[11]
        exits = (com_jacobian, G, h - margin if margin else h, rates)
        q = q.copy()
        q.setflags(write=False)
        # Posture(...) without its frozen __init__ (one object.__setattr__ per field), the three
        # objects left to __getattr__, the tick's arrays in the cached properties' own slots.
        posture: Posture = _new(Posture)
        vars(posture).update(
            key=q.tobytes(),
            q=q,
            robot=self.robot,
            settings=settings,
            com=com,
            mass=mass,
            com_jacobian=com_jacobian,
            zmp_limit=None,
            exit_arrays=exits,
            impact_point_normal=(point, normal),
            _made=made,
        )
        return posture

    def _posture(
        self,
        q: np.ndarray,
        com: np.ndarray,
        mass: float,
        projected: BalanceAreas | Projected,
        impact: ImpactModel,
        com_jacobian: np.ndarray,
        com_criterion: ComCriterion | None,
        zmp_limit: ContactVelocityLimit | None,
    ) -> Posture:
        """The :class:`Posture` of these parts at ``q`` (kept as a read-only copy)."""
        q = q.copy()
        q.setflags(write=False)
        return Posture(
            q.tobytes(),
            q,
            self.robot,
            self.settings,
            com,
            mass,
            projected,
            impact,
            com_jacobian,
            com_criterion,
            zmp_limit,
        )

    def impact_point(self) -> npt.NDArray[np.float64]:
        """The impact point (3,), m, in the stance frame of the last kinematics computed.

        Call it after :meth:`kinematics`, before the next one (a new array).
        """
        if self._tree is not None:
            local: npt.NDArray[np.float64] = self._tree_out.point_locals[0].copy()
            return local
        translation = pin.updateFramePlacement(self.model, self.scratch.data, self._impact_frame)
        point: npt.NDArray[np.float64] = translation.translation.copy()
        return point

    def _impact_point_jacobian(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The impact point (3,), stance frame, m, and its (3, nv) Jacobian (world axes).

        Of the last kinematics computed (new arrays).
        """
        if self._tree is not None:
            out = self._tree_out
            return out.point_locals[0].copy(), out.point_jacobians[0].copy()
        data, model, fid = self.scratch.data, self.model, self._impact_frame
        point = pin.updateFramePlacement(model, data, fid).translation.copy()
        return point, pin.getFrameJacobian(model, data, fid, _WORLD)[:3].copy()

    def kinematics(self, q: np.ndarray) -> Kinematics:
        """The pinocchio step of :meth:`evaluate` at ``q`` (nq, float64, contiguous).

        Left in this evaluator's Data: :meth:`impact_at` reads the impact frame from it, so
        call it before the next :meth:`kinematics`. The arrays are new (the caller keeps them).
        """
        m, torques = len(self._frames), self._torques
        rotations = np.empty((m, 3, 3))
        local = np.empty((m, 3))
        jacobians = np.empty((6 * m, self.model.nv)) if torques else np.zeros((0, 0))
        origin, com_local, mass, inertia, Ag = self._placements(q, rotations, local, jacobians)
        com_local = np.array(com_local, dtype=float)
        linear = Ag[:3]  # m times the CoM Jacobian
        com_jacobian = linear / mass
        # g(q) = -Ag[:3]^T g: the gravity's generalized force is the CoM's (the centroidal
        # momentum matrix's linear rows are m times the CoM Jacobian); equal to pinocchio's
        # computeGeneralizedGravity to rounding (1e-14 N m of 327 on G1), without its pass.
        gravity_torques = -(self._gravity @ linear) if torques else self._zero_velocity
        com = com_local + origin
        return Kinematics(
            origin,
            com_local,
            com,
            mass,
            com_jacobian,
            rotations,
            local,
            jacobians,
            gravity_torques,
            np.array(inertia, dtype=float),
        )

    def _placements(
        self,
        q: np.ndarray,
        rotations: npt.NDArray[np.float64],
        local: npt.NDArray[np.float64],
        jacobians: npt.NDArray[np.float64],
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], float, np.ndarray, np.ndarray]:
        """The kinematics at ``q``, in the stance frame (world axes, origin at the base).

        Writes the contacts' contact-to-world ``rotations`` (m, 3, 3), points ``local`` (m, 3)
        and, with torque limits, stacked world-aligned ``jacobians`` (6m, nv). Returns
        ``(origin, com_local, mass, inertia, Ag)``: the stance frame's origin in world (a new
        array, m), the CoM in the stance frame (m), the mass (kg), the composite rotational
        inertia about the CoM (world axes, kg m^2) and the centroidal momentum matrix (6, nv;
        its linear rows are m J_com), valid until the next kinematics. By
        :func:`~impact_balance.governor.tree_kernel.tree_postures` where the model's joints
        allow it (pinocchio's numbers to rounding), else by pinocchio.
        """
        if self._tree is not None:
            return self._tree_placements(q, rotations, local, jacobians)
        data, model = self.scratch.data, self.model
        # As Stance does: lever arms keep their precision however far the robot stands.
        q_local = self._q_local
        q_local[:] = q
        if self._free_flyer:
            origin = q[:3].copy()
            q_local[:3] = 0.0
        else:
            origin = np.zeros(3)
        # ccrba: joint placements, joint Jacobians, the composite inertia Ig and the centroidal
        # momentum matrix Ag (its linear rows are m times the CoM Jacobian).
        pin.ccrba(model, data, q_local, self._zero_velocity)
        self.scratch.holder = None  # what it holds is this evaluator's, never a Stance's
        com_local = pin.centerOfMass(model, data, _POSITION, False)
        # frame_point's numbers (the evaluator's frames have no offset of their own), in
        # pinocchio's calls directly: the pose as one 4 x 4 array, the Jacobian written in place.
        torques = self._torques
        for i, fid in enumerate(self._frames):
            pose = pin.updateFramePlacement(model, data, fid).homogeneous
            rotations[i] = pose[:3, :3]
            local[i] = pose[:3, 3]
            if torques:
                jacobians[6 * i : 6 * i + 6] = pin.getFrameJacobian(model, data, fid, _WORLD)
        Ig = data.Ig
        return origin, com_local, float(Ig.mass), Ig.inertia, data.Ag

    def _tree_placements(
        self,
        q: np.ndarray,
        rotations: npt.NDArray[np.float64],
        local: npt.NDArray[np.float64],
        jacobians: npt.NDArray[np.float64],
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], float, np.ndarray, np.ndarray]:
        """:meth:`_placements` by the compiled tree (the impact point and its Jacobian too)."""
        t, out = self._tree, self._tree_out
        assert t is not None
        tree_postures(
            t.parents, t.kinds, t.idx_q, t.idx_v, t.placements, t.masses, t.levers, t.inertias,
            t.frame_joints, t.frame_placements, q.reshape(1, -1), self._free_flyer,
            self._torques, -math.inf, 0.0, rotations.reshape((1, *rotations.shape)),
            local.reshape((1, *local.shape)), jacobians.reshape((1, *jacobians.shape)),
            out.origins, out.com_locals, out.centroidal, out.point_locals, out.point_jacobians,
            out.inertias, out.scalars,
        )  # fmt: skip
        return (
            out.origins[0].copy(),
            out.com_locals[0],
            float(out.scalars[0, 0]),
            out.inertias[0],
            # column-major, as pinocchio's Ag: numpy's products on it and the compiled call's
            # arguments are then the pinocchio path's (the same BLAS calls, the same numbers)
            np.asfortranarray(out.centroidal[0]),
        )

    def impact_at(self, q: np.ndarray, k: Kinematics) -> ImpactModel:
        """The impact model at ``q``, whose :meth:`kinematics` ``k`` the Data holds."""
        return self._impact(q, self._q_local, k.origin, k.com_local, k.mass, k.inertia)

    def _areas(
        self,
        rotations: npt.NDArray[np.float64],
        local: npt.NDArray[np.float64],
        origin: npt.NDArray[np.float64],
        com_local: npt.NDArray[np.float64],
        mass: float,
        com: npt.NDArray[np.float64],
        jacobians: npt.NDArray[np.float64],
        gravity_torques: npt.NDArray[np.float64],
    ) -> BalanceAreas | Projected:
        """The contact wrench polytope of the contacts' poses, projected.

        The ZMP support area and the CoM velocity area (positions in m, world axes;
        ``local``: the contact points in the stance frame, origin at ``origin``).

        Raises:
            SolverError: The projection failed (naming the contacts).
        """
        settings = self.settings
        try:
            return posture_areas(
                self._faces,
                rotations,
                local + origin,
                local - com_local,
                mass,
                com,
                settings.gravity,
                jacobians,
                self._idx,
                self._limit,
                gravity_torques,
                self._frictions,
                settings.plane_height,
                settings.zmp_margin,
                self._hint,
            )
        except SolverError as exc:
            raise exc.within("contacts (projection of the contact wrench polytope)") from None

    def _angular_momentum(self, impact: ImpactModel, com: np.ndarray) -> AngularMomentumTerm | None:
        """The angular momentum term at this posture (None: the paper's criterion)."""
        settings = self.settings
        tau = settings.angular_momentum_damping_time
        if tau is None:
            return None
        omega = lipm_omega(
            float(com[2]), settings.plane_height, settings.gravity, field="plane_height"
        )
        gain = angular_momentum_gain(omega, settings.gravity, tau)
        return AngularMomentumTerm(np.asarray(impact.point - com, dtype=float), gain, float(tau))

    def _impact(
        self,
        q: np.ndarray,
        q_local: np.ndarray,
        origin: np.ndarray,
        com_local: np.ndarray,
        mass: float,
        inertia: np.ndarray,
    ) -> ImpactModel:
        """The impact model at the kinematics held in the Data.

        As :func:`~impact_balance.impact.model.impact_model` computes it.
        """
        spec, model = self.settings.impact, self.model
        # frame_point's numbers (the impact point is a frame of the evaluator's model)
        point_local, J = self._impact_point_jacobian()
        arm = point_local - com_local
        if spec.inertia == "joint_space":
            with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported by the model
                W = joint_space_inertia_map(self.scratch, model, q, J)
        else:  # compiled, in floats: an overflow is an inf, reported by the model, not a warning
            W = composite_inertia_map(arm, mass, inertia)
        return model_from_inertia_map(
            spec, point_local + origin, arm, self._normal.copy(), self._cone.copy(), W, mass, J
        )


class _TreeOut(NamedTuple):
    """:func:`~impact_balance.governor.tree_kernel.tree_postures`'s arrays of one posture."""

    origins: np.ndarray
    com_locals: np.ndarray
    centroidal: np.ndarray
    point_locals: np.ndarray
    point_jacobians: np.ndarray
    inertias: np.ndarray
    scalars: np.ndarray


def _point_frame(model: pin.Model, fid: int, offset: pin.SE3 | None, name: str) -> int:
    """The id of a frame of ``model`` at frame ``fid`` times ``offset``.

    ``fid`` itself without an offset, else a new operational frame on the same joint (``model``
    is modified).
    """
    if offset is None or offset == pin.SE3.Identity():  # exact, as frame_point tests it
        return fid
    frame = model.frames[fid]
    return int(
        model.addFrame(
            pin.Frame(
                name, frame.parentJoint, fid, frame.placement * offset, pin.FrameType.OP_FRAME
            )
        )
    )
