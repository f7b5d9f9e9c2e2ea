"""Disturbances: one type for every plant, command and study.

- :class:`Push` is what a plant applies: a constant horizontal force pulse on the body (start,
  duration, force). The reduced-order plant applies it at the CoM (its horizontal part changes the
  angular momentum about the contact point like the torque ``z_H (-F_y, F_x)``); the MuJoCo
  plants apply it to the torso or trunk.
- :class:`Disturbance` is what a trial asks for, as configuration: a push given as an impulse
  [N s], or as a velocity change [m/s] (impulse = robot mass x velocity change), a direction in
  the world frame or relative to the walk at the push (``frame``), and a time given as the
  single support it comes in (a step index, or a fraction of the plan's footsteps) and the
  phase of that single support; plus an optional
  initial perturbation while the robot still stands on both feet.
- :meth:`Disturbance.of_seed` is the one seeded sampler: which step, which phase, which
  direction. For a given seed every planner, step count, plant and command gets the same draw
  (common random numbers); only the magnitude varies between push levels.
- :class:`SupportTimeline` says when each single support of a walk starts and how long it lasts
  (and, for a biped, which foot it stands on at which heading); each plant gives its own
  (:meth:`footfall.sim.trial.Plant.timeline`), and
  :meth:`Disturbance.pushes` turns the disturbance into the plant's :class:`Push` pulses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import finite, finite_vector, non_negative, positive
from footfall.errors import InputError

#: the seed of the disturbance generator is ``[seed, DISTURBANCE_STREAM]``
DISTURBANCE_STREAM = 55_000
#: a seeded push comes in the single support of the step at this fraction of the plan's N ...
PUSH_STEP_WINDOW = (0.3, 0.7)
#: ... at this fraction of that single support
PUSH_PHASE_WINDOW = (0.2, 0.6)
#: length of a push pulse unless told otherwise [s]
PUSH_DURATION = 0.1
#: the initial perturbation ends this many push durations before the first single support
INITIAL_LEAD = 1.5
#: frames of a push direction: ``world`` (0 = +x) or ``walk`` (0 = forward along the stance
#: foot's heading, pi / 2 = inward toward the stance foot's side, see :class:`Disturbance`)
FRAMES = ("world", "walk")
#: the sides a stance foot may have on a :class:`SupportTimeline`
SIDES = ("left", "right")


@dataclass(frozen=True)
class Push:
    """A constant force pulse on the robot.

    Attributes:
        start: start time since the beginning of the walk [s], >= 0.
        duration: pulse length [s], > 0.
        force: world-frame force (3,) [N] during the pulse (read-only).
    """

    start: float
    duration: float
    force: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", non_negative("push.start", self.start))
        object.__setattr__(self, "duration", positive("push.duration", self.duration))
        f = finite_vector("push.force", self.force, 3)
        f.setflags(write=False)
        object.__setattr__(self, "force", f)

    @classmethod
    def horizontal(
        cls, start: float, impulse: float, direction: float = 0.0, duration: float = PUSH_DURATION
    ) -> Push:
        """A horizontal push of ``impulse`` [N s] (>= 0) over ``duration`` [s], in the world
        direction ``direction`` [rad] (0 = +x): force ``impulse / duration`` along it."""
        impulse = non_negative("push.impulse", impulse)
        direction = finite("push.direction", direction)
        duration = positive("push.duration", duration)
        f = impulse / duration
        return cls(
            start, duration, np.array([f * math.cos(direction), f * math.sin(direction), 0.0])
        )

    @property
    def impulse(self) -> float:
        """Magnitude of the horizontal impulse [N s]."""
        return float(np.hypot(self.force[0], self.force[1])) * self.duration

    @property
    def direction(self) -> float:
        """Direction of the horizontal force in the world frame [rad] (0 = +x)."""
        return float(math.atan2(self.force[1], self.force[0]))

    @property
    def end(self) -> float:
        """End time [s]."""
        return self.start + self.duration

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data: start and duration [s], force [N], impulse [N s], direction [rad]."""
        return {
            "start_s": self.start,
            "duration_s": self.duration,
            "force_N": self.force.tolist(),
            "impulse_Ns": self.impulse,
            "direction_rad": self.direction,
        }

    def active(self, t: float) -> bool:
        """Whether the push acts at time ``t`` [s]."""
        return self.start <= t < self.start + self.duration


def push_force(pushes: tuple[Push, ...], t: float) -> FloatArray:
    """Sum of the forces (3,) [N] of the ``pushes`` active at ``t`` [s]."""
    force = np.zeros(3)
    for p in pushes:
        if p.active(t):
            force += p.force
    return force


