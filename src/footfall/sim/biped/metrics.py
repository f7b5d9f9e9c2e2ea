"""Summary metrics of a simulated walk of the MuJoCo biped (document 000, section 5.5).

:func:`summarise` turns a walk's measurements into :class:`WalkMetrics`: whether it fell and
reached the goal, where the feet landed against the plan and the commanded footsteps, and the
single-support ZMP offset (the stance-foot CoP from the sole centre, the quantity of the section
5.5 table) measured, commanded and planned. ``WalkMetrics.to_dict()`` is the ``metrics`` object of
``footfall walk``'s walk.json.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.planning.plan import FootstepPlan
from footfall.results.walk import (
    MeanMax,
    MeasuredZMP,
    StepZMP,
    WalkMetrics,
    WalkTrace,
    ZMPStats,
)
from footfall.sim.biped.model import WalkerModel
from footfall.terrain.scene import Scene

#: the CoP counts as "at the edge" of the sole (the foot starts to tip) within this distance [m]
EDGE_TOL = 0.005
#: the goal is reached when the final feet midpoint is this close to it in plan view [m]
GOAL_TOL = 0.10


def _edge_half(params: WalkerModel) -> FloatArray:
    """Half extents (2,) [m] of the sole's contact rectangle (inside the rounded corners)."""
    return np.array(
        [
            params.foot_length / 2 - params.corner_radius,
            params.foot_width / 2 - params.corner_radius,
        ]
    )


def _measured_zmp(res: WalkTrace, params: WalkerModel) -> MeasuredZMP:
    """Statistics of the measured single-support ZMP offsets of the planned steps."""
    n = res.n_planned
    ss = (res.phase >= 0) & (res.phase < n)
    z = res.zmp_offset[ss]
    z = z[~np.isnan(z[:, 0])]
    if not z.shape[0]:
        return MeasuredZMP(**ZMPStats.fields_of(z), samples=0)
    sole_half = np.array([params.foot_length / 2, params.foot_width / 2])
    at_edge = np.any(np.abs(z) >= _edge_half(params) - EDGE_TOL, axis=1)
    return MeasuredZMP(
        **ZMPStats.fields_of(z),
        samples=int(z.shape[0]),
        at_edge_share=float(np.mean(at_edge)),
        inside_share=float(np.mean(np.all(np.abs(z) <= sole_half, axis=1))),
    )


def _per_step(res: WalkTrace, plan: FootstepPlan, params: WalkerModel) -> tuple[StepZMP, ...]:
    """Measured ZMP offsets per planned single support (those with samples)."""
    half = _edge_half(params)
    out = []
    for i in range(res.n_planned):
        sel = (res.phase == i) & ~np.isnan(res.zmp_offset[:, 0])
        a = res.zmp_offset[sel]
        if a.shape[0] == 0:
            continue
        nrm = np.linalg.norm(a, axis=1)
        out.append(
            StepZMP(
                phase=i,
                region=plan.regions[i],
                mean=float(np.mean(nrm)),
                max=float(np.max(nrm)),
                at_edge_share=float(np.mean(np.any(np.abs(a) >= half - EDGE_TOL, axis=1))),
            )
        )
    return tuple(out)


def _region_metrics(
    res: WalkTrace, scene: Scene, plan: FootstepPlan
) -> tuple[int, MeanMax, tuple[dict[str, Any], ...]]:
    """Footsteps landed off every region, the corrections' sizes and their region changes."""
    n = res.n_planned
    landed = res.landed[~np.isnan(res.landed[:, 0])]
    off = sum(1 for p in landed if not scene.terrain.region_of(p))
    corr = MeanMax.of(np.linalg.norm((res.targets[:n] - res.planned[:n])[:, :2], axis=1))
    own = {r.name: r for r in scene.terrain.regions}
    changes = []
    for i in range(n):
        planned = own.get(plan.regions[i + 1])
        if planned is None or float(planned.signed_distance(res.targets[i, :2])) > 0.0:
            name = scene.terrain.region_of(res.targets[i])
            changes.append({"step": i + 1, "planned": plan.regions[i + 1], "region": name})
    return off, corr, tuple(changes)


def summarise(
    res: WalkTrace, scene: Scene, plan: FootstepPlan, params: WalkerModel, t_steps_end: float
) -> WalkMetrics:
    """Summary metrics of a walk (see :class:`WalkMetrics`) of the (extended) ``plan`` over
    ``scene`` by the robot ``params``; ``t_steps_end`` [s] is when its last planned step ends."""
    n = res.n_planned
    ss = (res.phase >= 0) & (res.phase < n)
    zp = res.zmp_planned[ss]
    zp = zp[~np.isnan(zp[:, 0])]
    landed, planned, targets = res.landed[:n], res.planned[:n], res.targets[:n]
    done = ~np.isnan(landed[:, 0])
    final_mid = 0.5 * (res.feet[-1, 0] + res.feet[-1, 1])
    goal_err = float(np.linalg.norm(final_mid[:2] - scene.goal.position[:2]))
    all_landed = bool(np.all(done))
    off, corr, changes = _region_metrics(res, scene, plan)
    return WalkMetrics(
        fell=res.fell,
        fall_time_s=res.fall_time if res.fell else None,
        reached_goal=(not res.fell) and all_landed and goal_err <= GOAL_TOL,
        goal_error_m=goal_err,
        time_to_goal_s=t_steps_end if (all_landed and not res.fell) else None,
        steps_planned=n,
        stop_steps=int(res.landed.shape[0] - n),
        steps_landed=int(np.sum(done)),
        footstep_error_m=MeanMax.of(np.linalg.norm((landed - planned)[done, :2], axis=1)),
        footstep_height_error_m=MeanMax.of(np.abs((landed - planned)[done, 2])),
        footstep_error_vs_target_m=MeanMax.of(np.linalg.norm((landed - targets)[done, :2], axis=1)),
        zmp=_measured_zmp(res, params),
        zmp_commanded=ZMPStats.of(zp),
        zmp_plan=ZMPStats.of(plan.zmp_offsets()[:n].reshape(-1, 2)),
        per_step=_per_step(res, plan, params),
        sim_time_s=res.sim_time,
        wall_time_s=res.timing.get("total", math.nan),
        footsteps_off_regions=off,
        correction_m=corr,
        region_changes=changes,
    )
