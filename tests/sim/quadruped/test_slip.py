"""Foot slip per stance and the slip guard of the quadruped walk (issue 21).

The MuJoCo tests walk one gait cycle (7 s of simulated time, well under a second of wall time with
the servos); the guard's logic is also tested on the sampled plan with made-up slip velocities.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
from footfall.quadruped.gait import GaitPlan, PhaseKind
from footfall.sim.quadruped.slip import (
    DEFAULT_SLIP_LIMIT,
    SlipGuard,
    SlipMonitor,
    stance_slips,
)

if TYPE_CHECKING:
    from footfall.sim.quadruped.sim import SimResult

ROBOT = QuadrupedRobot()
#: the slippery ground of the tests: Coulomb's cone holds up to atan(0.6) = 31 deg
SLIPPERY = 0.6


def _plan(slope_deg: float, cycles: int = 1) -> GaitPlan:
    return plan_gait(
        ROBOT,
        GaitParams(
            slope=math.radians(slope_deg), body_pitch=math.radians(2 * slope_deg / 3), cycles=cycles
        ),
    )


# --- the guard's logic on the sampled plan (no MuJoCo) ---


def _phase_start(plan: GaitPlan, kind: PhaseKind, nth: int = 0) -> float:
    return [p.t0 for p in plan.phases if p.kind is kind][nth]


def test_a_slip_past_the_limit_mid_swing_holds_from_the_swing_end_on_four_feet() -> None:
    plan = _plan(15.0)
    ref = plan.sample(0.01)
    mon = SlipMonitor(SlipGuard(limit=0.0225), plan, ref)
    t_swing = _phase_start(plan, PhaseKind.SWING)
    k_slip = int(np.searchsorted(ref.t, t_swing + 0.2))
    swing_leg = int(np.flatnonzero(~ref.contact[k_slip])[0])
    stance_leg = (swing_leg + 1) % 4
    vel = np.zeros((4, 3))
    for k in range(k_slip):
        assert not mon.update(k, vel)
    # one stance foot slides 0.5 m/s for 5 samples: 2.5 cm > 2.25 cm at the 5th
    vel[stance_leg] = (-0.5, 0.0, 0.0)
    fired = [mon.update(k, vel) for k in range(k_slip, k_slip + 5)]
    assert fired == [False] * 4 + [True]
    stop = mon.stop
    assert stop is not None
    assert stop.time_s == pytest.approx(ref.t[k_slip + 4])
    assert stop.slip_m == pytest.approx(0.025)
    # the swing lands first: the hold starts where that swing phase ends
    swing_end = plan.phases[int(ref.phase[k_slip])].t1
    assert stop.hold_time_s == pytest.approx(swing_end)
    held = mon.reference
    j = int(np.searchsorted(ref.t, stop.hold_time_s - 1e-9))
    # causal: nothing before the hold changes, and the swing is finished as planned
    np.testing.assert_array_equal(held.joints[:j], ref.joints[:j])
    np.testing.assert_array_equal(held.contact[:j], ref.contact[:j])
    # from the hold on: four planned contacts, every foot on the foot-centre plane, still
    assert held.contact[j:].all()
    normal = plan.posture.slope_normal
    assert np.abs(held.feet[j:] @ normal).max() < 1e-9
    np.testing.assert_array_equal(
        held.joints[j:], np.broadcast_to(ref.joints[j], held.joints[j:].shape)
    )
    # the slip after the stop is not acted on again
    assert not mon.update(k_slip + 5, vel)


def test_a_slip_during_a_shift_holds_at_once() -> None:
    plan = _plan(15.0)
    ref = plan.sample(0.01)
    t_shift = _phase_start(plan, PhaseKind.SHIFT, 1)
    k = int(np.searchsorted(ref.t, t_shift + 0.3))
    mon = SlipMonitor(SlipGuard(limit=0.01), plan, ref)
    vel = np.zeros((4, 3))
    vel[0] = (0.0, 2.0, 0.0)  # 2 cm in one sample
    assert mon.update(k, vel)
    assert mon.stop is not None
    # all four feet are down in a shift: the body stops where it is, mid-shift
    assert plan.phases[int(ref.phase[k])].kind is PhaseKind.SHIFT
    assert mon.stop.hold_time_s == pytest.approx(ref.t[k])
    np.testing.assert_array_equal(mon.reference.body_pos[: k + 1], ref.body_pos[: k + 1])
    np.testing.assert_array_equal(
        mon.reference.body_pos[k:], np.tile(ref.body_pos[k], (ref.t.size - k, 1))
    )
    assert mon.reference.contact[k:].all()


def test_slip_is_summed_per_stance_and_restarts_when_the_foot_lands_again() -> None:
    plan = _plan(15.0)
    ref = plan.sample(0.01)
    mon = SlipMonitor(SlipGuard(limit=0.03), plan, ref)
    # every foot slides 1 cm/s whenever it is planned down; one stance lasts at most 4.5 s, so
    # 4.5 cm per stance in total, the limit crossed in the first stance after 3 s
    for k in range(ref.t.size):
        if mon.update(k, np.tile([0.01, 0.0, 0.0], (4, 1))):
            break
    assert mon.stop is not None
    assert mon.stop.time_s == pytest.approx(3.0, abs=0.015)
    # the same speed in stances shorter than 3 s never reaches the limit
    short = replace(ref, contact=ref.contact.copy())
    short.contact[::250] = False  # every foot lifts every 2.5 s
    mon = SlipMonitor(SlipGuard(limit=0.03), plan, short)
    assert not any(mon.update(k, np.tile([0.01, 0.0, 0.0], (4, 1))) for k in range(ref.t.size))


def test_stance_slips_lists_each_stance_with_its_part_down_the_slope() -> None:
    t = np.linspace(0.0, 2.5, 6)
    contact = np.ones((6, 4), dtype=bool)
    contact[2:4, 1] = False  # RF swings: two stances of RF
    disp = np.zeros((6, 4, 3))
    disp[:, 1] = (-0.05, 0.0, 0.0)  # RF slides 5 cm backwards each 0.5 s period it is down
    down = np.array([-1.0, 0.0, 0.0])
    out = stance_slips(t, contact, disp, down)
    rf = [s for s in out if s.leg == "RF"]
    assert [(s.t_start_s, s.t_end_s) for s in rf] == [(0.0, 1.0), (2.0, 2.5)]
    assert [s.slip_m for s in rf] == pytest.approx([0.1, 0.1])
    assert [s.down_slope_m for s in rf] == pytest.approx([0.1, 0.1])
    assert all(s.slip_m == 0.0 for s in out if s.leg != "RF")
    assert len(out) == 5


# --- validation ---


@pytest.mark.parametrize("limit", [0.0, -0.01, math.nan, math.inf, "2 cm", True])
def test_a_bad_limit_is_refused_naming_the_field(limit: object) -> None:
    with pytest.raises(InputError) as err:
        SlipGuard(limit=limit)  # type: ignore[arg-type]
    assert err.value.field == "slip_guard.limit"


def test_an_unknown_action_is_refused_naming_the_field() -> None:
    with pytest.raises(InputError) as err:
        SlipGuard(action="jump")
    assert err.value.field == "slip_guard.action"
    assert SlipGuard().limit == DEFAULT_SLIP_LIMIT


# --- in MuJoCo ---

os.environ.setdefault("MUJOCO_GL", "egl")


class Steep(NamedTuple):
    """The servo walk on 30 deg at friction 0.6, without and with the guard."""

    plan: GaitPlan
    off: SimResult
    stop: SimResult


@pytest.fixture(scope="module")
def steep() -> Steep:
    pytest.importorskip("mujoco")
    from footfall._mjcf import SimSettings
    from footfall.sim.quadruped.sim import simulate

    plan = _plan(30.0)
    settings = SimSettings(friction=SLIPPERY)
    return Steep(plan, simulate(plan, settings), simulate(plan, settings, slip_guard=SlipGuard()))


def _slide_after(res: SimResult, t0: float) -> float:
    """Summed length of every foot's sliding displacement after gait time t0 [m]."""
    sel = res.trace.t > t0
    return float(np.linalg.norm(res.trace.slip_disp[sel].sum(axis=0), axis=1).sum())


