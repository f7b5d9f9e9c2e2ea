"""The one disturbance type: the seeded sampler, its pushes on a plant's timeline (times by hand),
velocity changes as impulses, input errors, and the plants' clocks checked against their own
trajectories."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.sim.disturbance import (
    INITIAL_LEAD,
    PUSH_PHASE_WINDOW,
    PUSH_STEP_WINDOW,
    Disturbance,
    Push,
    SupportTimeline,
    push_force,
)


def test_disturbance_is_a_pure_function_of_the_seed() -> None:
    ds = [Disturbance.of_seed(s) for s in range(40)]
    assert Disturbance.of_seed(7) == ds[7]
    assert Disturbance.of_seed(np.int64(7)) == ds[7]
    assert len({(d.step_fraction, d.phase, d.direction) for d in ds}) == 40
    for s, d in enumerate(ds):
        assert d.seed == s and d.impulse == 0.0
        assert PUSH_STEP_WINDOW[0] <= d.step_fraction <= PUSH_STEP_WINDOW[1]
        assert PUSH_PHASE_WINDOW[0] <= d.phase <= PUSH_PHASE_WINDOW[1]
        assert 0.0 <= d.direction < 2 * math.pi
        assert 0.0 <= d.initial_direction < 2 * math.pi
        for n in (1, 2, 7, 11, 40):
            k = d.push_step(n)
            assert 0 <= k <= n - 1
            assert k == min(n - 1, math.floor(d.step_fraction * n))
    # directions cover the circle, not a corner of it
    assert np.ptp([d.direction for d in ds]) > math.pi
    # the magnitude does not change the draw (only the impulse varies between push levels)
    assert replace(Disturbance.of_seed(7, impulse=4.0), impulse=0.0) == ds[7]
    for bad in (-1, 1.5, True):
        with pytest.raises(InputError):
            Disturbance.of_seed(bad)  # type: ignore[arg-type]


def test_pushes_on_a_periodic_timeline_by_hand() -> None:
    t_ss, t_ds, start = 0.4, 0.1, 2.3
    tl = SupportTimeline.periodic(start, 10, t_ss, t_ds)
    assert tl.n_steps == 10 and tl.starts[3] == pytest.approx(2.3 + 3 * 0.5)
    d = Disturbance(
        impulse=6.0,
        direction=math.pi / 2,
        step=3,
        phase=0.25,
        duration=0.2,
        initial_impulse=1.0,
        initial_direction=math.pi,
    )
    first, push = d.pushes(tl, mass=30.0)
    # the push: 25 % into single support 3, 6 N s over 0.2 s along +y
    assert push.start == pytest.approx(2.3 + 3 * 0.5 + 0.25 * 0.4, abs=1e-12)
    assert push.duration == 0.2
    np.testing.assert_allclose(push.force, [0.0, 30.0, 0.0], atol=1e-12)
    assert push.impulse == pytest.approx(6.0) and push.direction == pytest.approx(math.pi / 2)
    # the initial perturbation ends INITIAL_LEAD durations before the first single support
    assert first.start == pytest.approx(start - INITIAL_LEAD * 0.2)
    np.testing.assert_allclose(first.force, [-5.0, 0.0, 0.0], atol=1e-12)
    # a step fraction instead of an index: floor(f N)
    g = replace(d, step=None, step_fraction=0.55)
    assert g.push_step(10) == 5 and g.push_time(tl) == pytest.approx(2.3 + 5 * 0.5 + 0.1)
    # no impulse, no push; an initial perturbation may still come (starting at 0 at the latest)
    early = SupportTimeline.periodic(0.0, 4, t_ss, t_ds)
    only = Disturbance(initial_impulse=1.0).pushes(early, 30.0)
    assert len(only) == 1 and only[0].start == 0.0
    assert Disturbance().pushes(tl, 30.0) == ()


def test_a_velocity_change_is_an_impulse_of_mass_times_dv() -> None:
    tl = SupportTimeline.periodic(0.0, 6, 0.4, 0.1)
    d = Disturbance.of_seed(3, dv=0.3)
    (push,) = d.pushes(tl, mass=32.5)
    assert push.impulse == pytest.approx(32.5 * 0.3)
    assert push.direction == pytest.approx(math.remainder(d.direction, 2 * math.pi))
    # the same draw as the impulse form of the same seed
    (same,) = Disturbance.of_seed(3, impulse=32.5 * 0.3).pushes(tl, mass=1.0)
    assert same.start == push.start
    np.testing.assert_allclose(same.force, push.force, rtol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"impulse": -1.0}, "push impulse [N s]"),
        ({"impulse": math.nan}, "push impulse [N s]"),
        ({"dv": -0.1}, "push velocity change [m/s]"),
        ({"dv": 0.1, "impulse": 2.0}, "push impulse [N s]"),
        ({"phase": 1.5}, "push phase"),
        ({"step": -2}, "push step"),
        ({"step": 1.5}, "push step"),
        ({"step_fraction": 1.0}, "push step fraction"),
        ({"duration": 0.0}, "push duration [s]"),
        ({"direction": math.inf}, "push direction [rad]"),
    ],
)
def test_bad_disturbances_name_their_field(kwargs: dict[str, object], field: str) -> None:
    with pytest.raises(InputError) as err:
        Disturbance(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_a_step_beyond_the_walk_is_refused() -> None:
    tl = SupportTimeline.periodic(0.0, 4, 0.4, 0.1)
    with pytest.raises(InputError) as err:
        Disturbance(impulse=1.0, step=4).pushes(tl, 30.0)
    assert err.value.field == "push step"


@pytest.mark.parametrize("step", [None, 0])
def test_a_walk_without_steps_cannot_be_pushed(step: int | None) -> None:
    """A plan without a solution has no single support: the push says so (it used to index an
    empty timeline)."""
    tl = SupportTimeline.periodic(0.0, 0, 0.4, 0.1)
    with pytest.raises(InputError) as err:
        Disturbance(dv=0.1, step=step).pushes(tl, 30.0)
    assert err.value.field == "plan"


def test_push_force_sums_the_active_pushes() -> None:
    a = Push.horizontal(1.0, 2.0, 0.0, 0.1)
    b = Push.horizontal(1.05, 1.0, math.pi / 2, 0.1)
    np.testing.assert_allclose(push_force((a, b), 0.99), 0.0)
    np.testing.assert_allclose(push_force((a, b), 1.07), [20.0, 10.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(push_force((a, b), 1.12), [0.0, 10.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(push_force((a, b), 1.16), 0.0)


def test_the_reduced_plant_is_pushed_when_its_timeline_says() -> None:
    """The first tick at which a pushed walk leaves the unpushed one is the push's start on the
    plant's clock: the timeline is the plant's own, read off its trajectory."""
    from footfall.planning import make_plan
    from footfall.sim.reduced.closed_loop import SimOptions
    from footfall.sim.reduced.trial import ReducedPlant
    from footfall.sim.trial import run_trial
    from footfall.terrain import builtin_scene

    scene = builtin_scene("flat")
    plan = make_plan(scene, "reactive")
    plant = ReducedPlant(SimOptions(engine="python"))
    d = Disturbance(impulse=4.0, direction=1.0, step=2, phase=0.5)
    calm = run_trial(plant, scene, plan).detail
    pushed = run_trial(plant, scene, plan, d).detail
    moved = np.flatnonzero(np.any(np.abs(pushed.com - calm.com) > 1e-12, axis=1))
    t_push = d.push_time(plant.timeline(plan))
    dt = float(np.diff(calm.t[:2])[0])
    # the trace holds the state at the start of each tick: the first change shows one tick on
    assert t_push < pushed.t[moved[0]] <= t_push + dt + 1e-9
