"""The push-recovery protocol: push directions relative to the walk against a hand computation,
impulse and timing against the plant's clock computed here, the seeded world-frame draws unchanged,
the level summary, and ``footfall bench pushes --protocol`` (input errors, one small real run)."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.experiments.protocol import (
    PROTOCOL_DURATION,
    PROTOCOL_PHASES,
    LevelSummary,
    ProtocolResult,
    PushProtocol,
    format_markdown,
    format_summary,
    largest_passed,
    summarise,
)
from footfall.planning import make_plan
from footfall.sim.disturbance import Disturbance, SupportTimeline
from footfall.sim.reduced.trial import ReducedPlant
from footfall.terrain.resolve import resolve_scene
from tests.cli import error_line, footfall


def _unit(force: np.ndarray) -> np.ndarray:
    assert force[2] == 0.0
    return force[:2] / np.hypot(force[0], force[1])


def _by_hand(heading: float, side: str, name: str) -> np.ndarray:
    """The world unit vector of a protocol direction, from the stance foot's axes: forward is
    the heading; the stance foot's side is its left normal for a left foot, its right normal
    for a right foot."""
    fwd = np.array([math.cos(heading), math.sin(heading)])
    left = np.array([-math.sin(heading), math.cos(heading)])
    own_side = left if side == "left" else -left
    return {"forward": fwd, "backward": -fwd, "inward": own_side, "outward": -own_side}[name]


HEADINGS = (0.0, 0.4, -2.1, 2.9, math.pi / 2, -0.7)
SIDES = ("right", "left", "left", "right", "right", "left")


@pytest.mark.parametrize("step", range(len(HEADINGS)))
def test_walk_frame_directions_by_hand(step: int) -> None:
    tl = SupportTimeline.periodic(1.0, len(HEADINGS), 0.4, 0.1, HEADINGS, SIDES)
    proto = PushProtocol(dv=(0.2,), step=step)
    for case in proto.cases():
        d = proto.disturbance(case, tl.n_steps)
        (push,) = d.pushes(tl, 30.0)
        want = _by_hand(HEADINGS[step], SIDES[step], case.direction)
        np.testing.assert_allclose(_unit(push.force), want, atol=1e-12)


def test_walk_frame_on_a_turning_plan() -> None:
    """On the reduced plant's timeline of a real plan that turns: the plan's sides and headings
    reach the timeline, and inward points to the stance foot's side of the body at every step."""
    plan = make_plan(resolve_scene("turn"), "reactive")
    assert plan.has_solution
    tl = ReducedPlant().timeline(plan)
    n = plan.n_steps
    assert tl.headings == tuple(float(h) for h in plan.headings[:n])
    assert tl.sides == tuple(s.value for s in plan.sides[:n])
    assert {"left", "right"} <= set(tl.sides) and np.ptp(tl.headings) > 1.0
    for step in range(n):
        d = Disturbance(impulse=1.0, direction=math.pi / 2, step=step, frame="walk")
        (push,) = d.pushes(tl, 32.0)
        # inward points from the body's centre line toward the stance footstep: the footstep
        # lies on that side of the line through the other foot along the heading
        other = plan.footsteps[step + 1, :2]  # the swing foot's landing, on the other side
        to_stance = plan.footsteps[step, :2] - other
        assert float(np.dot(_unit(push.force), to_stance)) > 0.0
        np.testing.assert_allclose(
            _unit(push.force),
            _by_hand(float(plan.headings[step]), plan.sides[step].value, "inward"),
            atol=1e-12,
        )


def test_walk_frame_needs_stance_feet() -> None:
    tl = SupportTimeline.periodic(0.0, 4, 0.4, 0.1)  # a quadruped's: no stance feet
    d = Disturbance(impulse=1.0, step=1, frame="walk")
    with pytest.raises(InputError, match="push frame"):
        d.pushes(tl, 10.0)
    with pytest.raises(InputError, match="push frame"):
        Disturbance(frame="body")
    with pytest.raises(InputError, match="timeline"):
        SupportTimeline.periodic(0.0, 2, 0.4, 0.1, (0.0, 0.0), ("left", "up"))


def test_impulse_duration_and_start_on_the_mujoco_plants_clock() -> None:
    pytest.importorskip("mujoco")
    from footfall.sim.biped.options import WalkOptions
    from footfall.sim.biped.trial import MujocoBipedPlant
    from footfall.sim.trial import trial_pushes

    plan = make_plan(resolve_scene("flat"), "reactive")
    plant = MujocoBipedPlant()
    proto = PushProtocol(dv=(0.1, 0.35))
    n = plan.n_steps
    step = n // 2  # the middle single support
    opts = WalkOptions()
    t_ss, t_ds, mass = plan.robot.t_ss, plan.robot.t_ds, plan.robot.mass
    cases = proto.cases()
    assert len(cases) == 2 * 12 and proto.cases_per_level == 12
    assert {(c.phase, c.direction) for c in cases if c.dv == 0.1} == {
        (p, d) for p in PROTOCOL_PHASES for d in ("forward", "backward", "inward", "outward")
    }
    for case, d in zip(cases, proto.disturbances(n), strict=True):
        (push,) = trial_pushes(plant, plan, d)
        assert push.duration == PROTOCOL_DURATION == 0.05
        assert push.impulse == pytest.approx(mass * case.dv, rel=1e-12)
        start = opts.settle_time + opts.shift_time + step * (t_ss + t_ds) + case.phase * t_ss
        assert push.start == pytest.approx(start, abs=1e-12)


