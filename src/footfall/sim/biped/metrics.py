"""Summary metrics of a simulated walk of the MuJoCo biped (document 000, section 5.5)."""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.planning.plan import FootstepPlan
from footfall.sim.biped.model import WalkerModel
from footfall.terrain.scene import Scene

#: the CoP counts as "at the edge" of the sole (the foot starts to tip) within this distance [m]
EDGE_TOL = 0.005
#: the goal is reached when the final feet midpoint is this close to it in plan view [m]
GOAL_TOL = 0.10


class WalkRecord(Protocol):
    """The measurements :func:`summarise` reads (those of
    :class:`~footfall.sim.biped.result.WalkResult`, whose docstring gives shapes and units)."""

    @property
    def phase(self) -> NDArray[np.int_]: ...
    @property
    def zmp_offset(self) -> FloatArray: ...
    @property
    def zmp_planned(self) -> FloatArray: ...
    @property
    def feet(self) -> FloatArray: ...
    @property
    def landed(self) -> FloatArray: ...
    @property
    def targets(self) -> FloatArray: ...
    @property
    def planned(self) -> FloatArray: ...
    @property
    def n_planned(self) -> int: ...
    @property
    def fell(self) -> bool: ...
    @property
    def fall_time(self) -> float: ...
    @property
    def sim_time(self) -> float: ...
    @property
    def timing(self) -> dict[str, float]: ...


def summarise(
    res: WalkRecord, scene: Scene, plan: FootstepPlan, params: WalkerModel, t_steps_end: float
) -> dict[str, Any]:
    """Summary metrics of a walk.

    Keys: ``fell``, ``fall_time_s``, ``reached_goal``, ``goal_error_m``, ``time_to_goal_s`` (when
    the last footstep landed, NaN if it did not), ``steps_planned``, ``steps_landed``,
    ``footstep_error_m`` / ``footstep_error_vs_target_m`` (mean and max horizontal distance of the
    landed sole centres from the plan / from the commanded footsteps), ``zmp`` (single-support
    stance-foot CoP offset from the sole centre: mean and max norm [m], mean |x| and |y|, share of
    ticks at a sole edge, share inside the sole), ``zmp_commanded`` (the adjuster's torque as a
    ZMP, before the sole clip), ``zmp_plan`` (the plan's own torques) and ``per_step`` (per phase: mean and max offset norm, at-edge share).
    """
    n = res.n_planned
    ss = (res.phase >= 0) & (res.phase < n)
    z = res.zmp_offset[ss]
    ok = ~np.isnan(z[:, 0])
    z = z[ok]
    half = np.array(
        [
            params.foot_length / 2 - params.corner_radius,
            params.foot_width / 2 - params.corner_radius,
        ]
    )
    sole_half = np.array([params.foot_length / 2, params.foot_width / 2])

    def stats(a: FloatArray) -> dict[str, float]:
        if a.shape[0] == 0:
            return {
                "mean": math.nan,
                "max": math.nan,
                "mean_abs_x": math.nan,
                "mean_abs_y": math.nan,
            }
        nrm = np.linalg.norm(a, axis=1)
        return {
            "mean": float(np.mean(nrm)),
            "max": float(np.max(nrm)),
            "mean_abs_x": float(np.mean(np.abs(a[:, 0]))),
            "mean_abs_y": float(np.mean(np.abs(a[:, 1]))),
        }

    zs = stats(z)
    if z.shape[0]:
        at_edge = np.any(np.abs(z) >= half - EDGE_TOL, axis=1)
        zs["at_edge_share"] = float(np.mean(at_edge))
        zs["inside_share"] = float(np.mean(np.all(np.abs(z) <= sole_half, axis=1)))
    zs["samples"] = int(z.shape[0])
    zp = res.zmp_planned[ss]
    zp = zp[~np.isnan(zp[:, 0])]
    per_step = []
    for i in range(n):
        sel = (res.phase == i) & ~np.isnan(res.zmp_offset[:, 0])
        a = res.zmp_offset[sel]
        if a.shape[0] == 0:
            continue
        nrm = np.linalg.norm(a, axis=1)
        per_step.append(
            {
                "phase": i,
                "region": plan.regions[i],
                "mean": float(np.mean(nrm)),
                "max": float(np.max(nrm)),
                "at_edge_share": float(np.mean(np.any(np.abs(a) >= half - EDGE_TOL, axis=1))),
            }
        )
    npl = res.n_planned
    landed, planned, targets = res.landed[:npl], res.planned[:npl], res.targets[:npl]
    done = ~np.isnan(landed[:, 0])
    err_plan = np.linalg.norm((landed - planned)[done, :2], axis=1)
    err_tgt = np.linalg.norm((landed - targets)[done, :2], axis=1)
    err_z = np.abs((landed - planned)[done, 2])

    def mm(a: FloatArray) -> dict[str, float]:
        return {
            "mean": float(np.mean(a)) if a.size else math.nan,
            "max": float(np.max(a)) if a.size else math.nan,
        }

    final_mid = 0.5 * (res.feet[-1, 0] + res.feet[-1, 1])
    goal_err = float(np.linalg.norm(final_mid[:2] - scene.goal.position[:2]))
    all_landed = bool(np.all(done))
    reached = (not res.fell) and all_landed and goal_err <= GOAL_TOL
    return {
        "fell": res.fell,
        "fall_time_s": res.fall_time if res.fell else None,
        "reached_goal": reached,
        "goal_error_m": goal_err,
        "time_to_goal_s": t_steps_end if (all_landed and not res.fell) else None,
        "steps_planned": npl,
        "stop_steps": int(res.landed.shape[0] - npl),
        "steps_landed": int(np.sum(done)),
        "footstep_error_m": mm(err_plan),
        "footstep_height_error_m": mm(err_z),
        "footstep_error_vs_target_m": mm(err_tgt),
        "zmp": zs,
        "zmp_commanded": stats(zp),
        "zmp_plan": stats(plan.zmp_offsets()[:n].reshape(-1, 2)),
        "per_step": per_step,
        "sim_time_s": res.sim_time,
        "wall_time_s": res.timing.get("total", math.nan),
    }
