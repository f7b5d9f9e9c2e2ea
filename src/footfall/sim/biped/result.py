"""What a simulated walk of the MuJoCo biped measured (:func:`footfall.sim.biped.walk.walk`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.planning.plan import FootstepPlan
from footfall.sim.biped.metrics import WalkMetrics
from footfall.sim.pushes import Push


@dataclass(frozen=True)
class WalkResult:
    """Measurements of one simulated walk (arrays sampled every control tick, T samples).

    Attributes:
        t: time since the start of the walk, shape (T,) [s].
        phase: single-support phase index per tick, -1 outside single support, shape (T,).
        com: measured CoM, shape (T, 3) [m].
        com_ref: reference CoM sent to the IK, shape (T, 3) [m].
        zmp_offset: stance-foot CoP relative to the sole centre in the foot frame, shape (T, 2)
            [m] (NaN outside single support or without contact).
        zmp_planned: the ZMP offset of the adjuster's commanded torque, shape (T, 2) [m].
        feet: measured sole centres (left, right), shape (T, 2, 3) [m].
        landed: measured sole centre after each planned footstep 1..N landed, shape (N, 3) [m]
            (NaN if never reached).
        targets: the commanded (corrected) footsteps 1..N, shape (N, 3) [m].
        planned: the plan's footsteps 1..N, shape (N, 3) [m].
        n_planned: the plan's N; entries beyond it are stopping steps.
        fell: whether a fall was detected.
        fall_time: when [s] (NaN if none).
        metrics: summary numbers (:func:`~footfall.sim.biped.metrics.summarise`).
        timing: wall-clock seconds per part: ``control`` (measurement, adjuster, references),
            ``ik`` (``servo``) or ``model`` (MuJoCo's model terms, Jacobians and the tasks) and
            ``qp`` (the whole-body QP) for ``wbc``, ``physics``, ``render``, ``total``.
        sim_time: simulated time [s].
        controller: the controller's own account (``wbc``: :class:`~footfall.sim.biped.wbc.WbcTally`,
            torques, friction and centres of pressure against their limits; ``servo``: IK failures).
        video: path of the MP4 or None; video_note says why there is none.
    """

    t: FloatArray
    phase: NDArray[np.int_]
    com: FloatArray
    com_ref: FloatArray
    zmp_offset: FloatArray
    zmp_planned: FloatArray
    feet: FloatArray
    landed: FloatArray
    targets: FloatArray
    planned: FloatArray
    n_planned: int
    fell: bool
    fall_time: float
    metrics: WalkMetrics
    timing: dict[str, float]
    sim_time: float
    controller: dict[str, Any]
    video: Path | None = None
    video_note: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The walk's part of ``footfall walk``'s walk.json: metrics, timing [s], real-time factor
        (simulated over wall seconds, rendering excluded), the planned / commanded / landed
        footsteps (arrays, N x 3 [m]) and the video."""
        return {
            "metrics": self.metrics.to_dict(),
            "timing_s": self.timing,
            "real_time_factor": self.sim_time
            / max(self.timing["total"] - self.timing["render"], 1e-9),
            "footsteps": {
                "planned": self.planned[: self.n_planned],
                "commanded": self.targets,
                "landed": self.landed,
            },
            "controller": self.controller,
            "video": str(self.video) if self.video else None,
            "video_note": self.video_note,
        }


def walk_report(
    scene_name: str,
    planner: str,
    robot: str,
    plan: FootstepPlan,
    pushes: Sequence[Push],
    result: WalkResult,
) -> dict[str, Any]:
    """What ``footfall walk`` writes to ``walk.json``: the plan in brief, the pushes and the
    walk's :meth:`WalkResult.to_dict`."""
    return {
        "scene": scene_name,
        "planner": planner,
        "robot": robot,
        "plan": {
            "status": plan.status.value,
            "n_steps": plan.n_steps,
            "solve_time_s": plan.solve_time,
            "message": plan.message,
        },
        "push": [
            {"start_s": p.start, "duration_s": p.duration, "force_N": p.force.tolist()}
            for p in pushes
        ],
        **result.to_dict(),
    }