def test_world_frame_seeded_draws_unchanged() -> None:
    # Computed on main before the walk frame was added (commit a7d180f):
    #   Disturbance.of_seed(s, impulse=4.0) -> (step_fraction, phase, direction, initial_direction)
    #   and Disturbance.of_seed(3, dv=0.2, initial_impulse=1.0).pushes(
    #       SupportTimeline.periodic(0.7, 10, 0.4, 0.1), 30.0) -> (start, duration, force)
    draws = {
        0: (0.5334694527991064, 0.44097967999140264, 3.531962748582877, 5.08604176485658),
        1: (0.4869837550323995, 0.3095053462706067, 4.29468520835076, 5.138920486062399),
        7: (0.5627283160195353, 0.5684874926739838, 6.231469500155968, 2.4884414113706566),
        123: (0.6023763167004398, 0.4856263631038097, 5.63226524196681, 5.5617359719075585),
    }
    for seed, want in draws.items():
        d = Disturbance.of_seed(seed, impulse=4.0)
        assert d.frame == "world"
        assert (d.step_fraction, d.phase, d.direction, d.initial_direction) == want
    pushes = Disturbance.of_seed(3, dv=0.2, initial_impulse=1.0).pushes(
        SupportTimeline.periodic(0.7, 10, 0.4, 0.1), 30.0
    )
    got = [(p.start, p.duration, p.force.tolist()) for p in pushes]
    assert got == [
        (0.5499999999999999, 0.1, [9.898496228307373, 1.42118697509677, 0.0]),
        (2.790009145366621, 0.1, [57.08500915564592, 18.4743532958483, 0.0]),
    ]
    # a timeline with stance feet does not change a world push
    tl = SupportTimeline.periodic(0.7, 10, 0.4, 0.1, (1.0,) * 10, ("left", "right") * 5)
    assert [p.force.tolist() for p in Disturbance.of_seed(3, dv=0.2).pushes(tl, 30.0)] == [
        got[1][2]
    ]


def _row(dv: float, phase: float, direction: str, ok: bool) -> dict[str, object]:
    return {"dv_m_s": dv, "phase": phase, "direction": direction, "success": ok, "fell": not ok}


def test_summary_counts_and_largest_level() -> None:
    rows = [_row(v, p, d, True) for v in (0.1, 0.2) for p in (0.2, 0.7) for d in ("in", "out")]
    rows += [_row(0.3, 0.2, "in", True), _row(0.3, 0.7, "out", False)]
    levels = summarise(rows)
    assert [(lv.dv, lv.passed, lv.total, lv.failed) for lv in levels] == [
        (0.1, 4, 4, ()),
        (0.2, 4, 4, ()),
        (0.3, 1, 2, ("out@0.7",)),
    ]
    assert largest_passed(levels) == "0.2 m/s"
    assert largest_passed(levels[:2]).startswith(">= 0.2 m/s")
    assert largest_passed(levels[2:]) == "none"
    # a failed level below the largest passed is said, not hidden
    odd = [LevelSummary(0.1, 11, 12, ("inward@0.2",)), LevelSummary(0.2, 12, 12, ())]
    assert largest_passed(odd) == "0.2 m/s (but 0.1 m/s failed)"


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"dv": ()}, "dv"),
        ({"dv": (-0.1,)}, "dv"),
        ({"dv": (0.1, 0.1)}, "dv"),
        ({"dv": (0.1,), "phases": (1.2,)}, "phases"),
        ({"dv": (0.1,), "directions": ("up",)}, "directions"),
        ({"dv": (0.1,), "duration": 0.0}, "duration"),
        ({"dv": (0.1,), "region_aware": "horizons"}, "region_aware"),
        ({"dv": (0.1,), "leg_momentum": -0.5}, "leg_momentum"),
        ({"dv": (0.1,), "leg_momentum": 0.5, "controller": "servo"}, "leg_momentum"),
        ({"dv": (0.1,), "walk_on": 3}, "walk_on"),
        ({"dv": (0.1,), "walk_on": -2}, "walk_on"),
    ],
)
def test_protocol_refuses_bad_settings(kwargs: dict[str, object], field: str) -> None:
    with pytest.raises(InputError, match=field):
        PushProtocol(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (["--dv", "-0.1"], "dv"),
        (["--dv", "fast"], "dv"),
        (["--dv", ""], "dv"),
        (["--dv", "0"], "dv"),
        (["--phases", "0.2,1.5"], "phases"),
        (["--robot", "no_such_robot"], "robot"),
        (["--scene", "no_such_scene"], "scene"),
        (["--directions", "sideways"], "directions"),
        (["--region-aware", "horizons"], "region_aware"),
        (["--leg-momentum", "1.5"], "leg_momentum"),
        (["--leg-momentum", "0.5", "--controller", "servo"], "leg_momentum"),
        (["--walk-on", "1"], "walk_on"),
    ],
)
def test_cli_refuses_bad_values(tmp_path: Path, args: list[str], field: str) -> None:
    out = tmp_path / "out"
    r = footfall("bench", "pushes", "--protocol", *args, "--out", str(out))
    error_line(r, field)
    assert not out.exists()


