"""The walker with the MPC's step timing (``WalkOptions.step_timing``).

The swing path is re-timed without a jump when the touchdown moves forward, and lands at the
new touchdown. A push of the field's protocol that the biped does not survive with the fixed
timing (flat_long, 0.6 m/s inward at 20 % of single support 10) it survives with it, and the
swing foot is measured on the ground sooner than the planned touchdown: from the sole heights
of the trace, not the walker's clock.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.experiments.protocol import PushCase, PushProtocol
from footfall.planning import make_plan
from footfall.sim.biped.model import planner_params
from footfall.sim.biped.options import STEP_TIMING, WalkOptions
from footfall.sim.biped.walk import BipedWalk
from footfall.sim.trial import make_plant, run_trial
from footfall.terrain import builtin_scene

pytest.importorskip("mujoco")

#: the protocol case: 0.6 m/s inward at 20 % of the middle single support (N = 20)
CASE = PushCase(0.6, 0.2, "inward")
#: a sole this high [m] or lower over flat ground stands on it (the soles' collision radius)
ON_GROUND = 0.006


class _Mover:
    """A stub adjuster: the plan's footstep and no torque, and once, a touchdown moved."""

    def __init__(self, plan, at: float, advance: float) -> None:  # type: ignore[no-untyped-def]
        self.plan, self.at, self.advance, self._pending = plan, at, advance, 0.0

    def update(self, t, state, stance, phase):  # type: ignore[no-untyped-def]
        if phase == 2 and abs(t - self.at) < 1e-9:
            self._pending = self.advance
        return np.array(self.plan.footsteps[phase + 1]), np.zeros(2)

    def take_advance(self) -> float:
        out, self._pending = self._pending, 0.0
        return out


@pytest.fixture(scope="module")
def flat20():  # type: ignore[no-untyped-def]
    scene = builtin_scene("flat_long")
    plan = make_plan(scene, "miqcqp", 20, robot=planner_params(base=scene.robot))
    return scene, plan


def test_the_swing_path_is_continuous_and_lands_at_the_moved_touchdown(flat20) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat20
    w = BipedWalk(scene, plan, WalkOptions())
    w._begin_step(2)
    t_ss, dt = w.t_ss, w.dt
    tp, adv = 0.08, 0.06
    w.src = _Mover(plan, tp, adv)  # type: ignore[assignment]
    before = w._swing_time(tp)
    assert before == tp and w._swing_speedup() == 1.0  # unmoved: the planned path, exactly
    w.src.update(tp, None, None, 2)
    t_moved = w._move_touchdown(2, tp)
    assert t_moved == pytest.approx(tp + adv)
    assert w._swing_time(t_moved) == pytest.approx(before, abs=1e-12)  # no jump
    assert w._swing_time(t_ss) == pytest.approx(t_ss, abs=1e-12)  # ends at the touchdown
    # the path runs faster by what it had left over the time left
    assert w._swing_speedup() == pytest.approx((t_ss - tp) / (t_ss - tp - adv))
    assert w.t_saved == pytest.approx(adv) and w.t_saved_planned == pytest.approx(adv)
    t_end = w.t_walk0 + w.n * w.t_step
    assert w.t_end_steps == pytest.approx(t_end - adv)
    # a new step starts on the planned path again
    w._begin_step(3)
    assert w._swing_time(0.1) == 0.1 and w._swing_speedup() == 1.0
    assert math.isclose(dt, 0.01)


def _walk(scene, plan, on: bool):  # type: ignore[no-untyped-def]
    proto = PushProtocol(dv=(CASE.dv,), phases=(CASE.phase,), directions=(CASE.direction,))
    d = proto.disturbance(CASE, plan.n_steps)
    plant = make_plant("mujoco", options=WalkOptions(step_timing=on))
    return d, run_trial(plant, scene, plan, d).detail


def test_a_protocol_push_is_survived_by_landing_sooner(flat20) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat20
    d, fixed = _walk(scene, plan, False)
    assert fixed.trace.fell  # the case is hard: not survived with the fixed timing
    assert fixed.metrics.touchdowns_moved == ()
    _, timed = _walk(scene, plan, True)
    assert not timed.trace.fell and timed.metrics.reached_goal
    moved = {m["step"]: m["earlier_s"] for m in timed.metrics.touchdowns_moved}
    assert d.step in moved and moved[d.step] > 0.0
    # the swing foot of the pushed support is on the ground before its planned touchdown, by
    # about the time moved: measured from the sole heights
    tr = timed.trace
    opts, robot = WalkOptions(), plan.robot
    t_walk0 = opts.settle_time + opts.shift_time
    t_planned = t_walk0 + d.step * (robot.t_ss + robot.t_ds) + robot.t_ss
    side = 0 if plan.sides[d.step].other.name == "LEFT" else 1
    t_lift = t_walk0 + d.step * (robot.t_ss + robot.t_ds)
    after = tr.t > t_lift + 0.1  # the sole is in the air by then
    assert tr.feet[np.argmax(after), side, 2] > 2 * ON_GROUND
    down = np.nonzero(after & (tr.feet[:, side, 2] <= ON_GROUND))[0]
    assert down.size
    t_down = float(tr.t[down[0]])
    assert t_down < t_planned - 0.5 * moved[d.step]
    # every ticked single support of the pushed step is shorter than the planned one
    ticks = int(np.sum(tr.phase == d.step))
    assert ticks <= round((robot.t_ss - moved[d.step]) / opts.control_dt) + 1


def test_the_walkers_option_is_checked_and_its_default_is_on() -> None:
    assert WalkOptions().step_timing is STEP_TIMING is True
    with pytest.raises(InputError, match="step_timing"):
        WalkOptions(step_timing="yes")  # type: ignore[arg-type]
    assert replace(WalkOptions(), step_timing=False).step_timing is False


def test_the_command_lines_default_is_the_walkers() -> None:
    import inspect

    from footfall.cli import simulation

    default = inspect.signature(simulation.walk_cmd).parameters["step_timing"].default.default
    assert default == WalkOptions.step_timing
