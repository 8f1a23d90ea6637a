"""Simulation of a scenario in MuJoCo: the model (:mod:`.model`), its joint models, an impact trial.

See :func:`build_model` and :class:`SimModel`.
"""

from .environment import ContactParameters
from .joints import JOINT_MODELS, ServoOptions
from .model import SimModel, SimOptions, build_model

__all__ = ["build_model", "SimModel", "SimOptions", "ContactParameters", "ServoOptions", "JOINT_MODELS"]
