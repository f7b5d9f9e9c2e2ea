"""Small helpers shared by the MJCF generators (quadruped, biped, terrain)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from footfall._validate import check_fields, non_negative, positive
from footfall.errors import MissingExtraError


def require_mujoco() -> Any:
    """Import MuJoCo (the ``sim`` extra) or raise a MissingExtraError saying how to install it."""
    try:
        import mujoco
    except ImportError as exc:
        raise MissingExtraError(
            f"MuJoCo is required: pip install 'footfall[sim]' ({exc})"
        ) from None
    return mujoco


def fmt(*values: float | np.floating, digits: int = 6) -> str:
    """Numbers as an MJCF attribute string with ``digits`` significant digits."""
    return " ".join(f"{float(v):.{digits}g}" for v in values)


def box_inertia(mass: float, sx: float, sy: float, sz: float) -> tuple[float, float, float]:
    """Principal inertia [kg m^2] of a solid box with full side lengths sx, sy, sz [m]."""
    return (
        mass * (sy * sy + sz * sz) / 12.0,
        mass * (sx * sx + sz * sz) / 12.0,
        mass * (sx * sx + sy * sy) / 12.0,
    )


def rod_inertia(mass: float, length: float, radius: float) -> tuple[float, float, float]:
    """Slender rod along z: principal inertia about its centre [kg m^2]."""
    transverse = mass * (3.0 * radius * radius + length * length) / 12.0
    return transverse, transverse, 0.5 * mass * radius * radius


@dataclass(frozen=True)
class SimSettings:
    """Physics and actuator settings of a generated model (defaults: the 100 kg quadruped).

    Attributes:
        timestep: physics step [s].
        kp: position gain of every joint actuator [N m / rad].
        kv: velocity gain (damping) of every joint actuator [N m s / rad].
        torque_limit: actuator torque limit [N m].
        friction: sliding friction coefficient between feet and ground.
        impratio: ratio of frictional to normal constraint impedance (elliptic cone).
        armature: rotor inertia added to each joint [kg m^2] (stabilises stiff position control).
        joint_damping: viscous damping of every joint of the generated quadruped [N m s / rad].
    """

    timestep: float = 0.002
    kp: float = 6000.0
    kv: float = 120.0
    torque_limit: float = 1500.0
    friction: float = 1.0
    impratio: float = 10.0
    armature: float = 0.05
    joint_damping: float = 2.0

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive,
            ("timestep", "kp", "kv", "torque_limit", "friction", "impratio"),
            prefix="sim.",
        )
        object.__setattr__(self, "armature", non_negative("sim.armature", self.armature))
        object.__setattr__(
            self, "joint_damping", non_negative("sim.joint_damping", self.joint_damping)
        )


def mjcf_preamble(
    settings: SimSettings, joint_damping: float, geom_default: str, shadow_size: int
) -> str:
    """The ``<compiler>``, ``<option>``, ``<visual>`` and ``<default>`` elements every generated
    robot shares: radians, the implicit-fast integrator with an elliptic friction cone (feet do
    not creep on slopes), an offscreen buffer for 1280 x 720 video, and the joint defaults."""
    s = settings
    return f"""<compiler angle="radian" autolimits="true"/>
  <option timestep="{s.timestep:.6g}" integrator="implicitfast" cone="elliptic"
          impratio="{s.impratio:.6g}"/>
  <visual>
    <global offwidth="1280" offheight="720"/>
    <quality shadowsize="{shadow_size}"/>
  </visual>
  <default>
    <joint damping="{joint_damping:g}" armature="{s.armature:.6g}"/>
    <geom {geom_default}/>
  </default>"""


#: the checker texture of the ground and the robot's materials, shared by every generated model
GRID_TEXTURE = """<texture name="grid" type="2d" builtin="checker" rgb1="0.55 0.6 0.55" rgb2="0.45 0.5 0.45"
             width="512" height="512"/>"""
ROBOT_MATERIALS = """<material name="body" rgba="0.25 0.35 0.6 1"/>
    <material name="leg" rgba="0.7 0.7 0.72 1"/>
    <material name="joint" rgba="0.3 0.3 0.3 1"/>
    <material name="foot" rgba="0.15 0.15 0.15 1"/>"""


#: the terrain's material (the region geoms of :mod:`footfall.sim.biped.terrain_mjcf`)
TERRAIN_MATERIAL = '<material name="terrain" texture="grid" texrepeat="4 4" texuniform="true"/>'
#: the light of every generated world
LIGHT = '<light pos="0 -3 6" dir="0 0.4 -1" directional="true"/>'


def mjcf_document(model: str, preamble: str, assets: str, world: str, actuators: str) -> str:
    """An MJCF document of a generated world: ``preamble`` (:func:`mjcf_preamble`), the ground
    texture and robot materials plus ``assets``, the light plus ``world`` (terrain geoms and the
    robot's bodies), and ``actuators``."""
    return f"""<mujoco model="{model}">
  {preamble}
  <asset>
    {GRID_TEXTURE}
    {ROBOT_MATERIALS}
    {assets}
  </asset>
  <worldbody>
    {LIGHT}
    {world}
  </worldbody>
  <actuator>
    {actuators}
  </actuator>
</mujoco>
"""


def position_actuator(name: str, joint_attr: str, settings: SimSettings) -> str:
    """A position servo on a joint (``joint_attr`` is the quoted attribute value) with the
    settings' gains and torque limit."""
    s = settings
    return (
        f'<position name="{name}" joint={joint_attr} kp="{s.kp:.6g}" kv="{s.kv:.6g}" '
        f'forcerange="{fmt(-s.torque_limit, s.torque_limit)}"/>'
    )
