"""Sizes beyond the documented maxima are refused up front, before any work scales with them."""

from __future__ import annotations

import numpy as np
import pytest

from footfall.errors import InputError, SceneError
from footfall.models.biped import MAX_NODES, BipedParams
from footfall.planning import PlannerOptions, plan_footsteps
from footfall.planning.plan import MAX_HEADING_SEGMENTS, MAX_STEPS, available_cores
from footfall.planning.run import _search_note
from footfall.sim.reduced.closed_loop import MAX_CONTROL_RATE, SimOptions
from footfall.terrain import builtin_scene
from footfall.terrain.region import MAX_VERTICES, Region
from footfall.terrain.terrain import MAX_REGIONS, Terrain


def test_too_many_footsteps() -> None:
    with pytest.raises(InputError, match="n_steps"):
        plan_footsteps(builtin_scene("flat"), n_steps=MAX_STEPS + 1)


def test_too_many_nodes() -> None:
    with pytest.raises(InputError, match="n_nodes"):
        BipedParams(n_nodes=MAX_NODES + 1)
    assert BipedParams(n_nodes=MAX_NODES).n_nodes == MAX_NODES


def test_heading_segments_and_threads_are_bounded() -> None:
    with pytest.raises(InputError, match="heading_segments"):
        PlannerOptions(heading_segments=MAX_HEADING_SEGMENTS + 1)
    with pytest.raises(InputError, match="threads"):
        PlannerOptions(threads=available_cores() + 1)
    assert PlannerOptions(threads=available_cores()).threads == available_cores()


def test_too_many_regions_or_vertices() -> None:
    square = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]
    regions = [Region(f"r{i}", (0.0, 0.0, 1.0), 0.0, square) for i in range(MAX_REGIONS + 1)]
    with pytest.raises(SceneError, match="regions"):
        Terrain(tuple(regions))
    angles = np.linspace(0, 2 * np.pi, MAX_VERTICES + 2)[:-1]
    circle = np.c_[np.cos(angles), np.sin(angles)]
    with pytest.raises(SceneError, match="vertices"):
        Region("disc", (0.0, 0.0, 1.0), 0.0, circle)


def test_control_rate_is_bounded() -> None:
    with pytest.raises(InputError, match="control_rate"):
        SimOptions(control_rate=MAX_CONTROL_RATE * 10)


def test_min_steps_note_says_what_was_proven() -> None:
    proven = _search_note(
        10, 8, [{"n_steps": 8, "status": "infeasible"}, {"n_steps": 9, "status": "infeasible"}]
    )
    assert "proven infeasible: N = 8, 9" in proven and "10 is the smallest" in proven
    undecided = _search_note(
        10, 8, [{"n_steps": 8, "status": "infeasible"}, {"n_steps": 9, "status": "time_limit"}]
    )
    assert (
        "not decided: N = 9 (time_limit)" in undecided
        and "smallest" not in undecided.split(";")[-1].split(",")[0]
    )
    assert "fewer steps may exist" in undecided
    skipped = {"from": 6, "to": 7, "reason": "no footstep N - 1 can be the goal foot"}
    both = _search_note(10, 8, [{"n_steps": 8, "status": "infeasible"}], skipped)
    assert "N = 6..7 ruled out without a solve (no footstep N - 1 can be the goal foot)" in both
    assert "proven infeasible: N = 8" in both


def test_a_plan_with_a_nan_footstep_is_refused_at_construction() -> None:
    from dataclasses import replace

    from footfall.planning import make_plan

    plan = make_plan(builtin_scene("flat"), "kinematic", 8)
    feet = plan.footsteps.copy()
    feet[3, 0] = np.nan
    with pytest.raises(InputError, match=r"plan.footsteps\[3\]"):
        replace(plan, footsteps=feet)
    with pytest.raises(InputError, match=r"plan\.headings"):
        replace(plan, headings=plan.headings[:-1])


def test_quadruped_cycles_are_bounded() -> None:
    from footfall.quadruped.gait import MAX_CYCLES, GaitParams

    with pytest.raises(InputError, match="cycles"):
        GaitParams(slope=0.2, body_pitch=0.1, cycles=MAX_CYCLES + 1)