@dataclass(frozen=True)
class SupportTimeline:
    """When the single supports of a walk happen, on the plant's clock.

    Attributes:
        walk_start: when the first single support starts [s] (before it the robot stands).
        starts: start of each single support, shape (N,) [s].
        durations: length of each single support, shape (N,) [s].
        headings: heading [rad] of the stance foot of each single support, shape (N,); empty
            when the plant has no such feet (a push in the ``walk`` frame needs them).
        sides: the stance foot (``left`` or ``right``) of each single support, length N; empty
            with ``headings``.
    """

    walk_start: float
    starts: tuple[float, ...]
    durations: tuple[float, ...]
    headings: tuple[float, ...] = ()
    sides: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        n = len(self.starts)
        if len(self.durations) != n:
            raise InputError("timeline.durations", len(self.durations), f"{n} single supports")
        if len(self.headings) != len(self.sides) or len(self.headings) not in (0, n):
            raise InputError(
                "timeline.headings", len(self.headings), f"0 or {n}, as many as timeline.sides"
            )
        object.__setattr__(
            self, "headings", tuple(finite("timeline.headings", h) for h in self.headings)
        )
        sides = tuple(str(getattr(s, "value", s)) for s in self.sides)
        for s in sides:
            if s not in SIDES:
                raise InputError("timeline.sides", s, f"one of {', '.join(SIDES)}")
        object.__setattr__(self, "sides", sides)

    @classmethod
    def periodic(
        cls,
        walk_start: float,
        n_steps: int,
        t_ss: float,
        t_ds: float,
        headings: Sequence[float] | FloatArray = (),
        sides: Sequence[str] = (),
    ) -> SupportTimeline:
        """N single supports of ``t_ss`` [s], one every ``t_ss + t_ds`` [s] from ``walk_start``,
        standing on feet of ``sides`` at ``headings`` [rad] (the first N of a longer sequence:
        a footstep plan's N + 1 footsteps; empty: unknown)."""
        period = t_ss + t_ds
        return cls(
            walk_start,
            tuple(walk_start + i * period for i in range(n_steps)),
            (t_ss,) * n_steps,
            tuple(float(h) for h in headings[:n_steps]),
            tuple(sides[:n_steps]),
        )

    @property
    def n_steps(self) -> int:
        """Number of single supports N."""
        return len(self.starts)