@pytest.mark.slow
def test_cli_small_real_run(tmp_path: Path) -> None:
    """Two walks in two worker processes: the rows come back in the protocol's order."""
    pytest.importorskip("mujoco")
    out = tmp_path / "out"
    r = footfall(
        "bench", "pushes", "--protocol", "--robot", "biped", "--scene", "flat", "--dv", "0.05",
        "--phases", "0.45", "--directions", "forward,outward", "--workers", "2", "--out", str(out),
        timeout=600,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr[-2000:]
    with open(out / "protocol.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [(row["dv_m_s"], row["phase"], row["direction"]) for row in rows] == [
        ("0.05", "0.45", "forward"),
        ("0.05", "0.45", "outward"),
    ]
    mass = float(re.search(r"biped \(([\d.]+) kg\)", r.stdout).group(1))  # type: ignore[union-attr]
    for row in rows:
        assert float(row["impulse_Ns"]) == pytest.approx(mass * 0.05, rel=0.01)
        assert row["success"] == str(row["reached_goal"] == "True" and row["fell"] == "False")
    passed = sum(row["success"] == "True" for row in rows)
    failed = [f"{row['direction']}@{row['phase']}" for row in rows if row["success"] != "True"]
    line = next(x for x in r.stdout.splitlines() if x.startswith("dv 0.05 m/s"))
    assert f": {passed}/2 pass" in line
    for label in failed:
        assert label in line
    want = ">= 0.05 m/s" if passed == 2 else "none"
    assert f"largest dv passed: {want}" in r.stdout
    md = (out / "protocol.md").read_text()
    assert f"{passed}/2 pass" in md and md.rstrip().endswith("**")
    assert "footstep regions horizon" in md and "footstep regions horizon" in r.stdout

    assert md.count("| forward |") == 1 and md.count("| outward |") == 1
    png = (out / "protocol.png").read_bytes()
    assert png.startswith(b"\x89PNG") and png.endswith(b"IEND\xaeB`\x82")


def test_the_protocols_walker_takes_the_region_mode() -> None:
    """The plant a protocol walks with has the protocol's region mode (the walker's options)."""
    pytest.importorskip("mujoco")
    from footfall.experiments import protocol as proto

    for mode in ("planned", "horizon"):
        plant = proto._plant("biped", "wbc", mode)
        assert plant.options.region_aware == mode
        assert plant.options.controller == "wbc"


def test_walker_defaults_are_stored_resolved() -> None:
    # what the walks used, not None: the wbc walker's forecast share and added stopping steps
    proto = PushProtocol(dv=(0.1,))
    assert proto.leg_momentum == 0.5 and proto.walk_on == 4
    assert PushProtocol(dv=(0.1,), walk_on=0).walk_on == 0
    assert PushProtocol(dv=(0.1,), controller="servo").leg_momentum == 0.0
    assert proto.step_timing is True
    assert PushProtocol(dv=(0.1,), step_timing=False).step_timing is False


def test_the_protocols_walker_takes_the_step_timing() -> None:
    pytest.importorskip("mujoco")
    from footfall.experiments import protocol as proto

    for on in (True, False):
        plant = proto._plant("biped", "wbc", "horizon", None, None, on)
        assert plant.options.step_timing is on


def test_reports_name_the_leg_momentum_share_only_when_on() -> None:
    row = {"dv_m_s": 0.1, "phase": 0.2, "direction": "forward", "success": True, "fell": False}
    for share, shown in ((0.0, False), (0.5, True)):
        proto = PushProtocol(dv=(0.1,), phases=(0.2,), directions=("forward",), leg_momentum=share)
        res = ProtocolResult(proto, "flat_long", 20, 10, 30.0, [dict(row)])
        for text in (format_summary(res), format_markdown(res)):
            assert ("legs' momentum 0.5" in text) is shown
