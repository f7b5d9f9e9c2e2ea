"""What a MuJoCo biped walk measured (:func:`footfall.sim.biped.walk.walk`): the per-tick
:class:`WalkTrace` the walker fills, the summary :class:`WalkMetrics` and the :class:`WalkResult`
that holds both. Declared once here, below both the simulation and the figures."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray


@dataclass
class WalkTrace:
    """Measurements of one walk, sampled every control tick (T samples); the walker fills it tick
    by tick. Per-tick arrays are NaN where nothing was measured.

    Attributes:
        t: time since the start of the walk, shape (T,) [s].
        phase: single-support phase index per tick, -1 outside single support, shape (T,).
        com: measured CoM, shape (T, 3) [m].
        com_ref: reference CoM sent to the whole-body controller, shape (T, 3) [m].
        zmp_offset: stance-foot CoP relative to the sole centre in the foot frame, shape (T, 2)
            [m] (NaN outside single support or without contact).
        zmp_planned: the ZMP offset of the adjuster's commanded torque, shape (T, 2) [m].
        feet: measured sole centres (left, right), shape (T, 2, 3) [m].
        landed: measured sole centre after each footstep 1..N (and the stopping steps) landed,
            shape (N, 3) [m] (NaN if never reached).
        targets: the commanded (corrected) footsteps 1..N, shape (N, 3) [m].
        planned: the plan's footsteps 1..N, shape (N, 3) [m].
        n_planned: the plan's N; entries beyond it are stopping steps.
        timing: wall-clock seconds per part: ``control`` (measurement, adjuster, references),
            ``ik`` (``servo``) or ``model`` (MuJoCo's model terms, Jacobians and the tasks) and
            ``qp`` (the whole-body QP) for ``wbc``, ``physics``, ``render``, ``total``.
        fell: whether a fall was detected.
        fall_time: when [s] (NaN if none).
        sim_time: simulated time [s].
        controller: the controller's own account (``wbc``: torques, friction and centres of
            pressure against their limits; ``servo``: IK failures).
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
    timing: dict[str, float]
    fell: bool = False
    fall_time: float = math.nan
    sim_time: float = 0.0
    controller: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def empty(cls, n_ticks: int, dt: float, footsteps: FloatArray, n_planned: int) -> WalkTrace:
        """An unmeasured trace of ``n_ticks`` ticks of ``dt`` [s] for a walk over ``footsteps``
        (N + 1, 3) [m] (the plan's, stopping steps included) of which ``n_planned`` are planned."""
        n = footsteps.shape[0] - 1
        return cls(
            t=np.arange(n_ticks, dtype=np.float64) * dt,
            phase=np.full(n_ticks, -1, dtype=int),
            com=np.full((n_ticks, 3), np.nan),
            com_ref=np.full((n_ticks, 3), np.nan),
            zmp_offset=np.full((n_ticks, 2), np.nan),
            zmp_planned=np.full((n_ticks, 2), np.nan),
            feet=np.full((n_ticks, 2, 3), np.nan),
            landed=np.full((n, 3), np.nan),
            targets=np.array(footsteps[1:], dtype=float),
            planned=np.array(footsteps[1:], dtype=float),
            n_planned=n_planned,
            timing={"control": 0.0, "ik": 0.0, "physics": 0.0, "render": 0.0},
        )

    def grown(self, n_ticks: int, dt: float, footsteps: FloatArray) -> WalkTrace:
        """This trace for a walk that got longer: ``n_ticks`` ticks of ``dt`` [s] (at least as
        many as now) over ``footsteps`` (N' + 1, 3) [m], the old ones first (stopping steps were
        appended); what was measured is kept, the rest unmeasured."""
        n_old, n_new = self.t.shape[0], int(n_ticks)
        steps = np.asarray(footsteps, dtype=float)[1:]
        if n_new < n_old or steps.shape[0] < self.landed.shape[0]:
            raise ValueError("a trace only grows")

        def pad(a: NDArray[Any], fill: float) -> NDArray[Any]:
            extra = np.full((n_new - n_old, *a.shape[1:]), fill, dtype=a.dtype)
            return np.concatenate([a, extra])

        k_new = steps.shape[0] - self.landed.shape[0]
        return replace(
            self,
            t=np.arange(n_new, dtype=np.float64) * dt,
            phase=pad(self.phase, -1),
            com=pad(self.com, np.nan),
            com_ref=pad(self.com_ref, np.nan),
            zmp_offset=pad(self.zmp_offset, np.nan),
            zmp_planned=pad(self.zmp_planned, np.nan),
            feet=pad(self.feet, np.nan),
            landed=np.concatenate([self.landed, np.full((k_new, 3), np.nan)]),
            targets=np.concatenate([self.targets, steps[self.targets.shape[0] :]]),
            planned=np.concatenate([self.planned, steps[self.planned.shape[0] :]]),
        )

    def trimmed(self, k_end: int, dt: float) -> WalkTrace:
        """The first ``k_end`` ticks (the walk ended there), with its simulated time."""
        return replace(
            self,
            t=self.t[:k_end],
            phase=self.phase[:k_end],
            com=self.com[:k_end],
            com_ref=self.com_ref[:k_end],
            zmp_offset=self.zmp_offset[:k_end],
            zmp_planned=self.zmp_planned[:k_end],
            feet=self.feet[:k_end],
            sim_time=k_end * dt,
        )


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
        at_edge_share: share of them within ``footfall.sim.biped.metrics.EDGE_TOL`` of the sole's contact
            rectangle's edge
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
        at_edge_share: share of its ticks at the sole's edge (``footfall.sim.biped.metrics.EDGE_TOL``).
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
            ``footfall.sim.biped.metrics.GOAL_TOL`` of the goal.
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
            ``footfall.terrain.terrain.LANDING_Z_TOL``
            (:meth:`~footfall.terrain.terrain.Terrain.region_of`).
        correction_m: horizontal distance of the commanded footsteps from the plan's [m].
        region_changes: planned steps whose commanded footstep lies in another region than the
            plan's (by geometry: ``{"step", "planned", "region"}``, region "" for none).
        region_choices: the region-aware adjuster's last decision per phase
            (:class:`~footfall.control.adjusters.RegionChoice` as dicts; empty otherwise).
        touchdowns_moved: the single supports the MPC's step timing shortened
            (``{"step", "earlier_s"}``: the single support and how much sooner [s] its swing
            foot was to land; empty when none was,
            :attr:`~footfall.control.adjusters.MPCAdjuster.step_timing`).
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
    touchdowns_moved: tuple[dict[str, Any], ...] = ()

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
            "touchdowns_moved": list(self.touchdowns_moved),
        }