@dataclass(frozen=True)
class Disturbance:
    """What a trial does to a walk: one push (and an optional initial perturbation).

    Attributes:
        impulse: push impulse [N s] (0: no push); with ``dv`` it must be 0.
        dv: the push as a velocity change [m/s] instead: impulse = robot mass x ``dv``.
        direction: push direction [rad] in ``frame``.
        step: the single support the push comes in (0-based); None: ``step_fraction`` of N.
        step_fraction: with ``step`` None, the step ``floor(f N)`` (at most N - 1), f in [0, 1).
        phase: when in that single support, as a share of it in [0, 1].
        duration: push length [s].
        initial_impulse: impulse of the initial perturbation [N s] (0: none): a push of
            ``duration`` ending ``INITIAL_LEAD`` durations before the first single support
            (starting at 0 at the latest).
        initial_direction: its direction in the world frame [rad].
        seed: the seed this disturbance was drawn from (None: given by hand).
        frame: the frame of ``direction``: ``world`` (0 = +x, pi / 2 = +y), or ``walk``, relative
            to the stance foot of the pushed single support: 0 = forward along its heading,
            pi / 2 = inward (toward the stance foot's side), -pi / 2 = outward (toward the swing
            foot's side), pi = backward. A left stance turns the direction to the world as
            ``heading + direction``, a right stance mirrors it: ``heading - direction``. The
            initial perturbation's direction is always in the world frame.
    """

    impulse: float = 0.0
    dv: float | None = None
    direction: float = 0.0
    step: int | None = None
    step_fraction: float = 0.5
    phase: float = 0.5
    duration: float = PUSH_DURATION
    initial_impulse: float = 0.0
    initial_direction: float = 0.0
    seed: int | None = None
    frame: str = "world"

    def __post_init__(self) -> None:
        if self.frame not in FRAMES:
            raise InputError("push frame", self.frame, f"one of {', '.join(FRAMES)}")
        object.__setattr__(self, "impulse", non_negative("push impulse [N s]", self.impulse))
        if self.dv is not None:
            object.__setattr__(self, "dv", non_negative("push velocity change [m/s]", self.dv))
            if self.impulse != 0.0:
                raise InputError(
                    "push impulse [N s]", self.impulse, "0 when the push is a velocity change"
                )
        for name in ("direction", "initial_direction"):
            object.__setattr__(self, name, finite(f"push {name} [rad]", getattr(self, name)))
        if self.step is not None:
            object.__setattr__(self, "step", _index("push step", self.step))
        f = non_negative("push step fraction", self.step_fraction)
        if f >= 1.0:
            raise InputError("push step fraction", self.step_fraction, "a share in [0, 1)")
        object.__setattr__(self, "step_fraction", f)
        ph = non_negative("push phase", self.phase)
        if ph > 1.0:
            raise InputError("push phase", self.phase, "a share of the single support in [0, 1]")
        object.__setattr__(self, "phase", ph)
        object.__setattr__(self, "duration", positive("push duration [s]", self.duration))
        object.__setattr__(
            self, "initial_impulse", non_negative("initial impulse [N s]", self.initial_impulse)
        )
        if self.seed is not None:
            object.__setattr__(self, "seed", _index("seed", self.seed))

    @classmethod
    def of_seed(
        cls,
        seed: int,
        impulse: float = 0.0,
        dv: float | None = None,
        duration: float = PUSH_DURATION,
        initial_impulse: float = 0.0,
    ) -> Disturbance:
        """The disturbance of trial ``seed``: step fraction in ``PUSH_STEP_WINDOW``, phase in
        ``PUSH_PHASE_WINDOW``, push and initial directions uniform, drawn from the seed alone."""
        seed = _index("seed", seed)
        rng = np.random.default_rng([seed, DISTURBANCE_STREAM])
        f, ph, a, b = (
            rng.uniform(*PUSH_STEP_WINDOW),
            rng.uniform(*PUSH_PHASE_WINDOW),
            rng.uniform(0.0, 2.0 * math.pi),
            rng.uniform(0.0, 2.0 * math.pi),
        )
        return cls(
            impulse=impulse,
            dv=dv,
            direction=float(a),
            step_fraction=float(f),
            phase=float(ph),
            duration=duration,
            initial_impulse=initial_impulse,
            initial_direction=float(b),
            seed=seed,
        )

    def push_step(self, n_steps: int) -> int:
        """The single support (0-based) of a walk of ``n_steps`` steps that is pushed."""
        if n_steps < 1:
            raise InputError(
                "plan", n_steps, "single supports to push (a plan without a solution has none)"
            )
        if self.step is not None:
            if self.step >= n_steps:
                raise InputError("push step", self.step, f"a step of the walk, 0..{n_steps - 1}")
            return self.step
        return min(n_steps - 1, int(self.step_fraction * n_steps))

    def impulse_for(self, mass: float) -> float:
        """The push impulse [N s] for a robot of ``mass`` [kg]."""
        return self.impulse if self.dv is None else positive("robot mass [kg]", mass) * self.dv

    def push_time(self, timeline: SupportTimeline) -> float:
        """When the push starts on ``timeline`` [s]."""
        step = self.push_step(timeline.n_steps)
        return timeline.starts[step] + self.phase * timeline.durations[step]

    def world_direction(self, timeline: SupportTimeline) -> float:
        """The push direction in the world frame [rad] on ``timeline`` (``direction`` itself in
        the ``world`` frame; in the ``walk`` frame from the pushed single support's stance foot).

        Raises:
            InputError: a ``walk`` push on a timeline without stance feet (a quadruped's).
        """
        if self.frame == "world":
            return self.direction
        if not timeline.headings:
            raise InputError(
                "push frame", self.frame, "world on a plant without stance feet of a biped"
            )
        step = self.push_step(timeline.n_steps)
        sign = 1.0 if timeline.sides[step] == "left" else -1.0
        return timeline.headings[step] + sign * self.direction

    def pushes(self, timeline: SupportTimeline, mass: float) -> tuple[Push, ...]:
        """The pulses of this disturbance on a walk with ``timeline`` by a robot of ``mass``
        [kg]: the initial perturbation (if any), then the push (if its impulse is > 0)."""
        out = []
        if self.initial_impulse > 0:
            t0 = max(0.0, timeline.walk_start - INITIAL_LEAD * self.duration)
            out.append(
                Push.horizontal(t0, self.initial_impulse, self.initial_direction, self.duration)
            )
        impulse = self.impulse_for(mass)
        if impulse > 0:
            t = self.push_time(timeline)
            direction = self.world_direction(timeline)
            out.append(Push.horizontal(t, impulse, direction, self.duration))
        return tuple(out)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data (impulse [N s], velocity change [m/s], angles [rad], duration [s])."""
        return {
            "impulse_Ns": self.impulse,
            "dv_m_s": self.dv,
            "direction_rad": self.direction,
            "step": self.step,
            "step_fraction": self.step_fraction,
            "phase": self.phase,
            "duration_s": self.duration,
            "initial_impulse_Ns": self.initial_impulse,
            "initial_direction_rad": self.initial_direction,
            "seed": self.seed,
            "frame": self.frame,
        }


def _index(field: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 0:
        raise InputError(field, value, "an integer >= 0")
    return int(value)
