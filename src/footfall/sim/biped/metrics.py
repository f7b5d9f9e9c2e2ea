"""Summary metrics of a simulated walk of the MuJoCo biped (document 000, section 5.5).

:func:`summarise` turns a walk's measurements into :class:`WalkMetrics`: whether it fell and
reached the goal, where the feet landed against the plan and the commanded footsteps, and the
single-support ZMP offset (the stance-foot CoP from the sole centre, the quantity of the section
5.5 table) measured, commanded and planned. ``WalkMetrics.to_dict()`` is the ``metrics`` object of
``footfall walk``'s walk.json.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
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
#: a landed sole centre is on a region when it is inside its polygon in plan view and within
#: this of its surface height [m] (the measured sole centre sits a few mm above the plane)
ON_REGION_Z_TOL = 0.03


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


@dataclass(frozen=True)
class MeanMax:
    """Mean and max of distances [m] (NaN without samples).

    Attributes:
        mean: mean [m].
        max: largest [m].
    """

    mean: float
    max: float

    @classmethod
    def of(cls, a: FloatArray) -> MeanMax:
        """Mean and max of ``a`` (n,) [m]."""
        return cls(
            mean=float(np.mean(a)) if a.size else math.nan,
            max=float(np.max(a)) if a.size else math.nan,
        )

    def to_dict(self) -> dict[str, float]:
        """``{"mean", "max"}``."""
        return {"mean": self.mean, "max": self.max}


@dataclass(frozen=True)
class ZMPStats:
    """ZMP offsets from the sole centre in the foot frame (NaN without samples).

    Attributes:
        mean: mean norm of the offset [m].
        max: largest norm [m].
        mean_abs_x: mean |x| (along the sole) [m].
        mean_abs_y: mean |y| (across the sole) [m].
    """

    mean: float
    max: float
    mean_abs_x: float
    mean_abs_y: float

    @staticmethod
    def fields_of(a: FloatArray) -> dict[str, float]:
        """The statistics of offsets ``a`` (n, 2) [m] by field name."""
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

    @classmethod
    def of(cls, a: FloatArray) -> ZMPStats:
        """Statistics of offsets ``a`` (n, 2) [m]."""
        return cls(**cls.fields_of(a))

    def to_dict(self) -> dict[str, Any]:
        """``{"mean", "max", "mean_abs_x", "mean_abs_y"}``."""
        return {
            "mean": self.mean,
            "max": self.max,
            "mean_abs_x": self.mean_abs_x,
            "mean_abs_y": self.mean_abs_y,
        }


@dataclass(frozen=True)
class MeasuredZMP(ZMPStats):
    """The measured single-support ZMP offsets: :class:`ZMPStats` plus where on the sole they were.

    Attributes:
        samples: ticks with a measured CoP.
        at_edge_share: share of them within ``EDGE_TOL`` of the sole's contact rectangle's edge
            (the foot starts to tip); None without samples.
        inside_share: share of them inside the sole; None without samples.
    """

    samples: int = 0
    at_edge_share: float | None = None
    inside_share: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """:meth:`ZMPStats.to_dict` plus ``at_edge_share``, ``inside_share`` (when measured) and
        ``samples``."""
        out = super().to_dict()
        if self.at_edge_share is not None:
            out["at_edge_share"] = self.at_edge_share
        if self.inside_share is not None:
            out["inside_share"] = self.inside_share
        out["samples"] = self.samples
        return out


@dataclass(frozen=True)
class StepZMP:
    """Measured ZMP offsets of one single support.

    Attributes:
        phase: single-support phase index i.
        region: the region of its stance footstep.
        mean: mean offset norm [m].
        max: largest offset norm [m].
        at_edge_share: share of its ticks at the sole's edge (``EDGE_TOL``).
    """

    phase: int
    region: str
    mean: float
    max: float
    at_edge_share: float

    def to_dict(self) -> dict[str, Any]:
        """The fields by name."""
        return {
            "phase": self.phase,
            "region": self.region,
            "mean": self.mean,
            "max": self.max,
            "at_edge_share": self.at_edge_share,
        }


@dataclass(frozen=True)
class WalkMetrics:
    """Summary of one walk (:func:`summarise`).

    Attributes:
        fell: whether a fall was detected.
        fall_time_s: when [s]; None without a fall.
        reached_goal: no fall, every planned footstep landed and the final feet midpoint within
            ``GOAL_TOL`` of the goal.
        goal_error_m: plan-view distance of the final feet midpoint from the goal [m].
        time_to_goal_s: when the last planned step ended [s]; None with a fall or a missing
            landing.
        steps_planned: the plan's N.
        stop_steps: stopping steps walked after the plan.
        steps_landed: planned footsteps that landed.
        footstep_error_m: horizontal distance of the landed sole centres from the plan [m].
        footstep_height_error_m: their vertical distance from the plan [m].
        footstep_error_vs_target_m: horizontal distance from the commanded footsteps [m].
        zmp: measured single-support stance-foot CoP offset from the sole centre.
        zmp_commanded: the adjuster's torque as a ZMP offset, before the sole clip.
        zmp_plan: the plan's own torques as ZMP offsets.
        per_step: the measured offsets per single support (those with samples).
        sim_time_s: simulated time [s].
        wall_time_s: wall-clock time of the loop [s].
        footsteps_off_regions: landed footsteps (planned and stopping) whose sole centre is
            outside every region of the scene in plan view or off its surface by more than
            ``ON_REGION_Z_TOL`` (issue 23).
        correction_m: horizontal distance of the commanded footsteps from the plan's [m].
        region_changes: planned steps whose commanded footstep lies in another region than the
            plan's (by geometry: ``{"step", "planned", "region"}``, region "" for none).
        region_choices: the region-aware adjuster's last decision per phase
            (:class:`~footfall.control.adjusters.RegionChoice` as dicts; empty otherwise).
    """

    fell: bool
    fall_time_s: float | None
    reached_goal: bool
    goal_error_m: float
    time_to_goal_s: float | None
    steps_planned: int
    stop_steps: int
    steps_landed: int
    footstep_error_m: MeanMax
    footstep_height_error_m: MeanMax
    footstep_error_vs_target_m: MeanMax
    zmp: MeasuredZMP
    zmp_commanded: ZMPStats
    zmp_plan: ZMPStats
    per_step: tuple[StepZMP, ...]
    sim_time_s: float
    wall_time_s: float
    footsteps_off_regions: int = 0
    correction_m: MeanMax = MeanMax(math.nan, math.nan)
    region_changes: tuple[dict[str, Any], ...] = ()
    region_choices: tuple[dict[str, Any], ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The metrics as JSON-ready nested dicts and lists (walk.json's ``metrics``)."""
        return {
            "fell": self.fell,
            "fall_time_s": self.fall_time_s,
            "reached_goal": self.reached_goal,
            "goal_error_m": self.goal_error_m,
            "time_to_goal_s": self.time_to_goal_s,
            "steps_planned": self.steps_planned,
            "stop_steps": self.stop_steps,
            "steps_landed": self.steps_landed,
            "footstep_error_m": self.footstep_error_m.to_dict(),
            "footstep_height_error_m": self.footstep_height_error_m.to_dict(),
            "footstep_error_vs_target_m": self.footstep_error_vs_target_m.to_dict(),
            "zmp": self.zmp.to_dict(),
            "zmp_commanded": self.zmp_commanded.to_dict(),
            "zmp_plan": self.zmp_plan.to_dict(),
            "per_step": [s.to_dict() for s in self.per_step],
            "sim_time_s": self.sim_time_s,
            "wall_time_s": self.wall_time_s,
            "footsteps_off_regions": self.footsteps_off_regions,
            "correction_m": self.correction_m.to_dict(),
            "region_changes": list(self.region_changes),
            "region_choices": list(self.region_choices),
        }