@dataclass(frozen=True)
class WalkResult:
    """One simulated walk: what was measured every tick and its summary.

    Attributes:
        trace: the per-tick measurements.
        metrics: the summary (:func:`footfall.sim.biped.metrics.summarise`).
        video: path of the MP4 or None; video_note says why there is none.
    """

    trace: WalkTrace
    metrics: WalkMetrics
    video: Path | None = None
    video_note: str = ""

    @property
    def real_time_factor(self) -> float:
        """Simulated over wall-clock seconds, rendering excluded."""
        timing = self.trace.timing
        return self.trace.sim_time / max(timing["total"] - timing["render"], 1e-9)

    def to_dict(self) -> dict[str, Any]:
        """The walk's part of ``footfall walk``'s walk.json: metrics, timing [s], real-time factor,
        the planned / commanded / landed footsteps (arrays, N x 3 [m]) and the video."""
        tr = self.trace
        return {
            "metrics": self.metrics.to_dict(),
            "timing_s": tr.timing,
            "real_time_factor": self.real_time_factor,
            "footsteps": {
                "planned": tr.planned[: tr.n_planned],
                "commanded": tr.targets,
                "landed": tr.landed,
            },
            "controller": tr.controller,
            "video": str(self.video) if self.video else None,
            "video_note": self.video_note,
        }


def walk_report(
    scene_name: str,
    planner: str,
    robot: str,
    plan: Any,
    disturbance: Any,
    pushes: tuple[Any, ...],
    result: WalkResult,
) -> dict[str, Any]:
    """What a walk's folder holds as ``walk.json`` (``footfall walk``; ``footfall view`` reads
    it): the plan in brief (a :class:`~footfall.planning.plan.FootstepPlan`), the
    :class:`~footfall.sim.disturbance.Disturbance` and the pushes it made, and the walk's
    :meth:`WalkResult.to_dict`."""
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
        "disturbance": disturbance.to_dict(),
        "push": [p.to_dict() for p in pushes],
        **result.to_dict(),
    }
