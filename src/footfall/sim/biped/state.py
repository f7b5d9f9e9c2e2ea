"""State the MuJoCo biped's walking loop carries from one control tick to the next.

:class:`~footfall.sim.biped.walk.BipedWalk` keeps each concern in one small object: where the feet
are (:class:`FeetState`), the current single support and its swing path (:class:`SwingState`),
the ALIP reference (:class:`ReferenceState`, eq. 5.1, 5.5, 5.8-5.10), the actuators' modes and
last set points (:class:`ActuationState`), and the measurements (:class:`WalkLog`). Per tick,
:class:`Observation` is what the robot measured and :class:`Command` what the schedule asks of the
whole body. :class:`Video` writes the frames.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._io import PendingFile
from footfall._typing import FloatArray
from footfall.models.biped import Side
from footfall.planning.plan import FootstepPlan
from footfall.sim.biped import names as nm
from footfall.sim.biped.references import SWING_SHARES

#: video frame rate [1/s]
VIDEO_FPS = 30

#: sole targets of the IK: position (3,) [m] and rotation (3, 3) per side
SolePoses = dict[Side, tuple[FloatArray, FloatArray]]


@dataclass
class FeetState:
    """Where each foot is (sole centre (3,) [m], measured at its last touchdown) and its sole
    rotation (3, 3) (the planned one, on its region's plane at its heading)."""

    pos: dict[Side, FloatArray]
    rot: dict[Side, FloatArray]


@dataclass
class SwingState:
    """The current single support: its phase index (-1 before the first), the stance side, and the
    swing sole's path: start pose, apex height [m] and the rise / descend shares of T_ss
    (:func:`~footfall.sim.biped.references.swing_reference`)."""

    stance: Side
    start: FloatArray
    rot0: FloatArray
    phase: int = -1
    apex: float = 0.0
    rise: float = SWING_SHARES[0]
    descend: float = 1.0 - SWING_SHARES[0]
    #: the target (3,) [m] the apex was set for
    apex_for: FloatArray = field(default_factory=lambda: np.zeros(3))


@dataclass
class ReferenceState:
    """The ALIP reference.

    Attributes:
        x: ALIP state (4,) relative to the current stance contact point (eq. 5.1).
        prev_stance: the stance sole centre (3,) [m] of the last single support.
        ds_aug: double-support state ``[x (4); d (3); w (3)]`` (eq. 5.8-5.10,
            :func:`~footfall.sim.biped.references.ds_propagator`).
        stop_from: measured CoM (2,) [m] when the stop begins.
        stop_vel: measured CoM velocity (2,) [m/s] when the stop begins.
    """

    prev_stance: FloatArray
    x: FloatArray = field(default_factory=lambda: np.zeros(4))
    ds_aug: FloatArray = field(default_factory=lambda: np.zeros(10))
    stop_from: FloatArray = field(default_factory=lambda: np.zeros(2))
    stop_vel: FloatArray = field(default_factory=lambda: np.zeros(2))


@dataclass
class ActuationState:
    """Actuators between ticks.

    Attributes:
        ankle_mode: per side, whether its ankle is torque-driven.
        ctrl_prev: last tick's actuator commands (12,) (set points [rad] or torques [N m]).
        pos_prev: which actuators were position servoed last tick (12,).
        ankle_u: the adjuster's ALIP ankle torque (2,) [N m] of the last single-support tick.
        landed_in: the single support in which the swing sole touched down early (-1: none).
    """

    ankle_mode: dict[Side, bool]
    ctrl_prev: FloatArray
    pos_prev: NDArray[np.bool_]
    ankle_u: FloatArray = field(default_factory=lambda: np.zeros(2))
    landed_in: int = -1


@dataclass(frozen=True)
class Observation:
    """What the robot measured at the start of a tick: CoM (3,) [m], its velocity (3,) [m/s], the
    angular momentum about it (3,), each foot's contact points and forces, a body-hit flag."""

    com: FloatArray
    vel: FloatArray
    l_g: FloatArray
    contacts: dict[Side, tuple[FloatArray, FloatArray]]
    body_hit: bool


@dataclass
class Command:
    """What the schedule asks of the whole body this tick.

    Attributes:
        com_ref: reference CoM (3,) [m].
        feet: sole targets per side.
        yaw: torso yaw [rad].
        walking: inside the stepping window (after the shift, before the stop).
        phase: the step index i while walking (-1 otherwise).
        tp: time since the start of step i [s] while walking.
        single: in single support (``walking`` and ``tp < T_ss``).
    """

    com_ref: FloatArray
    feet: SolePoses
    yaw: float
    walking: bool = False
    phase: int = -1
    tp: float = 0.0
    single: bool = False


@dataclass
class WalkLog:
    """Measurements of the walk, named as :class:`~footfall.sim.biped.result.WalkResult`'s fields
    (whose docstring gives shapes and units); per tick arrays are NaN where not measured."""

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
    def empty(cls, n_ticks: int, dt: float, plan: FootstepPlan, n_planned: int) -> WalkLog:
        """An unmeasured log of ``n_ticks`` ticks of ``dt`` [s] for the (extended) ``plan``."""
        n = plan.n_steps
        return cls(
            t=np.arange(n_ticks, dtype=np.float64) * dt,
            phase=np.full(n_ticks, -1, dtype=int),
            com=np.full((n_ticks, 3), np.nan),
            com_ref=np.full((n_ticks, 3), np.nan),
            zmp_offset=np.full((n_ticks, 2), np.nan),
            zmp_planned=np.full((n_ticks, 2), np.nan),
            feet=np.full((n_ticks, 2, 3), np.nan),
            landed=np.full((n, 3), np.nan),
            targets=np.array(plan.footsteps[1:], dtype=float),
            planned=np.array(plan.footsteps[1:]),
            n_planned=n_planned,
            timing={"control": 0.0, "ik": 0.0, "physics": 0.0, "render": 0.0},
        )

    def trimmed(self, k_end: int, dt: float) -> WalkLog:
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


class Video:
    """MP4 of the walk from the tracking camera (offscreen GL), one frame every ``1 / VIDEO_FPS``.

    Without GL there is no video and :attr:`note` says why; the walk goes on.
    """

    def __init__(
        self, mujoco: Any, model: Any, path: Path | None, size: tuple[int, int], dt: float
    ) -> None:
        self.renderer: Any = None
        self.writer: Any = None
        self.file: PendingFile | None = None
        self.note = ""
        self.frame_every = max(1, round(1.0 / (VIDEO_FPS * dt)))
        if path is None:
            return
        try:
            self.renderer = mujoco.Renderer(model, height=size[1], width=size[0])
        except Exception as exc:  # any GL failure means "no video", never a crash
            self.note = f"no offscreen GL ({type(exc).__name__}: {exc}); video skipped"
            return
        import imageio.v2 as imageio

        # written beside the destination and renamed over it when complete (close)
        self.file = PendingFile(path)
        self.writer = imageio.get_writer(str(self.file.tmp), fps=VIDEO_FPS, macro_block_size=8)

    def frame(self, k: int, data: Any) -> bool:
        """Render tick ``k`` if a frame is due; whether one was."""
        if self.writer is None or k % self.frame_every != 0:
            return False
        self.renderer.update_scene(data, camera=nm.TRACK_CAMERA)
        self.writer.append_data(self.renderer.render())
        return True

    def close(self, complete: bool = True) -> None:
        """Finish the file (put in place when ``complete``; removed, the previous video left,
        when the walk was interrupted) and free the renderer."""
        if self.writer is not None:
            self.writer.close()
            assert self.file is not None
            self.file.finish(complete)
        if self.renderer is not None:
            self.renderer.close()
