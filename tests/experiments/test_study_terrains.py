"""A study across terrain families, end to end on the reduced-order loop: the generated terrains
become scene files beside the rows, the rows name them, the plans are the same made in one or
two processes, the report judges with the terrain as the unit, and `footfall view` finds each
trial's terrain (the statistics against hand values: test_terrain_stats.py)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from footfall.errors import InputError
from footfall.experiments.study import run_study
from footfall.experiments.study.design import study_from_dict
from footfall.experiments.study.report import write_report
from footfall.experiments.study.runner import make_plans, terrain_family, write_terrains
from footfall.terrain.families import family_terrain
from footfall.terrain.scene import load_scene, scene_to_yaml

#: one terrain of each family (seed 1: both plan in a few seconds), 2 seeds: 2 x 2 x 2 walks
DESIGN: dict[str, Any] = {
    "name": "terrains",
    "simulator": "reduced",
    "scenes": [],
    "families": ["discrete_steps", "stairs_slope_gap"],
    "terrains": 1,
    "terrain_start": 1,
    "planners": ["miqcqp", "reactive"],
    "steps": ["smallest"],
    "default_push": 2.0,
    "seeds": 2,
    "push_levels": [],
    "level_seeds": 0,
    "time_limit": 120.0,
}
NAMES = ["discrete_steps-t0001", "stairs_slope_gap-t0001"]


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> tuple[Any, Path, Any]:
    design = study_from_dict(DESIGN)
    out = tmp_path_factory.mktemp("terrain_study") / "s"
    run = run_study(design, out, workers=1)
    return design, out, run


def test_every_terrain_is_a_scene_file_beside_the_rows(study: tuple[Any, Path, Any]) -> None:
    design, out, _ = study
    files = sorted(p.name for p in (out / "terrains").iterdir())
    assert files == [f"{n}.yaml" for n in NAMES]
    for name, (family, seed) in zip(
        NAMES, [("discrete_steps", 1), ("stairs_slope_gap", 1)], strict=True
    ):
        text = (out / "terrains" / f"{name}.yaml").read_text()
        assert text == scene_to_yaml(family_terrain(family, seed))
        assert load_scene(out / "terrains" / f"{name}.yaml").name == name
    assert write_terrains(design, out) == 0  # the same files: nothing rewritten
    assert terrain_family(design) == dict(
        zip(NAMES, ["discrete_steps", "stairs_slope_gap"], strict=True)
    )


def test_rows_name_the_terrains_and_every_walk_ran(study: tuple[Any, Path, Any]) -> None:
    design, _, run = study
    assert run.trials == design.max_trials() == 2 * 2 * 2
    assert len(run.rows) == run.ran == run.trials
    assert sorted({r["scene"] for r in run.rows}) == NAMES
    assert all(r["error"] is None for r in run.rows)


def test_the_report_judges_with_the_terrain_as_the_unit(study: tuple[Any, Path, Any]) -> None:
    design, out, run = study
    summary, _ = write_report(out, design, run.rows, run.plans, ["header"])
    md = (out / "summary.md").read_text()
    assert "## Across terrain: the terrain is the unit" in md
    assert "### Verdict across terrain" in md
    assert (out / "terrain_paired.png").stat().st_size > 0
    assert not (out / "fragility.png").exists()  # no named scene: no per-scene figures
    data = json.loads((out / "summary.json").read_text())
    pairs = data["terrain_pairs"]
    assert [(p["family"], p["baseline"]) for p in pairs] == [
        ("discrete_steps", "reactive"),
        ("stairs_slope_gap", "reactive"),
    ]
    for p in pairs:  # one terrain per family: its seeds where both walks succeeded, by hand
        terrain = next(n for n in NAMES if n.startswith(p["family"]))
        ok = {(r["planner"], r["seed"]) for r in run.rows if r["scene"] == terrain and r["success"]}
        both = sum(("miqcqp", s) in ok and ("reactive", s) in ok for s in range(2))
        assert p["pairs"] == both
        assert p["terrains"] == (1 if both else 0)
    # one terrain cannot be judged, and the verdict says so rather than inventing a CI
    assert all("cannot be judged" in line for line in summary.family_verdict)
    assert len(summary.family_verdict) == 2


def test_plans_made_in_two_processes_are_the_same(
    study: tuple[Any, Path, Any], tmp_path: Path
) -> None:
    design, out, run = study
    two = make_plans(design, out / "plans", workers=2)  # served by the cache the run filled

    def key(entries: list[Any]) -> list[tuple[Any, ...]]:
        return [(e.scene, e.planner, e.mode, e.plan.status.value, e.plan.n_steps) for e in entries]

    assert key(two) == key(run.plans)
    for a, b in zip(two, run.plans, strict=True):
        assert a.plan.objective == b.plan.objective or (
            math.isnan(a.plan.objective) and math.isnan(b.plan.objective)
        )


def test_the_viewer_finds_each_trials_terrain(study: tuple[Any, Path, Any]) -> None:
    from footfall.viz.view.load import load_view

    _, out, run = study
    data = load_view(out)
    assert data.kind == "study"
    assert sorted(s.name for s in data.scenes) == NAMES
    assert len(data.trials) == len(run.rows)
    assert not any("not built in" in n for n in data.notes)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"families": [], "terrains": 0}, "scenes"),  # no scenes, no families: nothing to walk
        ({"terrains": 0}, "terrains"),
        ({"families": ["cinder_blocks"]}, "families[0]"),
        ({"families": ["discrete_steps", "discrete_steps"]}, "families[1]"),
        ({"families": "discrete_steps"}, "families"),
        ({"terrain_start": -1}, "terrain_start"),
        ({"terrain_start": 10**9 + 1}, "terrain_start"),
        ({"families": [], "scenes": ["flat"]}, "terrains"),  # terrains without a family
    ],
)
def test_bad_family_fields_name_their_field(change: dict[str, Any], field: str) -> None:
    with pytest.raises(InputError) as e:
        study_from_dict(DESIGN | change)
    assert e.value.field == field


def test_max_trials_counts_the_terrains() -> None:
    d = study_from_dict(DESIGN | {"terrains": 7, "scenes": ["flat"]})
    # (1 scene + 2 families x 7 terrains) x (1 horizon planner + the reactive) x 2 seeds
    assert d.max_trials() == (1 + 2 * 7) * 2 * 2


def test_summary_json_gives_every_plans_status_and_gap(study: tuple[Any, Path, Any]) -> None:
    design, out, run = study
    write_report(out, design, run.rows, run.plans, ["header"])
    data = json.loads((out / "summary.json").read_text())
    by = {(p["scene"], p["planner"], p["mode"]): p for p in data["plans"]}
    assert len(by) == len(run.plans)
    for e in run.plans:
        p = by[(e.scene, e.planner, e.mode)]
        assert p["status"] == e.plan.status.value
        gap = e.plan.gap
        assert p["gap"] == (gap if math.isfinite(gap) else None)


def test_the_shipped_terrain_study_is_served_by_its_own_plans(tmp_path: Path) -> None:
    """The plans shipped with benchmarks/study/section55_terrain serve its terrains (a change of
    a generator or of the plan cache key would silently re-plan and re-walk the study)."""
    import shutil

    from footfall.experiments.study.design import load_study
    from footfall.experiments.study.runner import _planner

    shipped = Path(__file__).parents[2] / "benchmarks" / "study" / "section55_terrain"
    design = load_study(shipped / "study.yaml")
    shutil.copytree(shipped / "plans", tmp_path / "plans")
    plan_for = _planner(design, tmp_path / "plans")
    for family in design.families:
        scene = family_terrain(family, 0)
        assert (shipped / "terrains" / f"{scene.name}.yaml").read_text() == scene_to_yaml(scene)
        for planner in design.planners:
            plan = plan_for(scene, planner, None, None)
            assert "loaded from cache" in plan.message, (scene.name, planner, plan.message)
