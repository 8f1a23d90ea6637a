"""What MuJoCo's integrator adds to the joint-space inertia: its implicit joint damping.

MuJoCo's ``implicit``, ``implicitfast`` and ``discrete`` integrators, and its ``Euler``
integrator unless the ``eulerdamp`` flag is disabled, integrate the joints' viscous damping
``D`` (``dof_damping``, N m s/rad or N s/m) implicitly: one step of ``h`` seconds solves
``(M + h D) a = f - D qdot`` for the acceleration ``a`` (``M`` the joint-space inertia with the
armature, ``f`` every other generalised force). A torque that cancels ``D qdot`` (a motor's
damping compensation) leaves ``(M + h D) a = f``: the plant's inertia is ``M + h D``, ``h D`` a
diagonal term of ``h * dof_damping`` (kg m^2 on a hinge, kg on a slide). ``RK4`` integrates the
damping explicitly: no term. (``discrete`` also adds ``h^2 K`` of joint stiffness, not counted
here: the project's models have none.)
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt

__all__ = ["damping_is_implicit", "implicit_damping_inertia"]

_IMPLICIT = frozenset(
    {
        int(mujoco.mjtIntegrator.mjINT_IMPLICIT),
        int(mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
        *(
            (int(mujoco.mjtIntegrator.mjINT_DISCRETE),)
            if hasattr(mujoco.mjtIntegrator, "mjINT_DISCRETE")
            else ()
        ),
    }
)


def damping_is_implicit(model: mujoco.MjModel) -> bool:
    """Whether ``model``'s integrator integrates the joint damping implicitly (module docstring).

    ``implicit``, ``implicitfast``, ``discrete``, and ``Euler`` without ``eulerdamp`` disabled:
    True; ``RK4`` and ``Euler`` with ``eulerdamp`` disabled: False.
    """
    integrator = int(model.opt.integrator)
    if integrator == int(mujoco.mjtIntegrator.mjINT_EULER):
        return not int(model.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)
    return integrator in _IMPLICIT


def implicit_damping_inertia(model: mujoco.MjModel) -> npt.NDArray[np.float64]:
    """The inertia the integrator adds to each degree of freedom: ``h * dof_damping`` or zero.

    Args:
        model: The MuJoCo model (its ``opt.timestep`` h, s, its integrator and ``dof_damping``).

    Returns:
        ``h * dof_damping`` by MuJoCo degree of freedom (``nv``; kg m^2 on a hinge, kg on a
        slide) when :func:`damping_is_implicit`, else zeros.
    """
    if not damping_is_implicit(model):
        return np.zeros(model.nv)
    answer: npt.NDArray[np.float64] = float(model.opt.timestep) * np.asarray(
        model.dof_damping, dtype=float
    )
    return answer
