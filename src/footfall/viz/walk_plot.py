"""Figure of a simulated biped walk: footsteps, CoM path, measured ZMP offset, CoM height."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from footfall.sim.biped.model import BipedModel
from footfall.sim.biped.result import WalkResult
from footfall.terrain.scene import Scene


def plot_walk(
    res: WalkResult, scene: Scene, path: Path, params: BipedModel | None = None, title: str = ""
) -> Path:
    """Write a three-panel PNG: top view, single-support ZMP offset in the foot frame, heights."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon, Rectangle

    p = params if params is not None else BipedModel()
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    ax = axes[0]
    for r in scene.terrain.regions:
        ax.add_patch(Polygon(r.vertices, closed=True, fc="0.85", ec="0.5", lw=0.8))
    ax.plot(res.com[:, 0], res.com[:, 1], "k-", lw=1, label="CoM (measured)")
    npl = res.n_planned
    ax.plot(
        res.planned[:npl, 0], res.planned[:npl, 1], "o", mfc="none", mec="tab:blue", label="plan"
    )
    ax.plot(res.targets[:, 0], res.targets[:, 1], "x", c="tab:orange", label="commanded")
    ax.plot(res.landed[:, 0], res.landed[:, 1], ".", c="tab:red", label="landed")
    ax.plot(*scene.goal.position[:2], "*", c="tab:green", ms=12, label="goal")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title or "footsteps and CoM")
    ax.legend(fontsize=7, loc="upper left")

    ax = axes[1]
    ss = res.phase >= 0
    z = res.zmp_offset
    ax.add_patch(
        Rectangle(
            (-p.foot_length / 2, -p.foot_width / 2), p.foot_length, p.foot_width, fc="none", ec="k"
        )
    )
    ax.scatter(z[ss, 0], z[ss, 1], s=4, c=res.t[ss], cmap="viridis", label="measured CoP")
    zp = res.zmp_planned
    ax.plot(zp[ss, 0], zp[ss, 1], ".", ms=2, c="tab:red", alpha=0.4, label="commanded")
    ax.set_xlim(-0.15, 0.15)
    ax.set_ylim(-0.1, 0.1)
    ax.set_aspect("equal")
    ax.set_xlabel("x in the foot frame [m]")
    ax.set_ylabel("y [m]")
    m = res.metrics.get("zmp", {})
    ax.set_title(
        f"single-support ZMP offset: mean {m.get('mean', np.nan):.3f} m, "
        f"max {m.get('max', np.nan):.3f} m",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="upper left")

    ax = axes[2]
    ax.plot(res.t, res.com[:, 2], "k-", lw=1, label="CoM z")
    ax.plot(res.t, res.com_ref[:, 2], "k--", lw=0.8, label="CoM z reference")
    ax.plot(res.t, res.feet[:, 0, 2], c="tab:blue", lw=0.8, label="left sole z")
    ax.plot(res.t, res.feet[:, 1, 2], c="tab:red", lw=0.8, label="right sole z")
    if res.fell:
        ax.axvline(res.fall_time, c="r", ls=":", label="fall")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("height [m]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