def test_the_guard_stops_the_slide_on_a_slippery_30_deg_slope(steep: Steep) -> None:
    off, stop = steep.off, steep.stop
    assert off.slip_stop is None
    ev = stop.slip_stop
    assert ev is not None
    assert ev.slip_m > DEFAULT_SLIP_LIMIT
    m_off, m_stop = off.metrics, stop.metrics
    # without the guard the feet slide far (measured: 83 cm over the stances, 19 cm in one)
    assert m_off.foot_slip_max_m > 5 * DEFAULT_SLIP_LIMIT
    total_off = sum(s.slip_m for s in m_off.stance_slips)
    total_stop = sum(s.slip_m for s in m_stop.stance_slips)
    assert total_stop < 0.3 * total_off
    # after the detection, over the same time window, the feet slide much less
    assert _slide_after(stop, ev.time_s) < 0.3 * _slide_after(off, ev.time_s)
    assert not m_stop.fell


def test_the_guard_holds_four_planned_contacts_and_the_robot_stands_on_them(
    steep: Steep,
) -> None:
    plan, stop = steep.plan, steep.stop
    ev = stop.slip_stop
    t = stop.trace.t
    assert ev is not None
    assert ev.hold_time_s >= ev.time_s
    # the hold starts at a phase boundary (never mid-swing)
    assert min(abs(p.t1 - ev.hold_time_s) for p in plan.phases) < 1e-9
    hold = t >= ev.hold_time_s - 1e-9
    ref = stop.trace.planned
    assert ref.contact[hold].all()
    np.testing.assert_array_equal(
        ref.joints[hold], np.broadcast_to(ref.joints[hold][0], ref.joints[hold].shape)
    )
    # measured: all four feet carry load over almost all of the hold
    assert np.mean(stop.trace.n_contacts[hold] == 4) > 0.95
    # and the planned stances before it end with the plan's (same stances, same times)
    before = [s for s in stop.metrics.stance_slips if s.t_end_s < ev.time_s]
    off_before = [s for s in steep.off.metrics.stance_slips if s.t_end_s < ev.time_s]
    assert [(s.leg, s.t_start_s, s.t_end_s) for s in before] == [
        (s.leg, s.t_start_s, s.t_end_s) for s in off_before
    ]


