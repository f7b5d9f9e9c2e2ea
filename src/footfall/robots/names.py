"""Names of the MuJoCo elements of a walker model (footfall's biped or a robot file's) and of the
terrain geoms, defined once: the contract between the robot models and the walker."""

from __future__ import annotations

from footfall.errors import UnknownNameError
from footfall.models.biped import Side

MODEL_NAME = "footfall_biped"
PELVIS_BODY = "pelvis"
TORSO_BODY = "torso"
TORSO_GEOM = "torso_box"
PELVIS_GEOM = "pelvis_box"
ROOT_JOINT = "root"
TRACK_CAMERA = "track"
#: terrain geoms are named ``region_<region name>``
REGION_GEOM_PREFIX = "region_"
REGION_MESH_PREFIX = "region_mesh_"

#: leg joints from the pelvis to the foot (hip yaw/roll/pitch, knee, ankle pitch/roll)
LEG_JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
#: joint axes in the parent body frame, in ``LEG_JOINTS`` order
LEG_JOINT_AXES = ("0 0 1", "1 0 0", "0 1 0", "0 1 0", "0 1 0", "1 0 0")
#: foot sole corners in the foot frame, as signs of (x, y): toe-left, toe-right, heel-right,
#: heel-left
FOOT_CORNERS = ((1, 1), (1, -1), (-1, -1), (-1, 1))

#: collision bits: terrain collides with the robot's feet, pelvis and torso; robot parts never
#: collide with each other (contype & conaffinity of two robot geoms is 0)
TERRAIN_CONTYPE, TERRAIN_CONAFFINITY = 1, 2
#: geom groups: terrain in 0, robot in 1 (ray casts against the terrain use group 0 only)
TERRAIN_GROUP, ROBOT_GROUP = 0, 1
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 1


def _side(side: Side) -> str:
    return Side(side).value


def joint(side: Side, name: str) -> str:
    """Joint name, e.g. ``left_knee``; ``name`` is one of ``LEG_JOINTS``."""
    if name not in LEG_JOINTS:
        raise UnknownNameError("joint", name, f"one of {', '.join(LEG_JOINTS)}")
    return f"{_side(side)}_{name}"


def actuator(side: Side, name: str) -> str:
    """Position actuator driving ``joint(side, name)``."""
    return f"{joint(side, name)}_pos"


def link_body(side: Side, name: str) -> str:
    """Body whose parent joint is ``joint(side, name)``."""
    return f"{joint(side, name)}_link"


def foot_body(side: Side) -> str:
    """The foot (child of the ankle roll joint)."""
    return link_body(side, LEG_JOINTS[-1])


def sole_site(side: Side) -> str:
    """Site at the sole centre: the point the planner's footsteps refer to; z axis = sole normal."""
    return f"{_side(side)}_sole"


def corner_geom(side: Side, corner: int) -> str:
    """Contact sphere at sole corner ``corner`` (index into ``FOOT_CORNERS``)."""
    return f"{_side(side)}_corner{corner}"


def foot_geom(side: Side) -> str:
    """Visual box of the foot (no collision; the corner spheres carry the contact)."""
    return f"{_side(side)}_foot_box"


def region_geom(region_name: str) -> str:
    """Terrain geom of the region named ``region_name``."""
    return f"{REGION_GEOM_PREFIX}{region_name}"
