"""The plan cache re-checks what it serves: an altered cached plan is discarded and made again."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from footfall.planning import PlannerOptions, check_plan, make_plan
from footfall.planning.cache import PlanCache, cached_plan, plan_key
from footfall.planning.plan import FootstepPlan
from tests.planning.scenes import SHORT_FLAT, scene

#: how far a tampered footstep is moved [m]: far off the 3 m x 2 m ground
TAMPER = 5.0


def test_a_valid_cached_plan_is_served(tmp_path: Path) -> None:
    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    made = cached_plan(sc, "miqcqp", 3, cache=cache)
    again = cached_plan(sc, "miqcqp", 3, cache=cache)
    assert "loaded from cache" in again.message
    np.testing.assert_array_equal(again.footsteps, made.footsteps)


def test_a_tampered_cached_plan_is_not_returned(tmp_path: Path) -> None:
    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    made = cached_plan(sc, "miqcqp", 3, cache=cache)
    (path,) = tmp_path.glob("plan-*.json")
    data = json.loads(path.read_text())
    data["footsteps"][2]["position"][0] += TAMPER
    path.write_text(json.dumps(data))
    again = cached_plan(sc, "miqcqp", 3, cache=cache)
    assert "loaded from cache" not in again.message
    assert "discarded" in again.message and "footstep 2" in again.message
    np.testing.assert_allclose(again.footsteps, made.footsteps, atol=1e-6)
    assert check_plan(again, sc).ok
    # the file was overwritten with the new plan: the next call is a clean hit
    third = cached_plan(sc, "miqcqp", 3, cache=cache)
    assert "loaded from cache" in third.message and "discarded" not in third.message


def _sideways(data: dict[str, Any]) -> str:
    data["footsteps"][2]["position"][1] += 0.5  # still on the ground, out of reach
    return "reach"


def _turned(data: dict[str, Any]) -> str:
    data["footsteps"][2]["heading"] += 3.0
    return "heading_rate"


def _alip(data: dict[str, Any]) -> str:
    data["alip"]["states"][1][1][2] *= 1.5
    return "dynamics"


@pytest.mark.parametrize("tamper", [_sideways, _turned, _alip])
def test_a_cached_plan_is_checked_in_full(tmp_path: Path, tamper) -> None:  # type: ignore[no-untyped-def]
    """Footsteps moved within their region, headings or ALIP states edited: the independent
    checker finds it, so the cache does too (before, only start, alternation and region)."""
    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    made = cached_plan(sc, "miqcqp", 3, cache=cache)
    (path,) = tmp_path.glob("plan-*.json")
    data = json.loads(path.read_text())
    kind = tamper(data)
    path.write_text(json.dumps(data))
    stored = FootstepPlan.from_dict(json.loads(path.read_text()), sc.robot)
    assert kind in check_plan(stored, sc).kinds()  # what `footfall check` says of the file
    again = cached_plan(sc, "miqcqp", 3, cache=cache)
    assert "loaded from cache" not in again.message and "discarded" in again.message
    np.testing.assert_allclose(again.footsteps, made.footsteps, atol=1e-6)


def test_a_kinematic_plan_over_the_torque_limit_is_served(tmp_path: Path) -> None:
    """The kinematic planner has no torque bound: its cached plans keep being served."""
    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    robot = replace(sc.robot, u_max=1.0)
    made = cached_plan(sc, "kinematic", 3, cache=cache, robot=robot)
    assert check_plan(made, sc, robot).kinds() == {"torque"}
    again = cached_plan(sc, "kinematic", 3, cache=cache, robot=robot)
    assert "loaded from cache" in again.message


def test_a_cached_plan_with_another_n_is_not_used(tmp_path: Path) -> None:
    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    three = make_plan(sc, "miqcqp", 3)
    cache.save(plan_key(sc, "miqcqp", 4, PlannerOptions()), three, sc.name)
    four = cached_plan(sc, "miqcqp", 4, cache=cache)
    assert four.n_steps == 4 and "discarded" in four.message
    assert "loaded from cache" not in four.message


def test_a_scene_name_never_reaches_a_path(tmp_path: Path) -> None:
    from dataclasses import replace

    plans = tmp_path / "out" / "plans"
    sc = replace(scene(SHORT_FLAT), name="../../../escaped")
    cached_plan(sc, "miqcqp", 3, cache=PlanCache(plans))
    written = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert written and all(p.parent == plans for p in written), written
    assert all(p.name.startswith("plan-") and p.suffix == ".json" for p in written)


def test_an_edited_scene_of_the_same_name_is_planned_again(tmp_path: Path) -> None:
    from dataclasses import replace

    cache = PlanCache(tmp_path)
    sc = scene(SHORT_FLAT)
    cached_plan(sc, "miqcqp", 3, cache=cache)
    moved = replace(sc, goal=replace(sc.goal, position=sc.goal.position + np.array([0.05, 0, 0])))
    again = cached_plan(moved, "miqcqp", 3, cache=cache)
    assert "loaded from cache" not in again.message
    assert len(list(tmp_path.glob("plan-*.json"))) == 2


def test_a_cache_file_that_is_not_json_is_planned_again(tmp_path: Path) -> None:
    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    made = cached_plan(sc, "miqcqp", 3, cache=cache)
    path = cache.path(plan_key(sc, "miqcqp", 3, PlannerOptions(), sc.robot))
    path.write_text("{ not json")
    again = cached_plan(sc, "miqcqp", 3, cache=cache)
    assert "discarded" in again.message
    np.testing.assert_allclose(again.footsteps, made.footsteps)
    assert json.loads(path.read_text())["status"] == made.status.value


def test_a_planner_revision_makes_its_old_entries_miss(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A planner whose algorithm changed (its revision bumped) gets new keys; the others keep
    theirs, so their (possibly minutes-long) plans stay served."""
    from footfall.planning import cache as cache_mod

    sc, opts = scene(SHORT_FLAT), PlannerOptions()
    before = {p: plan_key(sc, p, None, opts) for p in ("reactive", "miqcqp")}
    monkeypatch.setitem(cache_mod.PLANNER_REVISION, "reactive", 99)
    assert plan_key(sc, "reactive", None, opts) != before["reactive"]
    assert plan_key(sc, "miqcqp", None, opts) == before["miqcqp"]
    monkeypatch.setitem(cache_mod.PLANNER_REVISION, "reactive", 1)
    unrevised = plan_key(sc, "reactive", None, opts)
    monkeypatch.setitem(cache_mod.PLANNER_REVISION, "reactive", 2)
    assert plan_key(sc, "reactive", None, opts) != unrevised


