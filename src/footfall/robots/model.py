"""A robot file's humanoid as a walker model (the walker's ``WalkerModel``): the MuJoCo model of
:mod:`footfall.robots.build` and the facts of :mod:`footfall.robots.derive`, each computed once per
robot file and process."""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

import numpy as np

from footfall._mjcf import GRID_TEXTURE, LIGHT, TERRAIN_MATERIAL
from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.robots.build import Layout, layout, walker_xml
from footfall.robots.derive import (
    Kinematics,
    LegInfo,
    Reach,
    best_pelvis_height,
    derive_reach,
    measure_leg,
    nominal_posture,
)
from footfall.robots.file import RobotFile

#: pelvis heights tried when a robot file gives none: these shares of the straight-leg height
PELVIS_SHARES = tuple(np.round(np.arange(0.80, 0.985, 0.02), 3))


@functools.lru_cache(maxsize=8)
def _layout(rf: RobotFile) -> Layout:
    return layout(rf)


@functools.lru_cache(maxsize=8)
def _kinematics(rf: RobotFile) -> Kinematics:
    return Kinematics(walker_xml(rf, _layout(rf)))


@functools.lru_cache(maxsize=8)
def straight_leg_height(rf: RobotFile) -> float:
    """Pelvis origin above the soles with straight legs [m] (all leg joints at zero)."""
    kin = _kinematics(rf)
    kin.pose(np.zeros(12), np.zeros(3))
    return float(-min(p[2] for p, _ in kin.soles()))


@functools.lru_cache(maxsize=8)
def pelvis_height(rf: RobotFile) -> float:
    """The file's pelvis height, else the height with the largest double-support joint margins
    (:func:`~footfall.robots.derive.best_pelvis_height`) among ``PELVIS_SHARES`` of the
    straight-leg height."""
    if rf.pelvis_height is not None:
        return rf.pelvis_height
    full = straight_leg_height(rf)
    heights = [round(float(s) * full, 3) for s in PELVIS_SHARES]
    xml = walker_xml(rf, _layout(rf))
    return best_pelvis_height(lambda _h: xml, heights, rf.stance_width)


@functools.lru_cache(maxsize=8)
def _posture(rf: RobotFile) -> tuple[float, ...]:
    q = nominal_posture(_kinematics(rf), pelvis_height(rf), rf.stance_width)
    return tuple(float(v) for v in q)


@functools.lru_cache(maxsize=8)
def reach(rf: RobotFile) -> Reach:
    """The file's reach and step height, else derived (:func:`~footfall.robots.derive.derive_reach`)."""
    if rf.reach is not None and rf.step_height_max is not None:
        return Reach(rf.reach, rf.step_height_max)
    lay = _layout(rf)
    derived = derive_reach(
        _kinematics(rf), pelvis_height(rf), rf.stance_width, lay.sole.width, straight_leg_height(rf)
    )
    return Reach(
        rf.reach if rf.reach is not None else derived.vertices,
        rf.step_height_max if rf.step_height_max is not None else derived.step_height_max,
    )


@functools.lru_cache(maxsize=8)
def leg(rf: RobotFile) -> LegInfo:
    """The swing leg measured at the nominal posture."""
    return measure_leg(_kinematics(rf), np.array(_posture(rf)), pelvis_height(rf))


@dataclass(frozen=True)
class RobotModel:
    """A walker model from a robot file (the walker's ``WalkerModel``).

    Attributes:
        file: the robot file.
    """

    file: RobotFile

    @property
    def name(self) -> str:
        """The robot file's name."""
        return self.file.name

    @property
    def layout(self) -> Layout:
        """Legs, sole, torso and boxes (found or given)."""
        return _layout(self.file)

    @property
    def pelvis_height(self) -> float:
        """Pelvis (base) origin above the soles in the nominal posture [m]."""
        return pelvis_height(self.file)

    @property
    def foot_length(self) -> float:
        """Sole length [m]."""
        return self.layout.sole.length

    @property
    def foot_width(self) -> float:
        """Sole width [m]."""
        return self.layout.sole.width

    @property
    def corner_radius(self) -> float:
        """Radius of the sole's corner contact spheres [m]."""
        return self.layout.sole.radius

    @property
    def stance_width(self) -> float:
        """Lateral distance between the sole centres in the nominal posture [m]."""
        return self.file.stance_width

    @property
    def ankle_offset(self) -> tuple[float, float]:
        """Sole centre relative to the ankle axes in the foot frame (x: from the pitch axis, y:
        from the roll axis) [m]."""
        return _ankle_offset(self.file)

    def nominal_joints(self) -> FloatArray:
        """Leg joint angles (12,) [rad] of the nominal posture."""
        return np.array(_posture(self.file))

    def robot_limits(self) -> tuple[Reach, LegInfo]:
        """The reach, step height and swing leg the planner's parameters are derived from."""
        return reach(self.file), leg(self.file)

    def mjcf(self, terrain: tuple[str, str] = ("", ""), settings: Any = None) -> str:
        """MJCF of the robot on ``terrain`` (``(asset_xml, worldbody_xml)``).

        Raises:
            InputError: ``settings`` given: a robot's physics settings are its file's.
        """
        if settings is not None:
            raise InputError("settings", settings, "None (set physics: in the robot file)")
        return _with_terrain(walker_xml(self.file, self.layout), terrain)


@functools.lru_cache(maxsize=8)
def _ankle_offset(rf: RobotFile) -> tuple[float, float]:
    kin = _kinematics(rf)
    mj, m, d = kin.mj, kin.model, kin.data
    kin.pose(np.array(_posture(rf)), np.array([0.0, 0.0, pelvis_height(rf)]))
    foot = mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, nm.foot_body(Side.LEFT))
    rot, origin = d.xmat[foot].reshape(3, 3), d.xpos[foot]

    def local(p: FloatArray) -> FloatArray:
        return np.asarray(rot.T @ (p - origin))

    pitch = kin.jid[nm.LEG_JOINTS.index("ankle_pitch")]
    roll = kin.jid[nm.LEG_JOINTS.index("ankle_roll")]
    sole = local(d.site_xpos[kin.sites[0]])
    return (
        float(sole[0] - local(d.xanchor[pitch])[0]),
        float(sole[1] - local(d.xanchor[roll])[1]),
    )


def _with_terrain(robot_xml: str, terrain: tuple[str, str]) -> str:
    """``robot_xml`` with the terrain's assets and geoms and a light added."""
    root = ET.fromstring(robot_xml)
    asset_xml, world_xml = terrain
    extra = ET.fromstring(
        f"<mujoco><asset>{GRID_TEXTURE}{TERRAIN_MATERIAL}{asset_xml}</asset><worldbody>"
        f"{LIGHT}{world_xml}</worldbody></mujoco>"
    )
    for tag in ("asset", "worldbody"):
        dest = root.find(tag)
        if dest is None:
            dest = ET.SubElement(root, tag)
        src = extra.find(tag)
        assert src is not None
        # terrain first in the world body: the robot keeps its body order
        for i, e in enumerate(list(src)):
            dest.insert(i, e)
    return ET.tostring(root, encoding="unicode")
