"""impact-balance: impact-aware multi-contact balance criteria for legged robots.

Implements Wang, Tanguy and Kheddar, "Impact-Aware Multi-Contact Balance Criteria"
(IEEE T-RO 2023): the ZMP support area and CoM velocity area (zero-step capture region) of
any set of contacts, the frictional impact model, and the maximum contact velocity.

Data flow: scenario -> stance -> constraints -> areas -> impact -> answer.
"""

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
