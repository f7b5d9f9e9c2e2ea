"""What a MuJoCo quadruped walk measured (:func:`footfall.sim.quadruped.sim.simulate`, document
001): the per-sample :class:`QuadrupedTrace` the simulation fills, the summary
:class:`QuadrupedMetrics` and the :class:`QuadrupedResult` that holds both. Declared once here,
below both the simulation and the figures."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.quadruped.gait import GaitTrajectory


@dataclass
class QuadrupedTrace:
    """Measurements of one walk, sampled at the control period (T samples); the simulation fills
    it sample by sample.

    Attributes:
        t: time since the gait started, shape (T,) [s].
        trunk_pos: measured trunk centre, shape (T, 3) [m].
        trunk_pitch: measured nose-up pitch, shape (T,) [rad].
        cop: measured centre of pressure on the plane through the contacts, shape (T, 2) [m].
        margin: measured stability margin of the CoP in the measured support polygon, (T,) [m].
        n_contacts: number of feet in contact, shape (T,).
        feet: measured foot centres, shape (T, 4, 3) [m].
        slip_vel: tangential velocity of each foot's material point at its ground contact,
            shape (T, 4, 3) [m/s]. A rolling sphere has none, so this is true sliding, not the
            rolling of the spherical foot. A foot planned in stance but off the ground (it
            bounced, or the ground is lower than planned) slides with its centre: the centre's
            velocity along the ground; a swing foot off the ground has none.
        slip_disp: each foot's sliding displacement over control period ``k`` (from ``t[k]`` to
            ``t[k + 1]``), shape (T, 4, 3) [m]: the same sliding velocity integrated at every
            physics step of the period (left Riemann sum, the physics step as the interval; the
            first term is ``slip_vel[k]`` times the physics step). The per-stance slip sums it: a
            contact that lasts a few physics steps (a foot's release, a bounce) counts for those
            steps, not for a whole control period as one sample of ``slip_vel`` would.
        planned: the commanded references at the same instants: the plan, held on four feet
            from the slip guard's stop on (the plan itself without a stop).
        fallen_at: gait time of the first fall sample [s], NaN without a fall.
        wall_time: wall-clock time of the physics + control loop [s] (video excluded).
        sim_time: simulated time, settling included [s].
        qp_failures: physics steps whose whole-body QP failed (``wbc``; the last torques held).
    """

    t: FloatArray
    trunk_pos: FloatArray
    trunk_pitch: FloatArray
    cop: FloatArray
    margin: FloatArray
    n_contacts: NDArray[np.int_]
    feet: FloatArray
    slip_vel: FloatArray
    slip_disp: FloatArray
    planned: GaitTrajectory
    fallen_at: float = math.nan
    wall_time: float = 0.0
    sim_time: float = 0.0
    qp_failures: int = 0

    @classmethod
    def empty(cls, ref: GaitTrajectory) -> QuadrupedTrace:
        """An unmeasured trace at the sample times of the references ``ref``."""
        n = ref.t.shape[0]
        return cls(
            t=ref.t,
            trunk_pos=np.empty((n, 3)),
            trunk_pitch=np.empty(n),
            cop=np.full((n, 2), np.nan),
            margin=np.full(n, np.nan),
            n_contacts=np.zeros(n, dtype=int),
            feet=np.empty((n, 4, 3)),
            slip_vel=np.zeros((n, 4, 3)),
            slip_disp=np.zeros((n, 4, 3)),
            planned=ref,
        )


@dataclass(frozen=True)
class SlipStop:
    """When and why the slip guard stopped the gait.

    Attributes:
        leg: the foot whose slip crossed the limit (``LEGS`` name).
        time_s: gait time of the sample at which it crossed [s].
        slip_m: that foot's sliding displacement in its current stance then [m].
        hold_time_s: gait time from which the four-foot stance is held (the end of the phase
            the walk was in) [s].
    """

    leg: str
    time_s: float
    slip_m: float
    hold_time_s: float


@dataclass(frozen=True)
class StanceSlip:
    """Sliding of one foot over one planned stance (measured).

    Attributes:
        leg: the foot (``LEGS`` name).
        t_start_s: gait time the stance starts [s].
        t_end_s: gait time it ends (lift-off, or the end of the run) [s].
        slip_m: length of the foot's sliding displacement over the stance [m].
        displacement_m: that displacement in ``{W}`` (x, y, z) [m].
        down_slope_m: its signed part down the slope [m] (negative: up the slope; on level ground
            the part backwards, against the walking direction).
    """

    leg: str
    t_start_s: float
    t_end_s: float
    slip_m: float
    displacement_m: tuple[float, float, float]
    down_slope_m: float


@dataclass(frozen=True)
class BodySway:
    """Body sway per gait cycle, averaged over the cycles (see :func:`body_sway`)."""

    path_per_cycle_m: float
    """Horizontal path length of the body centre per cycle [m]."""
    lateral_path_per_cycle_m: float
    """Lateral (y) path length of the body centre per cycle [m]."""
    excess_path_per_cycle_m: float
    """Path length minus net horizontal displacement per cycle: motion spent swaying [m]."""
    shifts_per_cycle: float
    """Body shifts per gait cycle (the final centring shift excluded)."""


@dataclass(frozen=True)
class QuadrupedMetrics:
    """Summary of one simulated walk; measured in MuJoCo unless the name says ``planned``.

    ``None`` marks a measure with no sample to average (for example no stance sample with three
    loaded feet before a fall).
    """

    slope_deg: float
    """Slope angle beta_S [deg]."""
    body_deg: float
    """Planned body angle beta_B to the horizontal [deg]."""
    strategy: str
    """ZMP placement strategy (:class:`~footfall.quadruped.gait.ZmpStrategy` value)."""
    step_m: float
    """Planned step length S along the slope [m]."""
    swing_height_m: float
    """Planned swing height H normal to the slope [m]."""
    swing_period_s: float
    """Planned swing period T_w [s]."""
    shift_period_s: float
    """Planned duration of each body shift [s]."""
    cycles: int
    """Number of gait cycles."""
    gait_duration_s: float
    """Duration of the gait, settling excluded [s]."""
    distance_up_slope_m: float
    """Trunk displacement along the slope direction [m]."""
    planned_distance_up_slope_m: float
    """Planned body displacement along the slope direction [m]."""
    mean_speed_m_s: float
    """Distance up the slope over gait duration [m/s] (NaN for a zero duration)."""
    fell: bool
    """Whether the trunk touched the ground, tilted too far or dropped too low
    (:data:`footfall.sim.falls.QUADRUPED_FALL`)."""
    fall_time_s: float | None
    """Gait time of the first fall sample [s], None when it did not fall."""
    stability_margin_min_m: float | None
    """Smallest measured stability margin over planned-stance samples with >= 3 contacts [m]."""
    stability_margin_mean_m: float | None
    """Mean measured stability margin over the same samples [m]."""
    stability_margin_min_three_leg_m: float | None
    """Smallest measured margin over samples with exactly three planned contacts [m]."""
    stability_margin_mean_three_leg_m: float | None
    """Mean measured margin over samples with exactly three planned contacts [m]."""
    planned_margin_min_m: float
    """Smallest planned stability margin [m]."""
    planned_margin_min_three_leg_m: float
    """Smallest planned margin with exactly three planned contacts [m] (NaN without such a
    sample: the slip guard stopped the gait before the first swing)."""
    stance_samples: int
    """Number of samples where the plan has three or more feet down."""
    stance_samples_with_fewer_than_3_contacts: int
    """Planned-stance samples with fewer than three loaded feet measured."""
    zmp_error_mean_m: float | None
    """Mean distance of the measured CoP from the planned ZMP (eq. 5) [m]."""
    zmp_error_max_m: float | None
    """Largest distance of the measured CoP from the planned ZMP [m]."""
    foot_slip_max_m: float
    """Largest sliding displacement of a foot over one planned stance [m]."""
    foot_slip_mean_m: float
    """Mean sliding displacement of a foot over one planned stance [m]."""
    foot_backward_slip_total_m: float
    """Total sliding of the feet down the slope, summed over stances [m]."""
    stance_slips: tuple[StanceSlip, ...]
    """Sliding of every foot over each of its planned stances, ordered by start time."""
    trunk_drift_from_plan_m: float
    """Distance of the final trunk position from the planned final body position [m]."""
    body_sway_measured: BodySway
    """Sway of the measured trunk."""
    body_sway_planned: BodySway
    """Sway of the planned body."""
    sim_time_s: float
    """Simulated time, settling included [s]."""
    wall_time_s: float
    """Wall-clock time of the physics and control loop, video excluded [s]."""
    realtime_factor: float
    """Simulated seconds per wall-clock second."""
    video: str | None
    """Path of the MP4, None when no video was written."""
    video_note: str
    """Why there is no video, if there is none."""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with one key per field (the sways as nested dicts)."""
        return asdict(self)


@dataclass(frozen=True)
class QuadrupedResult:
    """One simulated quadruped walk: the per-sample measurements and their summary.

    Attributes:
        trace: the measurements.
        metrics: the summary (:func:`footfall.sim.quadruped.sim.summarise`).
        controller: ``servo`` or ``wbc``.
        slip_stop: when and why the slip guard stopped the gait, None when it did not.
        video: path of the MP4, or None; video_note says why there is none.
    """

    trace: QuadrupedTrace
    metrics: QuadrupedMetrics
    controller: str = "servo"
    slip_stop: SlipStop | None = None
    video: Path | None = None
    video_note: str = ""
