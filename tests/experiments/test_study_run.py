"""`footfall study` (issue 25) walking tiny reduced-order studies on the `flat` scene: resume,
the paired disturbance, errors recorded as rows, executors, and the command line."""

from __future__ import annotations

import math
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import yaml

import footfall
from footfall.experiments.study import COLUMNS, StudyDesign, run_study
from footfall.experiments.study import trials as trials_mod
from footfall.experiments.study.design import study_from_dict
from footfall.experiments.study.runner import make_plans, make_trials
from footfall.experiments.study.trials import RUN_DEPENDENT
from footfall.sim.disturbance import Disturbance

SRC = str(Path(footfall.__file__).resolve().parents[1])

#: the study of most tests: 2 planners x (3 seeds at 4 N s + 2 seeds at 0 N s) = 10 walks
DESIGN: dict[str, Any] = {
    "name": "tiny",
    "simulator": "reduced",
    "scenes": ["flat"],
    "planners": ["miqcqp", "reactive"],
    "steps": ["smallest"],
    "default_push": 4.0,
    "seeds": 3,
    "push_levels": [0.0],
    "level_seeds": 2,
    "initial_impulse": 0.5,
    "time_limit": 60.0,
}
N_WALKS = 10


def _design(**kw: Any) -> StudyDesign:
    return study_from_dict(DESIGN | kw)


