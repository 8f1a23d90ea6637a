"""impact-balance: impact-aware multi-contact balance criteria for legged robots.

Implements Wang, Tanguy and Kheddar, "Impact-Aware Multi-Contact Balance Criteria"
(IEEE T-RO 2023): the ZMP support area and CoM velocity area (zero-step capture region) of
any set of contacts, the frictional impact model, and the maximum contact velocity.

Data flow: scenario -> stance -> constraints -> areas -> impact -> answer.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import TYPE_CHECKING, Any

#: Where each public name lives: imported on first use (PEP 562), so that `import impact_balance`
#: costs only what the names a program touches need (the command line lists robots in ~0.2 s).
_EXPORTS: dict[str, str] = {
    "Analysis": ".analysis", "ImpactAnswer": ".analysis", "analyze": ".analysis",
    "BalanceAreas": ".areas", "areas_from_polytope": ".areas", "balance_areas": ".areas",
    "GRAVITY": ".constants",
    "WrenchPolytope": ".constraints", "contact_polytope": ".constraints", "wrench_polytope": ".constraints",
    "VelocityLimit": ".criteria", "capped_velocity": ".criteria", "max_contact_velocity": ".criteria", "zmp_max_contact_velocity": ".criteria",
    "cwc_faces": ".cwc", "cwc_faces_world": ".cwc", "cwc_span": ".cwc",
    "Diagnostic": ".diagnostics",
    "ImpactBalanceError": ".exceptions", "ImpactModelError": ".exceptions", "RobotLoadError": ".exceptions", "ScenarioError": ".exceptions", "SolverError": ".exceptions", "StrictWarningsError": ".exceptions", "UnknownConfigurationError": ".exceptions", "UnknownFrameError": ".exceptions", "UnknownJointError": ".exceptions", "UnknownKeyError": ".exceptions", "UnknownRobotError": ".exceptions", "UnknownScenarioError": ".exceptions",
    "ImpactModel": ".impact", "ImpactSpec": ".impact", "friction_cone": ".impact", "impact_model": ".impact",
    "PhasePortrait": ".lipm", "com_velocity_bounds": ".lipm", "lipm_omega": ".lipm", "phase_portrait": ".lipm",
    "Polygon": ".polygon",
    "project_polytope": ".projection",
    "QPOptions": ".qp", "QPResult": ".qp", "solve_contact_velocity_qp": ".qp",
    "BUNDLED_ROBOTS": ".robot", "Robot": ".robot", "load_robot": ".robot",
    "Scenario": ".scenario", "bundled_scenarios": ".scenario", "load_scenario": ".scenario",
    "Contact": ".stance", "ContactSpec": ".stance", "Stance": ".stance",
}

__version__ = "0.1.0"

__all__ = [
    "Analysis", "ImpactAnswer", "analyze",
    "BalanceAreas", "areas_from_polytope", "balance_areas",
    "GRAVITY",
    "WrenchPolytope", "contact_polytope", "wrench_polytope",
    "VelocityLimit", "capped_velocity", "max_contact_velocity", "zmp_max_contact_velocity",
    "cwc_faces", "cwc_faces_world", "cwc_span",
    "Diagnostic",
    "ImpactBalanceError", "ImpactModelError", "RobotLoadError", "ScenarioError", "SolverError",
    "UnknownConfigurationError", "UnknownFrameError", "UnknownJointError", "UnknownRobotError",
    "UnknownScenarioError", "UnknownKeyError", "StrictWarningsError",
    "ImpactModel", "ImpactSpec", "friction_cone", "impact_model",
    "PhasePortrait", "com_velocity_bounds", "lipm_omega", "phase_portrait",
    "Polygon", "project_polytope",
    "QPOptions", "QPResult", "solve_contact_velocity_qp",
    "BUNDLED_ROBOTS", "Robot", "load_robot",
    "Scenario", "bundled_scenarios", "load_scenario",
    "Contact", "ContactSpec", "Stance",
]


def __getattr__(name: str) -> Any:
    """Import a public name's module on first access (``impact_balance.analyze`` loads the core)."""
    module = _EXPORTS.get(name)
    if module is None:
        if not name.startswith("_") and importlib.util.find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(f".{name}", __name__)  # a submodule, as before: ib.scenario
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value  # later accesses skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # static analysers and IDEs see the plain imports
    from .analysis import Analysis, ImpactAnswer, analyze
    from .areas import BalanceAreas, areas_from_polytope, balance_areas
    from .constants import GRAVITY
    from .constraints import WrenchPolytope, contact_polytope, wrench_polytope
    from .criteria import VelocityLimit, capped_velocity, max_contact_velocity, zmp_max_contact_velocity
    from .cwc import cwc_faces, cwc_faces_world, cwc_span
    from .diagnostics import Diagnostic
    from .exceptions import (
        ImpactBalanceError,
        ImpactModelError,
        RobotLoadError,
        ScenarioError,
        SolverError,
        StrictWarningsError,
        UnknownConfigurationError,
        UnknownFrameError,
        UnknownJointError,
        UnknownKeyError,
        UnknownRobotError,
        UnknownScenarioError,
    )
    from .impact import ImpactModel, ImpactSpec, friction_cone, impact_model
    from .lipm import PhasePortrait, com_velocity_bounds, lipm_omega, phase_portrait
    from .polygon import Polygon
    from .projection import project_polytope
    from .qp import QPOptions, QPResult, solve_contact_velocity_qp
    from .robot import BUNDLED_ROBOTS, Robot, load_robot
    from .scenario import Scenario, bundled_scenarios, load_scenario
    from .stance import Contact, ContactSpec, Stance
