"""Figures of the document-001 quadruped walk (like the document's figs. 4, 8, 10 and 11).

All functions take plain arrays, the planner's results or a simulated walk's measurements
(:class:`~footfall.results.quadruped.QuadrupedTrace`) and write one PNG each; they use matplotlib's non-interactive Agg backend
(no display needed).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from footfall._io import save_figure
from footfall._typing import FloatArray
from footfall.quadruped.kinematics import body_rotation, foot_in_leg_frame
from footfall.quadruped.robot import LEGS, Leg
from footfall.quadruped.swing import SwingProfile, slope_to_leg_rotation, swing_in_leg_frame
from footfall.results.quadruped import QuadrupedTrace

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from footfall.quadruped.gait import GaitPlan


#: length of the drawn frame axes [m]
_AXIS_LEN = 0.12


def _plt() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _frame(ax: Axes, origin: FloatArray, rot: FloatArray, label: str, color: str) -> None:
    """Draw the x and z axes of a frame in the x-z plane."""
    for col, name in ((0, "x"), (2, "z")):
        d = rot[:, col] * _AXIS_LEN
        ax.annotate(
            "",
            xy=(origin[0] + d[0], origin[2] + d[2]),
            xytext=(origin[0], origin[2]),
            arrowprops={"arrowstyle": "->", "color": color, "lw": 1.4},
        )
        ax.text(origin[0] + 1.1 * d[0], origin[2] + 1.1 * d[2], name, color=color, fontsize=7)
    ax.text(origin[0] - 0.05, origin[2] - 0.05, f"{{{label}}}", color=color, fontsize=9)


def plot_swing_frames(plan: GaitPlan, path: Path, leg: Leg = Leg.LF) -> Path:
    """Fig. 8: swing trajectory of eq. (10)-(13) on the slope with frames {W}, {B}, {leg}, {G}.

    Draws, in the world x-z plane, the slope, the body, the first swing of ``leg`` computed in
    ``{G}`` and rotated into the leg frame by beta_Delta (eq. 13), and the frames.
    """
    from footfall.quadruped.gait import PhaseKind

    plt = _plt()
    robot, post = plan.robot, plan.posture
    ph = next(p for p in plan.phases if p.kind is PhaseKind.SWING and p.leg is leg)
    assert ph.foot_end is not None
    i = leg.idx
    rot_b = body_rotation(post.body_pitch)
    body = ph.body_start
    start, end = ph.feet_start[i], ph.foot_end
    mid = 0.5 * (start + end)
    origin = foot_in_leg_frame(robot, leg, body, post.body_pitch, mid)
    prof = SwingProfile(float(np.linalg.norm(end - start)), plan.params.swing_height, ph.duration)
    t = np.linspace(0.0, ph.duration, 101)
    p_leg = swing_in_leg_frame(prof, t, post.beta_delta, origin)
    hip = body + rot_b @ robot.hip_offset(leg)
    p_w = hip + p_leg @ rot_b.T

    fig, ax = plt.subplots(figsize=(7, 5))
    xs = np.array([body[0] - 1.0, body[0] + 1.2])
    ground = xs * np.tan(post.slope) - robot.foot_radius
    ax.fill_between(
        xs, ground, ground.min() - 0.5, color="0.85", label=f"slope {np.degrees(post.slope):.0f}°"
    )
    corners = np.array(
        [
            [s * robot.body_length / 2, 0.0, z * robot.body_height / 2]
            for s, z in ((1, 1), (1, -1), (-1, -1), (-1, 1), (1, 1))
        ]
    )
    cw = body + corners @ rot_b.T
    ax.plot(cw[:, 0], cw[:, 2], "k-", lw=1.5, label="body")
    for j, lg in enumerate(LEGS):
        if lg.is_left:
            h = body + rot_b @ robot.hip_offset(lg)
            f = ph.feet_start[j]
            ax.plot([h[0], f[0]], [h[2], f[2]], "-", color="0.4", lw=2)
    ax.plot(p_w[:, 0], p_w[:, 2], "r-", lw=2, label=f"{leg.value} swing, eq. (10)-(13)")
    ax.plot([start[0], end[0]], [start[2], end[2]], "ro", ms=4)
    rot_g = rot_b @ slope_to_leg_rotation(post.beta_delta)
    _frame(ax, body, rot_b, "B", "tab:blue")
    w0 = np.array([body[0], 0.0, body[0] * np.tan(post.slope) - robot.foot_radius])
    _frame(ax, w0, np.eye(3), "W", "k")
    _frame(ax, hip, rot_b, leg.value, "tab:green")
    _frame(ax, mid, rot_g, "G", "tab:red")
    ax.set_aspect("equal")
    ax.set_xlabel("x in {W} [m]")
    ax.set_ylabel("z in {W} [m]")
    ax.set_title(
        f"Swing trajectory and frames (fig. 8): S={prof.step:.2f} m, H={prof.height:.2f} m, "
        f"β_S={np.degrees(post.slope):.0f}°, β_B={np.degrees(post.body_pitch):.0f}°",
        fontsize=9,
    )
    ax.set_ylim(w0[2] - 0.3, hip[2] + 0.35)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


def plot_foot_path(
    plan: GaitPlan, res: QuadrupedTrace | None, path: Path, leg: Leg = Leg.LF
) -> Path:
    """Fig. 10: the ``leg`` foot path in the x-z plane of {W}, planned and measured."""
    plt = _plt()
    i = leg.idx
    ref = res.planned if res is not None else plan.sample(0.01, with_zmp=False)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(ref.feet[:, i, 0], ref.feet[:, i, 2], "k--", lw=1, label="planned")
    if res is not None:
        ax.plot(res.feet[:, i, 0], res.feet[:, i, 2], "r-", lw=1.2, label="measured (MuJoCo)")
    ax.set_xlabel("x in {W} [m]")
    ax.set_ylabel("z in {W} [m]")
    ax.set_title(f"{leg.value} foot centre trajectory in {{W}} xoz (fig. 10)", fontsize=10)
    ax.set_aspect("equal")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


def plot_body_height(
    runs: list[tuple[str, FloatArray, FloatArray, FloatArray | None]], path: Path
) -> Path:
    """Fig. 11: body-centre z over time, one line per run.

    Args:
        runs: ``(label, t [s], measured z [m], planned z [m] or None)`` per run.
        path: output PNG.
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for k, (label, t, z, zp) in enumerate(runs):
        style = "-" if k == 0 else "--"
        line = ax.plot(t, z, style, lw=1.3, label=f"{label} measured")[0]
        if zp is not None:
            ax.plot(t, zp, ":", color=line.get_color(), lw=1, label=f"{label} planned")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("body centre z [m]")
    ax.set_title("Body centre z trajectory (fig. 11)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


def plot_stability(plan: GaitPlan, res: QuadrupedTrace | None, path: Path) -> Path:
    """Top view of the first cycle (support triangles, OSPs, ZMP path; like figs. 3-4) and the
    stability margin over time (planned, and measured from the CoP of the contact forces)."""
    from footfall.quadruped.gait import PhaseKind

    plt = _plt()
    ref = res.planned if res is not None else plan.sample(0.01)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1, 1.4]})
    first = [p for p in plan.phases if p.cycle == 0 and p.kind is PhaseKind.SWING]
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, ph in enumerate(first):
        assert ph.leg is not None
        stance = [j for j in range(4) if j != ph.leg.idx]
        tri = ph.feet_start[stance, :2]
        loop = np.vstack([tri, tri[:1]])
        ax0.plot(
            loop[:, 0],
            loop[:, 1],
            "-",
            color=colors[k % len(colors)],
            lw=1,
            label=f"support during {ph.leg.value} swing",
        )
    for ph in plan.shifts():
        if ph.cycle == 0 and ph.zmp_target is not None and not np.isnan(ph.target_margin):
            ax0.plot(*ph.zmp_target, "k*", ms=9)
            circ = plt.Circle(tuple(ph.zmp_target), ph.target_margin, fill=False, ls=":", color="k")
            ax0.add_patch(circ)
    sel = np.array([plan.phases[i].cycle == 0 for i in ref.phase])
    ax0.plot(ref.zmp[sel, 0], ref.zmp[sel, 1], "b-", lw=0.8, label="planned ZMP (eq. 5)")
    if res is not None:
        ax0.plot(res.cop[sel, 0], res.cop[sel, 1], "r-", lw=0.6, alpha=0.7, label="measured CoP")
    for j, lg in enumerate(LEGS):
        f0 = ref.feet[np.flatnonzero(sel)[0], j]
        ax0.text(f0[0], f0[1] + 0.03, lg.value, fontsize=8)
    ax0.set_aspect("equal")
    ax0.set_title(f"cycle 1, strategy {plan.params.strategy.value}: targets ★", fontsize=9)
    ax0.set_xlabel("x [m]")
    ax0.set_ylabel("y [m]")
    ax0.legend(fontsize=6, loc="upper left", bbox_to_anchor=(0.0, -0.18), ncol=2)
    ax1.plot(ref.t, ref.margin, "b-", lw=1, label="planned")
    if res is not None:
        ax1.plot(res.t, res.margin, "r-", lw=0.8, label="measured (CoP vs contact polygon)")
    ax1.axhline(0.0, color="k", lw=0.8)
    ax1.set_xlabel("t [s]")
    ax1.set_ylabel("stability margin S_m [m] (eq. 8)")
    ax1.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


#: the files of :func:`save_walk_figures`
WALK_FIGURES = (
    "fig8_swing_frames.png",
    "fig10_lf_foot_path.png",
    "fig11_body_z.png",
    "stability.png",
)


def save_walk_figures(plan: GaitPlan, res: QuadrupedTrace, out: Path, label: str) -> list[Path]:
    """The figures of one simulated walk in ``out``: swing frames (fig. 8), the LF foot path
    (fig. 10), body height (fig. 11, one run called ``label``) and the stability plot."""
    swing, foot, body, stability = (out / name for name in WALK_FIGURES)
    return [
        plot_swing_frames(plan, swing),
        plot_foot_path(plan, res, foot),
        plot_body_height([(label, res.t, res.trunk_pos[:, 2], res.planned.body_pos[:, 2])], body),
        plot_stability(plan, res, stability),
    ]