@pytest.fixture(scope="module")
def plans(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The plans of every study here, made once (copied into each study folder's plans/)."""
    folder = tmp_path_factory.mktemp("study_plans") / "plans"
    make_plans(_design(planners=["miqcqp", "kinematic", "reactive"]), folder)
    assert any(folder.iterdir())
    return folder


def _out(tmp: Path, plans: Path, name: str) -> Path:
    out = tmp / name
    shutil.copytree(plans, out / "plans")
    return out


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory, plans: Path) -> Any:
    """One uninterrupted run of ``DESIGN`` on one local worker."""
    out = _out(tmp_path_factory.mktemp("study_ref"), plans, "ref")
    return run_study(_design(), out, workers=1)


def _comparable(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Rows without the run-dependent columns, NaN replaced by a marker (NaN != NaN)."""
    out = []
    for r in rows:
        out.append(
            {
                k: ("nan" if isinstance(v, float) and math.isnan(v) else v)
                for k, v in r.items()
                if k not in RUN_DEPENDENT
            }
        )
    return sorted(out, key=lambda r: r["key"])


def test_reference_run_is_complete_and_sane(reference: Any) -> None:
    assert reference.trials == reference.ran == len(reference.rows) == N_WALKS
    assert _design().max_trials() == N_WALKS
    assert all(r["error"] is None for r in reference.rows)
    assert all(r["success"] is True for r in reference.rows)
    assert all(r["zmp_offset_mean"] > 0 for r in reference.rows)
    assert sorted({(r["planner"], r["push_impulse"]) for r in reference.rows}) == [
        ("miqcqp", 0.0),
        ("miqcqp", 4.0),
        ("reactive", 0.0),
        ("reactive", 4.0),
    ]
    # the unpushed walks have no push direction
    for r in reference.rows:
        assert math.isnan(r["push_direction"]) == (r["push_impulse"] == 0.0)


def test_interrupt_and_resume_equals_an_uninterrupted_run(
    tmp_path: Path, plans: Path, reference: Any
) -> None:
    out = _out(tmp_path, plans, "resumed")
    first = run_study(_design(), out, workers=1, limit=4)
    assert (first.ran, len(first.rows), first.trials) == (4, 4, N_WALKS)
    assert (out / "trials.parquet").is_file() and not (out / "trials.parts").exists()
    second = run_study(_design(), out, workers=1)
    assert second.ran == N_WALKS - 4  # the four finished walks are skipped
    assert _comparable(second.rows) == _comparable(reference.rows)
    third = run_study(_design(), out, workers=1)
    assert third.ran == 0 and _comparable(third.rows) == _comparable(reference.rows)

    import pyarrow.parquet as pq

    table = pq.read_table(out / "trials.parquet")
    assert table.column_names == [c for c, _ in COLUMNS]
    assert table.num_rows == N_WALKS
    # what is on disk is what the run returned
    assert _comparable(table.to_pylist()) == _comparable(reference.rows)


def test_paired_design_same_disturbance_for_every_planner(reference: Any) -> None:
    robots = {e.planner: e.plan.robot for e in reference.plans}
    n = {e.planner: e.plan.n_steps for e in reference.plans}
    assert n["miqcqp"] != n["reactive"]  # the pairing must hold across different N
    by_seed: dict[tuple[int, float], dict[str, dict[str, Any]]] = {}
    for r in reference.rows:
        by_seed.setdefault((r["seed"], r["push_impulse"]), {})[r["planner"]] = r
    assert len(by_seed) == 5
    for (seed, impulse), rs in by_seed.items():
        assert set(rs) == {"miqcqp", "reactive"}
        d = Disturbance.of_seed(seed)
        phases = []
        for planner, r in rs.items():
            robot = robots[planner]
            assert r["n_steps"] == n[planner]
            assert r["push_step"] <= d.step_fraction * n[planner] < r["push_step"] + 1
            phase = (r["push_time"] - r["push_step"] * (robot.t_ss + robot.t_ds)) / robot.t_ss
            phases.append(phase)
        assert phases[0] == pytest.approx(phases[1], abs=1e-9)
        assert phases[0] == pytest.approx(d.phase, abs=1e-9)
        if impulse > 0:
            dirs = {r["push_direction"] for r in rs.values()}
            assert dirs == {d.direction}
    # different seeds are disturbed differently
    assert len({r["push_direction"] for r in reference.rows if r["push_impulse"] > 0}) == 3


def _raise_on_seed(monkeypatch: pytest.MonkeyPatch, seed: int) -> None:
    real = trials_mod.run_plant

    def flaky(plant: Any, scene: Any, plan: Any, disturbance: Disturbance) -> Any:
        if disturbance.seed == seed:
            raise RuntimeError(f"boom on seed {seed}")
        return real(plant, scene, plan, disturbance)

    monkeypatch.setattr(trials_mod, "run_plant", flaky)


def test_a_trial_that_raises_is_recorded_with_its_error(
    tmp_path: Path, plans: Path, reference: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    _raise_on_seed(monkeypatch, 1)
    out = _out(tmp_path, plans, "err")
    run = run_study(_design(), out, workers=1)
    assert len(run.rows) == run.trials == N_WALKS
    bad = [r for r in run.rows if r["error"] is not None]
    assert sorted((r["planner"], r["push_impulse"]) for r in bad) == [
        ("miqcqp", 0.0),
        ("miqcqp", 4.0),
        ("reactive", 0.0),
        ("reactive", 4.0),
    ]
    for r in bad:
        assert r["seed"] == 1
        assert "RuntimeError" in r["error"] and "boom on seed 1" in r["error"]
        assert r["success"] is None and math.isnan(r["zmp_offset_mean"])
    good = [r for r in run.rows if r["error"] is None]
    ref = [r for r in reference.rows if r["seed"] != 1]
    assert _comparable(good) == _comparable(ref)
    # the error rows are on disk too, and a rerun does not repeat them
    assert run_study(_design(), out, workers=1).ran == 0


def test_adding_a_step_mode_flags_the_walks_already_in_the_folder(
    tmp_path: Path, plans: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A study may grow its step modes in the same folder; a walk already run at the smallest N
    that is also the equal-N walk (smallest N = the reactive walk's N) must count in both."""
    from footfall.experiments.study import runner
    from footfall.experiments.study.stats import paired

    real = runner.make_plans

    def same_n(
        design: StudyDesign,
        folder: Path,
        say: Any = None,
        monitor_for: Any = None,
        workers: int = 1,
    ) -> list[Any]:
        # a scene where the horizon planner's smallest N is the reactive walk's N: make_plans
        # then reuses the smallest-N plan as the equal-N plan
        out = [e for e in real(design, folder, say, monitor_for, workers) if e.mode != "equal"]
        if "equal" in design.steps:
            out += [replace(e, mode="equal", plan_time=0.0) for e in out if e.mode == "smallest"]
        return out

    monkeypatch.setattr(runner, "make_plans", same_n)
    out = _out(tmp_path, plans, "grow")
    small = {"push_levels": [], "level_seeds": 0}
    first = run_study(_design(steps=["smallest"], **small), out, workers=1)
    assert first.ran == 6
    grown = run_study(_design(steps=["smallest", "equal"], **small), out, workers=1)
    assert grown.ran == 0  # nothing new to walk: the equal-N walks are the smallest-N walks
    fresh = run_study(
        _design(steps=["smallest", "equal"], **small), _out(tmp_path, plans, "fresh"), workers=1
    )
    assert all(r["equal_n"] and r["smallest_n"] for r in fresh.rows)
    assert _comparable(grown.rows) == _comparable(fresh.rows)
    p = paired(grown.rows, "flat", "equal", 4.0, "miqcqp", "reactive")
    assert p.seeds == 3


def _main(monkeypatch: pytest.MonkeyPatch, *args: str) -> int:
    """``footfall ARGS`` in this process (so a monkeypatch reaches the walks); its exit code."""
    from footfall.cli import main

    monkeypatch.setattr(sys, "argv", ["footfall", *args])
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        main()
        return 0
    except SystemExit as e:
        return int(e.code or 0)
    finally:
        for s, h in handlers.items():
            signal.signal(s, h)


def test_cli_exits_1_when_a_walk_raised(
    tmp_path: Path, plans: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    _raise_on_seed(monkeypatch, 2)
    out = _out(tmp_path, plans, "cli_err")
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(DESIGN))
    code = _main(monkeypatch, "study", str(f), "--out", str(out), "--workers", "1", "--quiet")
    err = capsys.readouterr().err
    assert code == 1, err
    assert "2 walk(s) raised an error" in err, err  # seed 2: only at the default push
    assert "Traceback" not in err
    assert "2 raised an error" in (out / "summary.md").read_text()
    assert (out / "trials.parquet").is_file()


def test_local_pool_of_two_workers_gives_the_same_rows(
    tmp_path: Path, plans: Path, reference: Any
) -> None:
    out = _out(tmp_path, plans, "pool")
    run = run_study(_design(), out, executor="local", workers=2)
    assert run.ran == N_WALKS
    assert _comparable(run.rows) == _comparable(reference.rows)


@pytest.fixture
def ray_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    ray = pytest.importorskip("ray")
    # Ray's workers import footfall from this source tree, single-threaded
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([SRC, os.environ.get("PYTHONPATH", "")]))
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")
    try:
        yield ray
    finally:
        if ray.is_initialized():
            ray.shutdown()


@pytest.mark.slow
def test_ray_executor_gives_the_same_rows(
    tmp_path: Path, plans: Path, reference: Any, ray_env: Any
) -> None:
    out = _out(tmp_path, plans, "ray")
    design = _design(push_levels=[], level_seeds=0)  # 6 walks: Ray's start-up dominates anyway
    run = run_study(design, out, executor="ray", workers=2)
    assert run.ran == 6
    assert not ray_env.is_initialized()  # the executor shuts down the Ray it started
    ref = [r for r in reference.rows if r["push_impulse"] == 4.0]
    assert _comparable(run.rows) == _comparable(ref)


# ---------------------------------------------------------------------------------------------
# the command line (a separate process, as a user runs it)


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    env = os.environ | {"PYTHONPATH": SRC, "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )


def test_cli_refuses_a_file_and_quick_together(tmp_path: Path) -> None:
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(DESIGN))
    r = _cli("study", str(f), "--quick", "--out", str(tmp_path / "o"))
    assert r.returncode == 2, r.stdout + r.stderr
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and "--quick" in lines[0], r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "o" / "trials.parquet").exists()


