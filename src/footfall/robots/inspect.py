"""``footfall robot inspect``: what footfall finds and derives in a robot model, and the complete
robot file.

:func:`inspect_robot` takes a URDF/MJCF (with an optional robot file whose given values it keeps)
or a robot file, derives every value the file leaves out (:mod:`footfall.robots.build`,
:mod:`footfall.robots.derive`) and returns an :class:`Inspection`: the values with their units,
the text of the completed robot file (which ``--robot FILE`` takes as it is) and a figure of the
posture, the sole and the reach.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import save_figure
from footfall.models.biped import Side
from footfall.robots.file import (
    RobotFile,
    inspect_input_is_file,
    load_robot_file,
    model_entry,
    package_of,
    robot_file_yaml,
)
from footfall.robots.model import RobotModel, _kinematics, straight_leg_height


@dataclass(frozen=True)
class Inspection:
    """What :func:`inspect_robot` found.

    Attributes:
        robot: the completed robot file (every derived value filled in).
        mass: total mass [kg] (MuJoCo's, the walker model).
        com_height: CoM height above the soles in the nominal posture [m].
        leg_length: pelvis height with straight legs [m].
        foot: the foot link of each side.
        joint_limits: per leg joint (left leg, footfall's order): (lower, upper) [rad] and the
            torque limit [N m].
        ankle_offset: sole centre from the ankle axes (x, y) in the foot frame [m].
        leg_inertia: the swing leg's inertia about its hip pitch axis [kg m^2].
    """

    robot: RobotFile
    mass: float
    com_height: float
    leg_length: float
    foot: dict[Side, str]
    joint_limits: list[tuple[str, float, float, float]]
    ankle_offset: tuple[float, float]
    leg_inertia: float

    def lines(self) -> list[str]:
        """The derived values, one per line, with units."""
        rf, sole = self.robot, self.model.layout.sole
        assert rf.pelvis_height is not None and rf.reach is not None
        assert rf.step_height_max is not None
        out = [
            f"robot {rf.name}: {rf.model}",
            f"mass {self.mass:.2f} kg; CoM {self.com_height:.3f} m above the soles",
            f"pelvis height {rf.pelvis_height:.3f} m (straight legs {self.leg_length:.3f} m); "
            f"stance width {rf.stance_width:.3f} m",
            f"sole {sole.length:.3f} x {sole.width:.3f} m (x {sole.x[0]:+.3f}..{sole.x[1]:+.3f}, "
            f"y {sole.y[0]:+.3f}..{sole.y[1]:+.3f}, z {sole.z:+.3f} m in the foot frame); "
            f"ankle offset ({self.ankle_offset[0]:+.3f}, {self.ankle_offset[1]:+.3f}) m",
            f"feet: {self.foot[Side.LEFT]}, {self.foot[Side.RIGHT]}",
            "legs (left): "
            + "; ".join(
                f"{n} [{lo:+.2f}, {hi:+.2f}] rad, {t:g} N m" for n, lo, hi, t in self.joint_limits
            ),
            f"swing leg inertia about the hip {self.leg_inertia:.3f} kg m^2",
            "reach (next footstep from a right stance foot) "
            + ", ".join(f"({x:+.3f}, {y:+.3f})" for x, y in rf.reach)
            + f" m; step height up to {rf.step_height_max:.2f} m",
        ]
        return out

    @property
    def model(self) -> RobotModel:
        """The walker model of the completed file."""
        return RobotModel(self.robot)


def _robot_of(model: Path, config: Path | None, name: str | None) -> RobotFile:
    if inspect_input_is_file(model, config):
        rf = load_robot_file(model)
    else:
        if config is not None:
            rf = replace(load_robot_file(config), model=model.resolve(), package=package_of(model))
        else:
            rf = RobotFile(
                name=name or model.stem[:64], model=model.resolve(), package=package_of(model)
            )
    return replace(rf, name=name) if name else rf


def inspect_robot(model: Path, config: Path | None = None, name: str | None = None) -> Inspection:
    """Find and derive everything about the humanoid ``model`` (a URDF/MJCF, with ``config`` a
    robot file whose given values are kept, or a robot file)."""
    rf = _robot_of(Path(model), config, name)
    walker = RobotModel(rf)
    lay = walker.layout
    reach, leg = walker.robot_limits()
    complete = replace(
        rf,
        legs=lay.legs,
        sole=lay.sole,
        torso=lay.torso,
        pelvis_height=round(walker.pelvis_height, 3),
        reach=reach.vertices,
        step_height_max=reach.step_height_max,
    )
    from footfall.robots import names as nm

    kin = _kinematics(rf)
    kin.pose(walker.nominal_joints(), np.array([0.0, 0.0, walker.pelvis_height]))
    com_height = float(kin.com()[2] - kin.soles()[0][0][2])
    mj, m = _compiled(RobotModel(complete))
    limits = []
    for joint in nm.LEG_JOINTS:
        j = mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, nm.joint(Side.LEFT, joint))
        a = mj.mj_name2id(m, mj.mjtObj.mjOBJ_ACTUATOR, nm.actuator(Side.LEFT, joint))
        torque = float(m.actuator_forcerange[a, 1]) if m.actuator_forcelimited[a] else math.inf
        limits.append((joint, float(m.jnt_range[j, 0]), float(m.jnt_range[j, 1]), torque))
    return Inspection(
        robot=complete,
        mass=float(np.sum(m.body_mass)),
        com_height=com_height,
        leg_length=straight_leg_height(rf),
        foot=dict(zip(Side, lay.feet, strict=True)),
        joint_limits=limits,
        ankle_offset=walker.ankle_offset,
        leg_inertia=leg.inertia,
    )


def _compiled(walker: RobotModel) -> tuple[Any, Any]:
    from footfall._mjcf import require_mujoco

    mj = require_mujoco()
    return mj, mj.MjModel.from_xml_string(walker.mjcf())


def robot_file_text(rf: RobotFile, base: Path | None = None) -> str:
    """The YAML text of a complete robot file (model path relative to ``base`` when inside it;
    a file of an installed distribution as ``package``/``path``)."""
    model = model_entry(rf.model, rf.package, base)
    assert rf.legs is not None and rf.sole is not None and rf.reach is not None
    data: dict[str, Any] = {
        "name": rf.name,
        "model": model,
        **({"base": rf.base} if rf.base else {}),
        "torso": rf.torso,
        "legs": {"left": list(rf.legs.left), "right": list(rf.legs.right)},
        "sole": {
            "x": [round(v, 4) for v in rf.sole.x],
            "y": [round(v, 4) for v in rf.sole.y],
            "z": round(rf.sole.z, 4),
            "radius": rf.sole.radius,
        },
        "pelvis_height": rf.pelvis_height,
        "stance_width": rf.stance_width,
        "reach": [[round(x, 3), round(y, 3)] for x, y in rf.reach],
        "step_height_max": rf.step_height_max,
    }
    return robot_file_yaml(
        "robot file", rf.name, "the legs, sole, pelvis height, reach and step height", data
    )


def plot_inspection(ins: Inspection, path: Path) -> Path:
    """The nominal posture from the side and the front, the sole on the foot's collision
    outline, and the reach trapezoid with the nominal stance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon, Rectangle

    walker = ins.model
    mj, m = _compiled(walker)
    d = mj.MjData(m)
    from footfall.robots import names as nm

    root = m.jnt_qposadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, nm.ROOT_JOINT)]
    d.qpos[root + 2] = walker.pelvis_height
    d.qpos[root + 3] = 1.0
    q = walker.nominal_joints()
    for k, (s, j) in enumerate((s, j) for s in Side for j in nm.LEG_JOINTS):
        jid = mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, nm.joint(s, j))
        d.qpos[m.jnt_qposadr[jid]] = q[k]
    mj.mj_kinematics(m, d)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.5))
    for ax, (i, label) in zip(
        axes[:2], ((0, "x (side view) [m]"), (1, "y (front view) [m]")), strict=True
    ):
        for b in range(1, m.nbody):
            p = int(m.body_parentid[b])
            if p > 0:
                ax.plot([d.xpos[p][i], d.xpos[b][i]], [d.xpos[p][2], d.xpos[b][2]], "k-", lw=1)
        ax.plot(d.xpos[1:, i], d.xpos[1:, 2], "o", ms=2, c="tab:blue")
        ax.axhline(0.0, c="0.6", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlabel(label)
        ax.set_ylabel("z [m]")
    axes[0].set_title(f"{ins.robot.name}: nominal posture, pelvis {walker.pelvis_height:.3f} m")
    ax = axes[2]
    rf = ins.robot
    assert rf.reach is not None and rf.sole is not None
    ax.add_patch(Polygon(np.array(rf.reach), closed=True, fc="tab:green", alpha=0.3, label="reach"))
    sole = rf.sole
    for cy, lab in ((0.0, "stance sole"), (rf.stance_width, "nominal step")):
        ax.add_patch(
            Rectangle(
                (sole.x[0] - sole.centre[0], cy - sole.width / 2),
                sole.length,
                sole.width,
                fc="none",
                ec="k",
                label=lab,
            )
        )
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x from the stance sole [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"reach; steps up/down to {rf.step_height_max:.2f} m")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
