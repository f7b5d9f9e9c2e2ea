"""Foot slip of the quadruped walk: per-stance report and an online slip guard.

Slip is the sliding of a foot's material point at its ground contact (the recorder's
``slip_vel``, tangential to the contact, zero off the ground; a rolling sphere has none),
integrated over one planned stance of that foot. It is summed two ways:

- :func:`stance_slips`, after the walk: one :class:`StanceSlip` per planned stance of every foot,
  the integral taken at every physics step (the recorder's ``slip_disp``), so a contact that
  lasts a few physics steps (a foot's release) counts for those steps only;
- :class:`SlipMonitor`, during the walk: the sum so far of each stance foot, one control sample
  at a time from the sample just measured (causal: no later sample is read; at the control
  rate, as a controller sees the feet: one sample stands for its whole period). When a foot's slip
  in its current stance exceeds :attr:`SlipGuard.limit`, the guard acts. ``stop``: a swing
  first lands its foot; in a body shift or the final hold (all four feet down) the gait holds at
  once. The four-foot stance is then held for the rest of the run: the commanded reference stops
  advancing (:func:`held_reference`) while the physics goes on, so the run shows whether the
  robot stays put.

The guard is off unless ``simulate(slip_guard=SlipGuard(...))`` is given.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import positive
from footfall.errors import InputError
from footfall.quadruped.gait import GaitPlan, GaitTrajectory, PhaseKind
from footfall.quadruped.robot import LEGS
from footfall.quadruped.stability import stability_margin, support_polygon
from footfall.results.quadruped import SlipStop, StanceSlip

#: what the guard does when a foot slips past its limit
SLIP_ACTIONS = ("stop",)
#: default slip limit per stance [m]. Measured (friction 0.6, 3 cycles, body at 2/3 of the slope):
#: the walks that complete slide at most 1.1 cm per stance at +25 deg and 2.7 cm at -25 deg (servo);
#: the nominal 15 deg walk (friction 1) 0.3 cm. At +-30 deg the servo walk slides 15-34 cm per
#: stance and goes nowhere. 3 cm (7.5 % of the 0.4 m step) lets the walks that complete through
#: and catches a slide in its first centimetres.
DEFAULT_SLIP_LIMIT = 0.03


@dataclass(frozen=True)
class SlipGuard:
    """Online slip detector of the quadruped walk and what it does (see the module docstring).

    Attributes:
        limit: a foot's sliding displacement in its current planned stance above which the guard
            acts [m] (> 0).
        action: ``stop``: land the swinging foot (if any), then hold the four-foot stance.
    """

    limit: float = DEFAULT_SLIP_LIMIT
    action: str = "stop"

    def __post_init__(self) -> None:
        object.__setattr__(self, "limit", positive("slip_guard.limit", self.limit))
        if self.action not in SLIP_ACTIONS:
            raise InputError("slip_guard.action", self.action, f"one of {', '.join(SLIP_ACTIONS)}")


def downhill(plan: GaitPlan, points: FloatArray) -> FloatArray:
    """Unit vectors down the ground at ``points`` (..., 3) [m] in ``{W}``, same shape: gravity's
    direction projected on the local plane (backwards, -x, where the ground is level)."""
    pts = np.asarray(points, dtype=float)
    flat = pts.reshape(-1, 3)
    out = np.empty_like(flat)
    for i, p in enumerate(flat):
        n = plan.ground.normal(float(p[0]), float(p[1]))
        d = n[2] * n - np.array([0.0, 0.0, 1.0])  # -z minus its part along n
        size = float(np.linalg.norm(d))
        out[i] = d / size if size > 1e-9 else (-1.0, 0.0, 0.0)
    return out.reshape(pts.shape)


def stance_slips(
    t: FloatArray, contact: np.ndarray, slip_disp: FloatArray, down: FloatArray
) -> list[StanceSlip]:
    """One :class:`StanceSlip` per planned stance of every foot, ordered by start time.

    Args:
        t: sample times, shape (T,) [s].
        contact: planned (commanded) stance flags, shape (T, 4).
        slip_disp: measured sliding displacement of each foot's contact point over each sample's
            control period, shape (T, 4, 3) [m] (``QuadrupedTrace.slip_disp``).
        down: unit vector down the slope, shape (3,), or per sample and foot, shape (T, 4, 3)
            (a stance's part down the slope is taken along the vector at its first sample).
    """
    n = t.shape[0]
    down = np.broadcast_to(down, (n, 4, 3))
    out: list[StanceSlip] = []
    for i, leg in enumerate(LEGS):
        c = contact[:, i].astype(int)
        bounds = np.concatenate([[0], np.flatnonzero(np.diff(c) != 0) + 1, [n]])
        for a, b in itertools.pairwise(bounds):
            if not c[a]:
                continue
            disp = slip_disp[a:b, i].sum(axis=0)
            out.append(
                StanceSlip(
                    leg.value,
                    float(t[a]),
                    float(t[b] if b < n else t[-1]),
                    float(np.linalg.norm(disp)),
                    (float(disp[0]), float(disp[1]), float(disp[2])),
                    float(disp @ down[a, i]),
                )
            )
    out.sort(key=lambda s: (s.t_start_s, s.leg))
    return out


def hold_index(ref: GaitTrajectory, plan: GaitPlan, k: int) -> int:
    """The first sample at or after ``k`` where the walk can hold still on four feet: ``k``
    itself in a body shift or the final hold (every foot is down; a shift that went on to its end
    let a sliding robot run away), the first sample after a swing (the last sample when no phase
    follows)."""
    phase = int(ref.phase[k])
    if plan.phases[phase].kind is not PhaseKind.SWING:
        return k
    later = np.flatnonzero(ref.phase[k:] != phase)
    return k + int(later[0]) if later.size else ref.t.shape[0] - 1


def held_reference(ref: GaitTrajectory, plan: GaitPlan, j: int) -> GaitTrajectory:
    """``ref`` up to sample ``j``, then sample ``j`` held with all four feet down (same times).

    At ``j`` (a phase boundary, see :func:`hold_index`) every foot is on the ground: a swing
    ends where it lands and starts where it lifts off. The planned ZMP stays where the plan had
    it; its margin is recomputed in the four feet's polygon.
    """

    def hold(x: np.ndarray) -> np.ndarray:
        y = x.copy()
        y[j:] = x[j]
        return y

    contact = ref.contact.copy()
    contact[j:] = True
    margin = ref.margin.copy()
    poly = support_polygon(np.array([plan.contact_point(f) for f in ref.feet[j]]))
    margin[j:] = stability_margin(ref.zmp[j], poly) if np.all(np.isfinite(ref.zmp[j])) else math.nan
    return replace(
        ref,
        body_pos=hold(ref.body_pos),
        body_pitch=hold(ref.body_pitch),
        feet=hold(ref.feet),
        contact=contact,
        joints=hold(ref.joints),
        com=hold(ref.com),
        zmp=hold(ref.zmp),
        margin=margin,
        phase=hold(ref.phase),
    )


class SlipMonitor:
    """The running state of a :class:`SlipGuard` over one walk.

    Args:
        guard: the guard's settings.
        plan: the gait plan.
        ref: the sampled plan the controller tracks (T samples).

    Attributes:
        reference: the reference to track now (``ref``, or the held one after a stop).
        slip: each foot's sliding displacement in its current stance, shape (4, 3) [m] (zero off
            the ground).
        stop: the stop event, None until the guard stops the gait.
    """

    def __init__(self, guard: SlipGuard, plan: GaitPlan, ref: GaitTrajectory) -> None:
        self.guard = guard
        self.plan = plan
        self.reference = ref
        self.dt = float(ref.t[1] - ref.t[0]) if ref.t.shape[0] > 1 else 0.0
        self.slip = np.zeros((4, 3))
        self.stop: SlipStop | None = None

    def update(self, k: int, slip_vel: FloatArray) -> bool:
        """Add sample ``k``'s measured sliding velocity (4, 3) [m/s] of the feet; True when the
        guard has just replaced :attr:`reference` (the caller's controller must follow it)."""
        stance = self.reference.contact[k]
        if k > 0:
            # a foot that has just landed starts a new stance
            self.slip[stance & ~self.reference.contact[k - 1]] = 0.0
        self.slip[~stance] = 0.0
        self.slip[stance] += slip_vel[stance] * self.dt
        if self.stop is not None:
            return False
        size = np.linalg.norm(self.slip, axis=1)
        foot = int(np.argmax(size))
        if size[foot] <= self.guard.limit:
            return False
        ref = self.reference
        j = hold_index(ref, self.plan, k)
        self.stop = SlipStop(LEGS[foot].value, float(ref.t[k]), float(size[foot]), float(ref.t[j]))
        self.reference = held_reference(ref, self.plan, j)
        return True


def check_guard(guard: object) -> SlipGuard | None:
    """``guard`` if it is a :class:`SlipGuard` or None (an error naming the argument otherwise)."""
    if guard is not None and not isinstance(guard, SlipGuard):
        raise InputError("slip_guard", type(guard).__name__, "a SlipGuard or None")
    return guard


__all__ = [
    "DEFAULT_SLIP_LIMIT",
    "SLIP_ACTIONS",
    "SlipGuard",
    "SlipMonitor",
    "SlipStop",
    "StanceSlip",
    "check_guard",
    "downhill",
    "held_reference",
    "hold_index",
    "stance_slips",
]
