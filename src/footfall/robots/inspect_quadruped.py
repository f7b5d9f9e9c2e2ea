"""``footfall robot inspect`` of a quadruped: what footfall finds and derives in the model, and the
complete quadruped robot file (which ``footfall quadruped --robot FILE`` takes as it is).

A model is a quadruped when its four quadrants (front/hind x left/right of the base) each hold a
leg of three hinge joints (:func:`~footfall.robots.quadruped.find_quadruped_legs`); the values
come from :func:`~footfall.robots.quadruped.derive_quadruped`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import save_figure
from footfall.errors import InputError
from footfall.quadruped import GaitParams
from footfall.quadruped.kinematics import leg_link_points, whole_body_ik
from footfall.quadruped.robot import LEGS
from footfall.quadruped.scaling import gait_scale, scale_gait
from footfall.robots.build import raw_model
from footfall.robots.file import (
    MODEL_FORMATS,
    inspect_input_is_file,
    model_entry,
    package_of,
    robot_file_yaml,
)
from footfall.robots.quadruped import (
    QuadrupedDerivation,
    QuadrupedFile,
    derive_quadruped,
    find_quadruped_legs,
    is_quadruped_file,
    parse_quadruped_file,
)

#: the slope of the default gait ``lines`` reports [deg]
REPORT_SLOPE_DEG = 15.0


@dataclass(frozen=True)
class QuadrupedInspection:
    """What :func:`inspect_quadruped` found: the completed file and the derivation."""

    file: QuadrupedFile
    derived: QuadrupedDerivation
    gait: GaitParams | None
    gait_note: str

    def lines(self) -> list[str]:
        """The derived values, one per line, with units."""
        r, d = self.derived.robot, self.derived
        out = [
            f"quadruped {self.file.name}: {self.file.model}",
            f"mass {r.total_mass:.2f} kg (trunk {r.body_mass:.2f} kg, legs "
            f"{4 * r.leg_mass:.2f} kg); stance height {d.stance_height:.3f} m; foot radius "
            f"{d.foot_radius:.4f} m; knees {d.knees}",
            f"leg length (pitch axis to foot) {r.min_leg_length:.3f}-{r.max_leg_length:.3f} m",
        ]
        for leg, g in zip(LEGS, r.legs or (), strict=True):
            torque = "model's none" if g.torque is None else "/".join(f"{t:g}" for t in g.torque)
            out.append(
                f"{leg.value}: {', '.join(g.joints)}; hip at ({g.origin[0]:+.3f}, "
                f"{g.origin[1]:+.3f}, {g.origin[2]:+.3f}) m, foot {g.lateral:+.3f} m sideways; "
                + "; ".join(
                    f"[{lo:+.2f}, {hi:+.2f}] rad" for lo, hi in zip(g.lower, g.upper, strict=True)
                )
                + f"; {torque} N m"
            )
        if self.gait is not None:
            gp = self.gait
            out.append(
                f"gait on {REPORT_SLOPE_DEG:g} deg (scale {gait_scale(r):.3f} of document 001's): "
                f"step {gp.step:.3f} m, swing height {gp.swing_height:.3f} m, swing "
                f"{gp.swing_period:.2f} s, shift {gp.shift_period:.2f} s"
            )
        else:
            out.append(f"gait on {REPORT_SLOPE_DEG:g} deg: {self.gait_note}")
        if d.dropped:
            out.append(f"meshes MuJoCo cannot read, left out: {len(d.dropped)}")
        if d.repaired:
            out.append(f"inertias not positive definite, products dropped: {', '.join(d.repaired)}")
        return out


def looks_quadruped(model: Path, config: Path | None) -> bool:
    """Whether ``footfall robot inspect`` should treat its input as a quadruped: a quadruped robot
    file given (as MODEL or ``--config``), else a model with a three-joint leg per quadrant."""
    for path in (model, config):
        if path is not None and path.suffix.lower() in (".yaml", ".yml"):
            if not path.is_file():
                raise InputError("MODEL" if path == model else "--config", str(path), "a file")
            return is_quadruped_file(path)
    if model.suffix.lower() not in MODEL_FORMATS or not model.is_file():
        return False
    raw = raw_model(QuadrupedFile(name="probe", model=model.resolve()))
    try:
        legs = find_quadruped_legs(raw)
    except InputError:
        return False
    return len({j for leg in legs for j in leg}) == 12


def _file_of(model: Path, config: Path | None, name: str | None) -> QuadrupedFile:
    if inspect_input_is_file(model, config):
        qf = parse_quadruped_file(model, str(model), model.parent)
    else:
        if config is not None:
            qf = replace(
                parse_quadruped_file(config, str(config), config.parent),
                model=model.resolve(),
                package=package_of(model),
            )
        else:
            qf = QuadrupedFile(
                name=name or model.stem[:64], model=model.resolve(), package=package_of(model)
            )
    return replace(qf, name=name) if name else qf


def inspect_quadruped(
    model: Path, config: Path | None = None, name: str | None = None
) -> QuadrupedInspection:
    """Find and derive everything about the quadruped ``model`` (a URDF/MJCF, with ``config`` a
    quadruped robot file whose given values are kept, or a quadruped robot file)."""
    qf = _file_of(Path(model), config, name)
    derived = derive_quadruped(qf)
    complete = replace(
        qf,
        legs=derived.joints,
        foot_radius=round(derived.foot_radius, 4),
        knees=derived.knees if derived.knees != "mixed" else qf.knees,
        stance_height=round(derived.stance_height, 3),
    )
    slope = math.radians(REPORT_SLOPE_DEG)
    try:
        gait: GaitParams | None = scale_gait(
            derived.robot, GaitParams(slope=slope, body_pitch=2.0 * slope / 3.0)
        )
        note = ""
    except InputError as e:
        gait, note = None, f"{e.field}: {e.expected}"
    return QuadrupedInspection(complete, derived, gait, note)


def quadruped_file_text(qf: QuadrupedFile, base: Path | None = None) -> str:
    """The YAML text of a complete quadruped robot file (model path relative to ``base`` when
    inside it; a file of an installed distribution as ``package``/``path``)."""
    model = model_entry(qf.model, qf.package, base)
    assert qf.legs is not None
    data: dict[str, Any] = {
        "name": qf.name,
        "kind": "quadruped",
        "model": model,
        **({"base": qf.base} if qf.base else {}),
        "legs": {leg.value: list(j) for leg, j in zip(LEGS, qf.legs, strict=True)},
        "foot_radius": qf.foot_radius,
        **({"knees": qf.knees} if qf.knees else {}),
        **({"torque_limit": list(qf.torque_limit)} if qf.torque_limit else {}),
        "stance_height": qf.stance_height,
    }
    return robot_file_yaml(
        "quadruped robot file", qf.name, "the legs, foot radius, knee bend and stance height", data
    )


def plot_quadruped(ins: QuadrupedInspection, path: Path) -> Path:
    """The neutral stance from the side and the front (legs by their joint points, the planner's
    point masses' CoM), and the feet's support polygon from above."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    robot = ins.derived.robot
    body = np.array([0.0, 0.0, robot.stance_height])
    feet = np.array([[*robot.stance_offset(leg)[:2], 0.0] for leg in LEGS])
    q = whole_body_ik(robot, body, 0.0, feet)
    chains = []
    for i, leg in enumerate(LEGS):
        pts = leg_link_points(robot, q[3 * i : 3 * i + 3], leg) + robot.hip_offset(leg) + body
        chains.append(np.vstack([body + robot.hip_offset(leg), pts]))
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    for ax, (i, label) in zip(
        axes[:2], ((0, "x (side view) [m]"), (1, "y (front view) [m]")), strict=True
    ):
        for c in chains:
            ax.plot(c[:, i], c[:, 2], "o-", ms=3, lw=1.5)
        ax.axhline(-robot.foot_radius, c="0.6", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlabel(label)
        ax.set_ylabel("z [m]")
    axes[0].set_title(f"{ins.file.name}: stance, body {robot.stance_height:.3f} m above the feet")
    ax = axes[2]
    order = [0, 1, 2, 3, 0]
    ax.plot(feet[order, 0], feet[order, 1], "k-", lw=1)
    for leg, f in zip(LEGS, feet, strict=True):
        ax.annotate(leg.value, f[:2], fontsize=8)
    hips = np.array([robot.hip_offset(leg) for leg in LEGS])
    ax.plot(hips[:, 0], hips[:, 1], "s", c="tab:blue", label="hips (ab/ad axes)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("feet from above")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
