"""Names of the MuJoCo elements of the document-001 quadruped, defined once."""

from __future__ import annotations

from footfall.errors import UnknownNameError
from footfall.quadruped.robot import JOINT_NAMES, Leg

MODEL_NAME = "footfall_quadruped"
TRUNK_BODY = "trunk"
TRUNK_GEOM = "trunk_box"
ROOT_JOINT = "root"
FLOOR_GEOM = "floor"
STAIR_GEOM_PREFIX = "stair_"
PLANK_GEOM_PREFIX = "plank_"
TRACK_CAMERA = "track"

#: collision bits: the ground collides with feet and trunk, robot parts never with each other
GROUND_CONTYPE, GROUND_CONAFFINITY = 1, 1
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 1


def hip_body(leg: Leg) -> str:
    """Body carrying the hip ab/ad joint."""
    return f"{leg.value}_hip"


def thigh_body(leg: Leg) -> str:
    """Body carrying the hip pitch joint."""
    return f"{leg.value}_thigh"


def shank_body(leg: Leg) -> str:
    """Body carrying the knee joint and the foot."""
    return f"{leg.value}_shank"


def joint(leg: Leg, joint_name: str) -> str:
    """Joint name, e.g. ``LF_knee``; ``joint_name`` is one of ``JOINT_NAMES``."""
    if joint_name not in JOINT_NAMES:
        raise UnknownNameError("joint", joint_name, f"one of {', '.join(JOINT_NAMES)}")
    return f"{leg.value}_{joint_name}"


def actuator(leg: Leg, joint_name: str) -> str:
    """Position actuator driving ``joint(leg, joint_name)``."""
    return f"{joint(leg, joint_name)}_pos"


def foot_geom(leg: Leg) -> str:
    """Spherical foot collision geom."""
    return f"{leg.value}_foot"


def foot_site(leg: Leg) -> str:
    """Site at the foot centre (the point the planner's foot positions refer to)."""
    return f"{leg.value}_foot_site"
