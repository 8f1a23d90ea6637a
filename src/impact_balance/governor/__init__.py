"""The criterion in the control loop: an impact-speed governor for any whole-body controller.

The paper's Algorithm 1 ends with "track the maximum contact velocity with a whole-body QP".
A :class:`Governor` gives that maximum every control tick, from the measured state::

    from impact_balance.governor import Governor

    governor = Governor("palm_push_two_feet")      # once: robot, contacts, impact, ZMP margin
    limit = governor.limit(q, v)                   # each tick: pinocchio q (nq) and v (nv)
    u = governor.cap(u_ref)                        # the reference velocity (world, m/s), capped

- :mod:`.governor`: :class:`Governor` (construction, per-tick calls, reuse, the lock).
- :mod:`.options`: its criterion and the contact-aware options (:class:`ContactAwareOptions`).
- :mod:`.posture`: what is computed once per posture (:class:`Posture`).
- :mod:`.limit`: the per-tick answer (:class:`SpeedLimit`); the cap is
  :func:`~impact_balance.criteria.cap.cap_approach`.
- :mod:`.approach`: the cap as one inequality on an IK step (``-n^T J Δq <= ceiling dt``);
  :mod:`.pink_limit` (``PinkApproachLimit``) and :mod:`.mink_limit` (``MinkApproachLimit``, the
  ``mink`` extra; :mod:`.mujoco_state` maps MuJoCo's state) put it in pink's and mink's QPs.
  They are imported from their modules (not here: mink is optional).

See docs/governor.md for the conventions and how pink, mink or any QP controller uses it.
"""

from impact_balance.criteria.cap import cap_approach
from impact_balance.governor.batch import BatchLimits
from impact_balance.governor.governor import Governor
from impact_balance.governor.limit import SpeedLimit
from impact_balance.governor.options import (
    CRITERIA,
    ON_STALE,
    STARTS,
    ContactAwareOptions,
    Criterion,
    OnStale,
    Starts,
)
from impact_balance.governor.posture import Posture, PostureEvaluator, PostureSettings
from impact_balance.governor.worker import WorkerError

__all__ = [
    "CRITERIA",
    "ON_STALE",
    "STARTS",
    "BatchLimits",
    "ContactAwareOptions",
    "Criterion",
    "Governor",
    "OnStale",
    "Posture",
    "PostureEvaluator",
    "PostureSettings",
    "SpeedLimit",
    "Starts",
    "WorkerError",
    "cap_approach",
]
