"""Figure of a simulated biped walk: footsteps, CoM path, measured ZMP offset, CoM height.

The figure reads a :class:`~footfall.results.walk.WalkResult` and the sole through
:class:`SoleLike` (a walker model), so that pictures never import the simulation.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol

from footfall._io import save_figure
from footfall.results.walk import WalkResult
from footfall.terrain.scene import Scene

#: the sole drawn without a model: our biped's (``footfall.sim.biped.model.BipedModel``) [m]
DEFAULT_FOOT_LENGTH, DEFAULT_FOOT_WIDTH = 0.20, 0.10


class SoleLike(Protocol):
    """The sole's size [m] (a walker model)."""

    @property
    def foot_length(self) -> float: ...
    @property
    def foot_width(self) -> float: ...


def plot_walk(
    result: WalkResult, scene: Scene, path: Path, params: SoleLike | None = None, title: str = ""
) -> Path:
    """Write a three-panel PNG: top view, single-support ZMP offset in the foot frame, heights.

    ``params``: the sole drawn in the ZMP panel (None: our biped's).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon, Rectangle

    res = result.trace
    length = params.foot_length if params is not None else DEFAULT_FOOT_LENGTH
    width = params.foot_width if params is not None else DEFAULT_FOOT_WIDTH
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
    ax.add_patch(Rectangle((-length / 2, -width / 2), length, width, fc="none", ec="k"))
    ax.scatter(z[ss, 0], z[ss, 1], s=4, c=res.t[ss], cmap="viridis", label="measured CoP")
    zp = res.zmp_planned
    ax.plot(zp[ss, 0], zp[ss, 1], ".", ms=2, c="tab:red", alpha=0.4, label="commanded")
    ax.set_xlim(-0.15, 0.15)
    ax.set_ylim(-0.1, 0.1)
    ax.set_aspect("equal")
    ax.set_xlabel("x in the foot frame [m]")
    ax.set_ylabel("y [m]")
    m = result.metrics.zmp
    ax.set_title(
        f"single-support ZMP offset: mean {m.mean:.3f} m, max {m.max:.3f} m",
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
    return save_figure(fig, path, dpi=110)