def test_cli_names_the_bad_field_of_a_study_file(tmp_path: Path) -> None:
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(DESIGN | {"planners": ["miqcqp", "astar"]}))
    r = _cli("study", str(f), "--out", str(tmp_path / "o"))
    assert r.returncode == 2, r.stdout + r.stderr
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and "planners[1]" in lines[0] and "astar" in lines[0], r.stderr


def test_cli_writes_the_table_the_summary_and_the_figures(tmp_path: Path, plans: Path) -> None:
    out = _out(tmp_path, plans, "cli")
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(DESIGN | {"planners": ["miqcqp", "kinematic"]}))
    r = _cli("study", str(f), "--out", str(out), "--workers", "1", "--quiet")
    assert r.returncode == 0, r.stdout + r.stderr
    import pyarrow.parquet as pq

    assert pq.read_table(out / "trials.parquet").num_rows == N_WALKS
    md = (out / "summary.md").read_text()
    assert "Verdict" in md and "miqcqp - kinematic" in md
    assert (out / "fragility.png").stat().st_size > 0
    assert (out / "summary.json").is_file() and (out / "cells.csv").is_file()


def test_rows_of_a_plan_that_changed_are_walked_again(
    tmp_path: Path, plans: Path, reference: Any
) -> None:
    """A row records the digest of the plan it walked. When a planner makes another plan (here:
    the reactive rows claim another plan; a table from before the column existed has none), the
    rerun walks exactly those trials again and the table ends as the uninterrupted run's."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = _out(tmp_path, plans, "stale")
    run_study(_design(), out, workers=1)
    table = pq.read_table(out / "trials.parquet")
    rows = table.to_pylist()
    n_reactive = sum(r["planner"] == "reactive" for r in rows)
    assert 0 < n_reactive < len(rows)
    assert all(isinstance(r["plan"], str) and len(r["plan"]) == 16 for r in rows)
    for r in rows:
        if r["planner"] == "reactive":
            r["plan"] = "0" * 16
            r["success"] = not r["success"]  # a stale row's numbers must not survive
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), out / "trials.parquet")
    lines: list[str] = []
    stale = run_study(_design(), out, workers=1, limit=1, say=lines.append)
    assert stale.ran == 1 and any(f"{n_reactive} walk(s)" in s for s in lines)
    # the rows still stale are not reported
    assert len(stale.rows) == len(rows) - n_reactive + 1
    again = run_study(_design(), out, workers=1)
    assert again.ran == n_reactive - 1
    assert _comparable(again.rows) == _comparable(reference.rows)
    # a table without the plan column (written before it existed) is read; its rows are rerun
    pq.write_table(table.drop(["plan"]), out / "trials.parquet")
    old = run_study(_design(), out, workers=1)
    assert old.ran == N_WALKS
    assert _comparable(old.rows) == _comparable(reference.rows)


@pytest.mark.parametrize("mode", ["off", "planned", "nearby"])
def test_region_aware_reaches_the_walker(
    mode: str, plans: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The study's ``region_aware`` is the option the reduced-order walker runs with."""
    from footfall.sim.reduced import trial as reduced_trial

    seen: list[str] = []
    real = reduced_trial.simulate

    def spy(plan, opts, **kw):  # type: ignore[no-untyped-def]
        seen.append(opts.region_aware)
        return real(plan, opts, **kw)

    monkeypatch.setattr(reduced_trial, "simulate", spy)
    design = _design(region_aware=mode, planners=["miqcqp"], push_levels=[], level_seeds=0)
    entries = make_plans(design, plans)
    rows = [trials_mod.run_trial(t) for t in make_trials(design, entries)[:1]]
    assert seen == [mode] and rows[0]["error"] is None
