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
    "Analysis": ".analysis.analyze",
    "HeldStanceLimit": ".analysis.held_stance",
    "held_stance_max_contact_velocity": ".analysis.held_stance",
    "ImpactAnswer": ".analysis.analyze",
    "analyze": ".analysis.analyze",
    "BalanceAreas": ".balance.areas",
    "areas_from_polytope": ".balance.areas",
    "balance_areas": ".balance.areas",
    "GRAVITY": ".constants",
    "WrenchPolytope": ".contacts.wrench_polytope",
    "contact_polytope": ".contacts.wrench_polytope",
    "wrench_polytope": ".contacts.wrench_polytope",
    "ContactVelocityLimit": ".criteria.velocity_limit",
    "capped_velocity": ".criteria.cap",
    "max_contact_velocity": ".criteria.com",
    "zmp_max_contact_velocity": ".criteria.zmp",
    "cwc_faces": ".contacts.cwc",
    "cwc_faces_world": ".contacts.cwc",
    "cwc_span": ".contacts.cwc",
    "Diagnostic": ".analysis.result",
    "ImpactBalanceError": ".exceptions",
    "ImpactModelError": ".exceptions",
    "RobotLoadError": ".exceptions",
    "ScenarioError": ".exceptions",
    "SolverError": ".exceptions",
    "StrictWarningsError": ".exceptions",
    "UnknownConfigurationError": ".exceptions",
    "UnknownFrameError": ".exceptions",
    "UnknownJointError": ".exceptions",
    "UnknownKeyError": ".exceptions",
    "UnknownRobotError": ".exceptions",
    "UnknownScenarioError": ".exceptions",
    "ImpactModel": ".impact.model",
    "ImpactSpec": ".impact.model",
    "friction_cone": ".impact.model",
    "impact_model": ".impact.model",
    "PhasePortrait": ".balance.lipm",
    "com_velocity_bounds": ".balance.lipm",
    "finite_push_factor": ".balance.lipm",
    "lipm_omega": ".balance.lipm",
    "phase_portrait": ".balance.lipm",
    "Polygon": ".geometry.polygon",
    "project_polytope": ".projection",
    "QPOptions": ".criteria.qp",
    "QPResult": ".criteria.qp",
    "solve_contact_velocity_qp": ".criteria.qp",
    "BUNDLED_ROBOTS": ".robot.robot",
    "Robot": ".robot.robot",
    "load_robot": ".robot.robot",
    "Scenario": ".scenario",
    "bundled_scenarios": ".scenario",
    "load_scenario": ".scenario",
    "ContactAwareOptions": ".governor",
    "Governor": ".governor",
    "SpeedLimit": ".governor",
    "Contact": ".contacts.stance",
    "ContactSpec": ".contacts.stance",
    "Stance": ".contacts.stance",
}

__version__ = "0.1.0"

__all__ = [
    "BUNDLED_ROBOTS",
    "GRAVITY",
    "Analysis",
    "BalanceAreas",
    "Contact",
    "ContactAwareOptions",
    "ContactSpec",
    "ContactVelocityLimit",
    "Diagnostic",
    "Governor",
    "HeldStanceLimit",
    "ImpactAnswer",
    "ImpactBalanceError",
    "ImpactModel",
    "ImpactModelError",
    "ImpactSpec",
    "PhasePortrait",
    "Polygon",
    "QPOptions",
    "QPResult",
    "Robot",
    "RobotLoadError",
    "Scenario",
    "ScenarioError",
    "SolverError",
    "SpeedLimit",
    "Stance",
    "StrictWarningsError",
    "UnknownConfigurationError",
    "UnknownFrameError",
    "UnknownJointError",
    "UnknownKeyError",
    "UnknownRobotError",
    "UnknownScenarioError",
    "WrenchPolytope",
    "analyze",
    "areas_from_polytope",
    "balance_areas",
    "bundled_scenarios",
    "capped_velocity",
    "com_velocity_bounds",
    "contact_polytope",
    "cwc_faces",
    "cwc_faces_world",
    "cwc_span",
    "finite_push_factor",
    "friction_cone",
    "held_stance_max_contact_velocity",
    "impact_model",
    "lipm_omega",
    "load_robot",
    "load_scenario",
    "max_contact_velocity",
    "phase_portrait",
    "project_polytope",
    "solve_contact_velocity_qp",
    "wrench_polytope",
    "zmp_max_contact_velocity",
]


def __getattr__(name: str) -> Any:
    """Import a public name's module on first access (``impact_balance.analyze`` loads the core)."""
    module = _EXPORTS.get(name)
    if module is None:
        if not name.startswith("_") and importlib.util.find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(
                f".{name}", __name__
            )  # a submodule, as before: ib.scenario
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value  # later accesses skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # static analysers and IDEs see the plain imports
    from impact_balance.analysis.analyze import Analysis, ImpactAnswer, analyze
    from impact_balance.analysis.held_stance import (
        HeldStanceLimit,
        held_stance_max_contact_velocity,
    )
    from impact_balance.analysis.result import Diagnostic
    from impact_balance.balance.areas import BalanceAreas, areas_from_polytope, balance_areas
    from impact_balance.balance.lipm import (
        PhasePortrait,
        com_velocity_bounds,
        finite_push_factor,
        lipm_omega,
        phase_portrait,
    )
    from impact_balance.constants import GRAVITY
    from impact_balance.contacts.cwc import cwc_faces, cwc_faces_world, cwc_span
    from impact_balance.contacts.stance import Contact, ContactSpec, Stance
    from impact_balance.contacts.wrench_polytope import (
        WrenchPolytope,
        contact_polytope,
        wrench_polytope,
    )
    from impact_balance.criteria.cap import capped_velocity
    from impact_balance.criteria.com import max_contact_velocity
    from impact_balance.criteria.qp import QPOptions, QPResult, solve_contact_velocity_qp
    from impact_balance.criteria.velocity_limit import ContactVelocityLimit
    from impact_balance.criteria.zmp import zmp_max_contact_velocity
    from impact_balance.exceptions import (
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
    from impact_balance.geometry.polygon import Polygon
    from impact_balance.governor import ContactAwareOptions, Governor, SpeedLimit
    from impact_balance.impact.model import ImpactModel, ImpactSpec, friction_cone, impact_model
    from impact_balance.projection import project_polytope
    from impact_balance.robot.robot import BUNDLED_ROBOTS, Robot, load_robot
    from impact_balance.scenario import Scenario, bundled_scenarios, load_scenario