def _edge_half(params: WalkerModel) -> FloatArray:
    """Half extents (2,) [m] of the sole's contact rectangle (inside the rounded corners)."""
    return np.array(
        [
            params.foot_length / 2 - params.corner_radius,
            params.foot_width / 2 - params.corner_radius,
        ]
    )


def _measured_zmp(res: WalkRecord, params: WalkerModel) -> MeasuredZMP:
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


def _per_step(res: WalkRecord, plan: FootstepPlan, params: WalkerModel) -> tuple[StepZMP, ...]:
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


def region_of(scene: Scene, p: FloatArray) -> str:
    """Name of the region ``p`` (3,) [m] stands on (inside in plan view, within
    ``ON_REGION_Z_TOL`` of its surface), "" for none."""
    for r in scene.terrain.regions:
        if float(r.signed_distance(p[:2])) <= 0.0:
            if abs(float(r.height_at(p[:2])) - float(p[2])) <= ON_REGION_Z_TOL:
                return r.name
    return ""


def _region_metrics(
    res: WalkRecord, scene: Scene, plan: FootstepPlan
) -> tuple[int, MeanMax, tuple[dict[str, Any], ...]]:
    """Footsteps landed off every region, the corrections' sizes and their region changes."""
    n = res.n_planned
    landed = res.landed[~np.isnan(res.landed[:, 0])]
    off = sum(1 for p in landed if not region_of(scene, p))
    corr = MeanMax.of(np.linalg.norm((res.targets[:n] - res.planned[:n])[:, :2], axis=1))
    own = {r.name: r for r in scene.terrain.regions}
    changes = []
    for i in range(n):
        planned = own.get(plan.regions[i + 1])
        if planned is None or float(planned.signed_distance(res.targets[i, :2])) > 0.0:
            name = region_of(scene, res.targets[i])
            changes.append({"step": i + 1, "planned": plan.regions[i + 1], "region": name})
    return off, corr, tuple(changes)


def summarise(
    res: WalkRecord, scene: Scene, plan: FootstepPlan, params: WalkerModel, t_steps_end: float
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
