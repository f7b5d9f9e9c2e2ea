"""The MuJoCo biped on a scene's terrain: handles by name, measurements, ankle torque mode.

:class:`BipedSim` holds the MuJoCo model and data of a walker model (:mod:`footfall.sim.biped.model`
or a robot file (:mod:`footfall.robots`)) standing on a scene's terrain and reads what the walk measures:
sole poses, the CoM state, and each foot's contact points and forces, from which
:func:`sole_cop` gives the centre of pressure (the measured ZMP). :func:`ankle_joint_torque`
turns the ALIP torque (eq. 5.3) into ankle joint torques.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.control.adjusters import SOLE_TORQUE_SHARE
from footfall.errors import FootfallError
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.sim.biped.model import (
    BipedModel,
    BipedSimSettings,
    WalkerModel,
    require_mujoco,
)
from footfall.sim.biped.terrain_mjcf import terrain_xml
from footfall.terrain.scene import Scene

#: positions of the ankle joints in ``LEG_JOINTS``
ANKLE_PITCH, ANKLE_ROLL = 4, 5
#: damping of a torque-driven ankle [N m s / rad]
ANKLE_TORQUE_DAMPING = 0.5


class BipedSim:
    """MuJoCo model + data of a biped on a scene's terrain, with handles resolved by name.

    ``model_params`` is any :class:`~footfall.sim.biped.model.WalkerModel`: our biped
    (:class:`BipedModel`, the default) or a robot file's :class:`footfall.robots.model.RobotModel`; its MJCF
    names its elements as :mod:`footfall.robots.names` does. ``settings`` go to its ``mjcf``
    (None: the model's defaults).
    """

    def __init__(
        self,
        scene: Scene,
        model_params: WalkerModel | None = None,
        settings: BipedSimSettings | None = None,
    ) -> None:
        mujoco = require_mujoco()
        self.mujoco = mujoco
        self.params: WalkerModel = model_params if model_params is not None else BipedModel()
        xml = self.params.mjcf(terrain_xml(scene.terrain), settings)
        #: the MJCF text compiled into ``model`` (a replay stores it, :mod:`footfall.sim.replay`)
        self.xml = xml
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        m = self.model
        obj = mujoco.mjtObj

        def ident(kind: Any, name: str) -> int:
            i = int(mujoco.mj_name2id(m, kind, name))
            if i < 0:
                raise FootfallError(f"biped model has no element named {name!r}")
            return i

        self.pelvis = ident(obj.mjOBJ_BODY, nm.PELVIS_BODY)
        self.torso = ident(obj.mjOBJ_BODY, nm.TORSO_BODY)
        self.root_adr = int(m.jnt_qposadr[ident(obj.mjOBJ_JOINT, nm.ROOT_JOINT)])
        self.sides = (Side.LEFT, Side.RIGHT)
        self.sole_sites = {s: ident(obj.mjOBJ_SITE, nm.sole_site(s)) for s in self.sides}
        self.joint_qpos = np.array(
            [
                m.jnt_qposadr[ident(obj.mjOBJ_JOINT, nm.joint(s, j))]
                for s in self.sides
                for j in nm.LEG_JOINTS
            ]
        )
        self.joint_dof = np.array(
            [
                m.jnt_dofadr[ident(obj.mjOBJ_JOINT, nm.joint(s, j))]
                for s in self.sides
                for j in nm.LEG_JOINTS
            ]
        )
        self.actuators = np.array(
            [
                ident(obj.mjOBJ_ACTUATOR, nm.actuator(s, j))
                for s in self.sides
                for j in nm.LEG_JOINTS
            ]
        )
        self.foot_of_geom: dict[int, Side] = {}
        for s in self.sides:
            for k in range(len(nm.FOOT_CORNERS)):
                self.foot_of_geom[ident(obj.mjOBJ_GEOM, nm.corner_geom(s, k))] = s
        self.body_geoms = {
            ident(obj.mjOBJ_GEOM, nm.PELVIS_GEOM),
            ident(obj.mjOBJ_GEOM, nm.TORSO_GEOM),
        }
        self._kp = np.array(m.actuator_gainprm[self.actuators, 0])
        self._bias = np.array(m.actuator_biasprm[self.actuators, :3])
        self.mass = float(np.sum(m.body_mass))
        self.weight = self.mass * float(-m.opt.gravity[2])
        self._f6 = np.zeros(6)

    def set_standing(self, left: FloatArray, right: FloatArray, heading: float) -> None:
        """Nominal posture with the soles at ``left``/``right`` (3,) [m], then forward kinematics."""
        d = self.data
        d.qpos[:] = 0.0
        d.qvel[:] = 0.0
        mid = 0.5 * (np.asarray(left) + np.asarray(right))
        d.qpos[self.root_adr : self.root_adr + 3] = (
            mid[0],
            mid[1],
            mid[2] + self.params.pelvis_height,
        )
        d.qpos[self.root_adr + 3 : self.root_adr + 7] = (
            math.cos(heading / 2),
            0.0,
            0.0,
            math.sin(heading / 2),
        )
        q = self.params.nominal_joints()
        d.qpos[self.joint_qpos] = q
        d.ctrl[self.actuators] = q
        self.mujoco.mj_kinematics(self.model, d)
        # a model whose nominal soles are not straight below the pelvis (the G1's reach forward of
        # its ankles) is moved so that their midpoint is the feet's; ours: no shift (<= 1e-9 m)
        shift = mid - 0.5 * (self.sole(Side.LEFT)[0] + self.sole(Side.RIGHT)[0])
        if float(np.max(np.abs(shift))) > 1e-9:
            d.qpos[self.root_adr : self.root_adr + 3] += shift
        self.mujoco.mj_forward(self.model, d)

    def ankle_actuators(self, side: Side) -> NDArray[np.int_]:
        """Indices into ``actuators`` of the ``side`` ankle (pitch, roll)."""
        base = len(nm.LEG_JOINTS) * self.sides.index(side)
        return np.array([base + ANKLE_PITCH, base + ANKLE_ROLL])

    def set_ankle_torque_mode(self, side: Side, torque: bool) -> None:
        """Switch the ``side`` ankle servos to torque (ctrl = joint torque [N m]) or position mode.

        A MuJoCo position actuator is ``gain * ctrl + bias`` with gain ``kp`` and bias
        ``(0, -kp, -kv)``; torque mode is gain 1 and only a small damping ``ANKLE_TORQUE_DAMPING``.
        """
        for j in self.ankle_actuators(side):
            a = self.actuators[j]
            if torque:
                self.model.actuator_gainprm[a, 0] = 1.0
                self.model.actuator_biasprm[a, :3] = (0.0, 0.0, -ANKLE_TORQUE_DAMPING)
            else:
                self.model.actuator_gainprm[a, 0] = self._kp[j]
                self.model.actuator_biasprm[a, :3] = self._bias[j]

    def sole(self, side: Side) -> tuple[FloatArray, FloatArray]:
        """Measured sole centre (3,) [m] and rotation (3, 3) of the ``side`` foot."""
        sid = self.sole_sites[side]
        return np.array(self.data.site_xpos[sid]), np.array(self.data.site_xmat[sid]).reshape(3, 3)

    def com_state(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """CoM position (3,) [m], velocity (3,) [m/s], angular momentum about the CoM (3,)."""
        self.mujoco.mj_subtreeVel(self.model, self.data)
        b = self.pelvis
        d = self.data
        return (
            np.array(d.subtree_com[b]),
            np.array(d.subtree_linvel[b]),
            np.array(d.subtree_angmom[b]),
        )

    def contacts(self) -> tuple[dict[Side, tuple[FloatArray, FloatArray]], bool]:
        """Per foot, contact points (n, 3) and forces on the robot (n, 3) [N]; body-hit flag."""
        d, m = self.data, self.model
        pts: dict[Side, list[FloatArray]] = {s: [] for s in self.sides}
        frc: dict[Side, list[FloatArray]] = {s: [] for s in self.sides}
        body_hit = False
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom[0]), int(c.geom[1])
            if g1 in self.body_geoms or g2 in self.body_geoms:
                body_hit = True
                continue
            if g1 in self.foot_of_geom:
                side, sign = self.foot_of_geom[g1], -1.0
            elif g2 in self.foot_of_geom:
                side, sign = self.foot_of_geom[g2], 1.0
            else:
                continue
            self.mujoco.mj_contactForce(m, d, i, self._f6)
            # the contact frame's rows are (normal, tangent1, tangent2) and the force acts from
            # geom1 on geom2: on the robot as is when the foot is geom2, reversed otherwise
            pts[side].append(np.array(c.pos))
            frc[side].append(sign * (c.frame.reshape(3, 3).T @ self._f6[:3]))
        out = {
            s: (np.array(pts[s]).reshape(-1, 3), np.array(frc[s]).reshape(-1, 3))
            for s in self.sides
        }
        return out, body_hit


def sole_cop(
    points: FloatArray, forces: FloatArray, sole_pos: FloatArray, sole_rot: FloatArray
) -> tuple[FloatArray, float] | None:
    """Centre of pressure of a foot in its sole frame.

    The contact points lie (to within the contact penetration) on the sole plane, so the CoP is
    the normal-force-weighted mean of the points; it is returned relative to the sole centre in
    the foot's (x forward, y left) axes.

    Args:
        points: contact points (n, 3) [m], world.
        forces: contact forces on the foot (n, 3) [N], world.
        sole_pos: sole centre (3,) [m].
        sole_rot: sole rotation (3, 3), columns x, y, normal.

    Returns:
        ``(offset (2,) [m], normal force [N])`` or None without a pushing contact.
    """
    if points.shape[0] == 0:
        return None
    fn = forces @ sole_rot[:, 2]
    total = float(np.sum(fn))
    if total <= 0.0:
        return None
    cop = (fn @ points) / total
    local = sole_rot.T @ (cop - sole_pos)
    return local[:2], total


def ankle_joint_torque(
    u: FloatArray, sole_rot: FloatArray, weight: float, params: WalkerModel
) -> FloatArray:
    """Ankle (pitch, roll) joint torques [N m] that make the ground exert the ALIP torque ``u``.

    ``u = (tau_x, tau_y)`` is the torque of the ground on the robot about the sole centre
    (eq. 5.3). The foot is light, so the ankle joints pass it on: a hinge torque acts ``+tau`` on
    the child (the foot) and ``-tau`` on the parent, hence joint torque = ``-u`` expressed in the
    foot's axes. Each component is clipped so that the CoP stays ``SOLE_TORQUE_SHARE`` inside
    the contact rectangle of the sole (a larger torque would only tip the foot).

    When the sole centre is not straight below the ankle axes (``params.ankle_offset`` = (dx, dy)
    in the foot frame, e.g. the G1's sole reaches further forward than back), the normal force
    ``weight`` on the sole centre adds its moment about the ankle: ``(dx, dy, -h) x (0, 0, F_n)
    = (dy F_n, -dx F_n)``, so the joints add ``(+dx F_n, -dy F_n)`` (pitch, roll). Ours: (0, 0).
    """
    local = sole_rot[:2, :2].T @ np.asarray(u, dtype=float)
    lim_x = SOLE_TORQUE_SHARE * weight * (params.foot_width / 2 - params.corner_radius)
    lim_y = SOLE_TORQUE_SHARE * weight * (params.foot_length / 2 - params.corner_radius)
    tau_x = float(np.clip(local[0], -lim_x, lim_x))
    tau_y = float(np.clip(local[1], -lim_y, lim_y))
    dx, dy = params.ankle_offset
    return np.array([-tau_y + dx * weight, -tau_x - dy * weight])
