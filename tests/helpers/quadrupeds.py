"""Quadrupeds standing on four point feet, as scenario mappings (robots by name)."""

from __future__ import annotations

from typing import Any

__all__ = ["FEET", "four_point_feet"]

#: The foot frames of the quadrupeds example-robot-data ships, by robot name.
FEET = {
    "go2": ("FL_foot", "FR_foot", "RL_foot", "RR_foot"),
    "anymal_c": ("LF_FOOT", "LH_FOOT", "RF_FOOT", "RH_FOOT"),
    "solo12": ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"),
}


def four_point_feet(robot: str, friction: float = 0.7) -> dict[str, Any]:
    """``robot`` at its SRDF's standing posture on its four feet, point contacts laid flat."""
    return {
        "description": f"{robot} standing on four point feet",
        "robot": robot,
        "configuration": "standing",
        "contacts": [
            {"frame": f, "friction": friction, "size": [0, 0], "normal": [0, 0, 1]}
            for f in FEET[robot]
        ],
    }