def test_the_guard_does_not_trigger_on_the_nominal_15_deg_walk() -> None:
    pytest.importorskip("mujoco")
    from footfall.sim.quadruped.sim import simulate

    plan = _plan(15.0)
    off = simulate(plan)
    on = simulate(plan, slip_guard=SlipGuard())
    assert on.slip_stop is None
    assert on.metrics.foot_slip_max_m < DEFAULT_SLIP_LIMIT
    # a guard that does not act leaves the walk exactly as it was
    np.testing.assert_array_equal(on.trace.trunk_pos, off.trace.trunk_pos)
    np.testing.assert_array_equal(on.trace.planned.contact, off.trace.planned.contact)


def test_the_guard_stops_the_whole_body_controller_on_a_slippery_climb() -> None:
    """30 deg up at friction 0.6 (the cone's edge is 31 deg), two cycles: a foot of the wbc walk
    slides past the limit in the second cycle; the gait lands the swinging foot and holds, and
    the robot stands in the held pose: over the last two seconds the trunk stays within 3 cm of
    the held reference. (The reference is the plan's at the stop, which can lie some centimetres
    from where the trunk was then, mid-shift: the trunk moves there first.)"""
    pytest.importorskip("mujoco")
    from footfall._mjcf import SimSettings
    from footfall.sim.quadruped.sim import simulate

    plan = _plan(30.0, cycles=2)
    res = simulate(plan, SimSettings(friction=SLIPPERY), controller="wbc", slip_guard=SlipGuard())
    ev = res.slip_stop
    assert ev is not None
    hold = res.trace.t >= ev.hold_time_s - 1e-9
    assert hold.sum() > 400  # more than four seconds held
    assert res.trace.planned.contact[hold].all()
    assert not res.metrics.fell
    assert res.trace.qp_failures == 0
    tail = hold & (res.trace.t >= res.trace.t[-1] - 2.0)
    off = np.linalg.norm(res.trace.trunk_pos[tail] - res.trace.planned.body_pos[tail], axis=1)
    assert off.max() < 0.03


def test_simulate_refuses_a_guard_of_the_wrong_type() -> None:
    pytest.importorskip("mujoco")
    from footfall.sim.quadruped.sim import simulate

    with pytest.raises(InputError) as err:
        simulate(_plan(15.0), slip_guard=0.02)  # type: ignore[arg-type]
    assert err.value.field == "slip_guard"


# --- command line ---


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", "quadruped", "--no-video", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (("--on-slip", "jump"), "--on-slip"),
        (("--on-slip", "stop", "--slip-limit", "0"), "--slip-limit"),
        (("--on-slip", "stop", "--slip-limit", "nan"), "--slip-limit"),
    ],
)
def test_the_cli_refuses_bad_slip_options_with_exit_2(
    args: tuple[str, ...], option: str, tmp_path: Path
) -> None:
    r = _cli(*args, "--out", str(tmp_path))
    assert r.returncode == 2, r.stderr
    assert option in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "quadruped.json").exists()


def test_the_cli_reports_each_stance_and_the_stop(tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    # a limit of 1 mm trips on the nominal walk's few millimetres of slip
    r = _cli("--cycles", "1", "--on-slip", "stop", "--slip-limit", "0.001", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    out = json.loads((tmp_path / "quadruped.json").read_text())
    stances = out["stance_slips"]
    assert {s["leg"] for s in stances} == {"LF", "RF", "RH", "LH"}
    assert max(s["slip_m"] for s in stances) == pytest.approx(out["foot_slip_max_m"])
    guard = out["slip_guard"]
    assert guard["on_slip"] == "stop" and guard["limit_m"] == 0.001
    assert guard["stop"]["slip_m"] > 0.001
    assert guard["stop"]["hold_time_s"] >= guard["stop"]["time_s"]
    assert "slip guard:" in r.stdout + r.stderr