def test_the_shipped_study_plans_are_still_cache_hits(tmp_path: Path) -> None:
    """The section 5.5 study's plans ship in the repository (minutes of planning each); a new
    planner option or search setting must not silently turn them into misses for the study."""
    import shutil

    from footfall.experiments.study import builtin_study
    from footfall.experiments.study.runner import _planner
    from footfall.terrain import builtin_scene

    design = builtin_study("section55")
    shipped = Path(__file__).parents[2] / "benchmarks" / "study" / "section55" / "plans"
    shutil.copytree(shipped, tmp_path / "plans")
    plan_for = _planner(design, tmp_path / "plans")
    for name in design.scenes:
        for planner in design.planners:
            plan = plan_for(builtin_scene(name), planner, None, None)
            assert "loaded from cache" in plan.message, (name, planner, plan.message)


def test_search_switches_leave_the_key_alone_other_settings_change_it() -> None:
    import dataclasses

    from footfall.planning import cache as cache_mod
    from footfall.solvers.settings import BnbSettings

    sc, opts = scene(SHORT_FLAT), PlannerOptions()
    key = plan_key(sc, "miqcqp", None, opts)
    for name in cache_mod.KEY_NEUTRAL_BNB:
        flipped = BnbSettings(**{name: not getattr(BnbSettings(), name)})
        assert plan_key(sc, "miqcqp", None, dataclasses.replace(opts, bnb=flipped)) == key
    other = dataclasses.replace(opts, bnb=BnbSettings(probe_rounds=0))
    assert plan_key(sc, "miqcqp", None, other) != key


def test_a_cache_file_path_that_is_a_folder_is_refused_before_planning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from footfall.errors import InputError
    from footfall.planning import cache as cache_mod

    sc, cache = scene(SHORT_FLAT), PlanCache(tmp_path)
    cache.path(plan_key(sc, "miqcqp", 3, PlannerOptions(), sc.robot)).mkdir()
    planned: list[int] = []
    monkeypatch.setattr(cache_mod, "make_plan", lambda *a, **k: planned.append(1))
    with pytest.raises(InputError) as e:
        cached_plan(sc, "miqcqp", 3, cache=cache)
    assert e.value.field == "plan cache file" and planned == []


def test_a_plan_that_cannot_be_cached_is_still_returned(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A full disk when the plan is stored: the plan (minutes of planning) is returned, its
    message says it was not cached."""
    import errno

    def full(*args: object, **kwargs: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(PlanCache, "save", full)
    plan = cached_plan(scene(SHORT_FLAT), "miqcqp", 3, cache=PlanCache(tmp_path))
    assert plan.has_solution and "not cached" in plan.message and "No space" in plan.message
