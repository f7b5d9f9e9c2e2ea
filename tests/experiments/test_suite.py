"""The instance suite (footfall.experiments.suite): reading suite.json, agreement with a
certificate, running a tiny suite certified here with the planner itself, the ``footfall bench
plan --suite`` command, and the suite that benchmarks/make_suite.py writes."""

from __future__ import annotations

import copy
import importlib.util
import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from footfall.errors import InputError
from footfall.experiments.suite import (
    SUITE_FORMAT,
    SuiteInstance,
    SuiteRun,
    agrees_with,
    format_suite_table,
    instance_scene,
    load_suite,
    run_suite,
    solve_instance,
    suite_runs_to_dict,
)
from footfall.planning import PlannerOptions, plan_footsteps, reachable_steps_bound
from footfall.terrain.scene import scene_to_yaml
from footfall.terrain.suite_families import suite_terrain
from tests.cli import error_line, footfall

ROOT = Path(__file__).resolve().parents[2]
GAP = 1e-4
HEADING_SEGMENTS = 16
#: the optimum of stones-00 at N = 5 (bnb 1.6019312, SCIP 1.6019323 in benchmarks/make_suite.py's
#: certification): an anchor that does not come from this run
STONES_00_N5 = 1.60193


def _options(solver: str = "bnb") -> PlannerOptions:
    return PlannerOptions(
        solver=solver, time_limit=120.0, threads=1, gap=GAP, heading_segments=HEADING_SEGMENTS
    )


def _entry(name: str, family: str, seed: int, n: int, status: str, obj: Any, bound: Any) -> dict:  # type: ignore[type-arg]
    return {
        "name": name,
        "family": family,
        "seed": seed,
        "scene": f"scenes/{family}-{seed:02d}.yaml",
        "n_steps": n,
        "heading_segments": HEADING_SEGMENTS,
        "region_margin": 0.0,
        "status": status,
        "objective": obj,
        "bound": bound,
        "certificate": {},
    }


def _write_suite(folder: Path, instances: list[dict], gap: float = GAP) -> Path:  # type: ignore[type-arg]
    (folder / "scenes").mkdir(parents=True, exist_ok=True)
    for inst in instances:
        scene = suite_terrain(inst["family"], inst["seed"])
        (folder / inst["scene"]).write_text(scene_to_yaml(scene))
    doc = {"format": SUITE_FORMAT, "gap": gap, "instances": instances}
    (folder / "suite.json").write_text(json.dumps(doc, indent=2, allow_nan=False))
    return folder


@pytest.fixture(scope="module")
def certified(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """A tiny suite certified here by planning the generated scenes (not the files) with bnb:
    stones-00 at N = 5 (optimal) and stones-02 at N = 5 (infeasible)."""
    plans = {
        (seed, n): plan_footsteps(suite_terrain("stones", seed), n_steps=n, options=_options())
        for seed, n in ((0, 5), (2, 5))
    }
    opt, infeasible = plans[(0, 5)], plans[(2, 5)]
    assert opt.status.value == "optimal" and infeasible.status.value == "infeasible"
    assert opt.objective == pytest.approx(STONES_00_N5, rel=2e-4)
    instances = [
        _entry("stones-00-n05", "stones", 0, 5, "optimal", opt.objective, opt.bound),
        _entry("stones-02-n05", "stones", 2, 5, "infeasible", None, None),
    ]
    folder = _write_suite(tmp_path_factory.mktemp("suite") / "suite", instances)
    return {"folder": folder, "instances": instances, "objective": opt.objective}


def _perturbed(tmp: Path, certified: dict[str, Any], factor: float) -> Path:
    instances = copy.deepcopy(certified["instances"])
    instances[0]["objective"] *= factor
    instances[0]["bound"] = None
    return _write_suite(tmp / "perturbed", instances)


# --- load_suite ---------------------------------------------------------------------------------


def _valid_doc() -> dict[str, Any]:
    return {
        "format": 1,
        "gap": 1e-4,
        "instances": [
            _entry("stones-00-n05", "stones", 0, 5, "optimal", 1.6, 1.5999),
            _entry("stones-02-n05", "stones", 2, 5, "infeasible", None, None),
            _entry("gaps-01-n07", "gaps", 1, 7, "open", None, 1.2),
        ],
    }


def _load(tmp_path: Path, text: str) -> tuple[float, list[SuiteInstance]]:
    (tmp_path / "suite.json").write_text(text)
    return load_suite(tmp_path)


def test_load_suite_reads_a_valid_suite(tmp_path: Path) -> None:
    doc = _valid_doc()
    doc["instances"][0]["objective"] = 2  # an integer is a number
    doc["instances"][0]["certificate"] = {"bnb": {"status": "optimal", "objective": 2.0}}
    del doc["instances"][1]["region_margin"]  # 0 by default
    doc["instances"][2]["region_margin"] = 0.01
    gap, insts = _load(tmp_path, json.dumps(doc))
    assert gap == 1e-4 and isinstance(gap, float)
    assert [i.name for i in insts] == ["stones-00-n05", "stones-02-n05", "gaps-01-n07"]
    a, b, c = insts
    assert (a.status, a.objective, a.bound, a.n_steps, a.seed) == ("optimal", 2.0, 1.5999, 5, 0)
    assert isinstance(a.objective, float)
    assert a.certificate == {"bnb": {"status": "optimal", "objective": 2.0}}
    assert (b.status, b.objective, b.bound, b.region_margin) == ("infeasible", None, None, 0.0)
    assert (c.status, c.objective, c.bound, c.region_margin) == ("open", None, 1.2, 0.01)
    assert (a.scene, a.family, a.heading_segments) == ("scenes/stones-00.yaml", "stones", 16)
    # to_dict writes the fields suite.json holds: written back, they read the same
    doc2 = {"format": 1, "gap": gap, "instances": [i.to_dict() for i in insts]}
    _, again = _load(tmp_path, json.dumps(doc2, allow_nan=False))
    assert again == insts


def test_load_suite_refuses_a_folder_without_suite_json(tmp_path: Path) -> None:
    with pytest.raises(InputError) as err:
        load_suite(tmp_path)
    assert err.value.field == "suite" and err.value.value == str(tmp_path)
    (tmp_path / "suite.json").mkdir()  # a folder of that name is not the file
    with pytest.raises(InputError, match=r"suite\.json"):
        load_suite(tmp_path)


@pytest.mark.parametrize(
    "text", ['{"format": 1, "gap": 1e-4, "instances": [', "", "suite: yes", "{'format': 1}"]
)
def test_load_suite_refuses_text_that_is_not_json(tmp_path: Path, text: str) -> None:
    with pytest.raises(InputError) as err:
        _load(tmp_path, text)
    assert err.value.field == "suite"
    assert err.value.value == str(tmp_path / "suite.json") and "JSON" in err.value.expected


def test_load_suite_refuses_bytes_that_are_not_utf8(tmp_path: Path) -> None:
    (tmp_path / "suite.json").write_bytes(b'{"format": 1, "gap": "\xff"}')
    with pytest.raises(InputError) as err:
        load_suite(tmp_path)
    assert err.value.field == "suite" and "JSON" in err.value.expected


def _mutate(doc: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    """``doc`` with the value at ``path`` ("gap", "instances.1.scene") set, or deleted when
    ``value`` is ``...``."""
    keys = path.split(".")
    node: Any = doc
    for k in keys[:-1]:
        node = node[int(k)] if isinstance(node, list) else node[k]
    last: Any = int(keys[-1]) if isinstance(node, list) else keys[-1]
    if value is ...:
        del node[last]
    else:
        node[last] = value
    return doc


#: (where, value, field named by the error): a bad instance is put at index 1
BAD_FIELDS = [
    ("format", 2, ": format"),
    ("format", "1", ": format"),
    ("format", 0, ": format"),
    ("format", ..., ": format"),
    ("gap", -0.001, ": gap"),
    ("gap", 1.0, ": gap"),
    ("gap", 5, ": gap"),
    ("gap", "1e-4", ": gap"),
    ("gap", True, ": gap"),
    ("gap", None, ": gap"),
    ("gap", ..., ": gap"),
    ("instances", [], ": instances"),
    ("instances", {}, ": instances"),
    ("instances", ..., ": instances"),
    ("instances.1", "stones-02-n05", "instances[1]: instance"),
    ("instances.1.name", None, "instances[1]: name"),
    ("instances.1.name", ..., "instances[1]: name"),
    ("instances.1.seed", "2", "instances[1]: seed"),
    ("instances.1.seed", True, "instances[1]: seed"),
    ("instances.1.seed", 2.0, "instances[1]: seed"),
    ("instances.1.n_steps", 0, "instances[1]: n_steps"),
    ("instances.1.n_steps", 5.5, "instances[1]: n_steps"),
    ("instances.1.heading_segments", ..., "instances[1]: heading_segments"),
    ("instances.1.scene", "../stones-02.yaml", "instances[1]: scene"),
    ("instances.1.scene", "scenes/../../stones-02.yaml", "instances[1]: scene"),
    ("instances.1.scene", "/etc/passwd", "instances[1]: scene"),
    ("instances.1.scene", 3, "instances[1]: scene"),
    ("instances.1.status", "proven", "instances[1]: status"),
    ("instances.1.status", "Infeasible", "instances[1]: status"),
    ("instances.1.status", ..., "instances[1]: status"),
    ("instances.1.region_margin", "0", "instances[1]: region_margin"),
    ("instances.1.bound", True, "instances[1]: bound"),
    ("instances.1.objective", [1.0], "instances[1]: objective"),
    ("instances.1.certificate", [], "instances[1]: certificate"),
    ("instances.0.objective", None, "instances[0]: objective"),  # optimal without objective
    ("instances.0.objective", ..., "instances[0]: objective"),
]


@pytest.mark.parametrize(("where", "value", "field"), BAD_FIELDS)
def test_load_suite_refuses_a_bad_field(tmp_path: Path, where: str, value: Any, field: str) -> None:
    doc = _mutate(_valid_doc(), where, value)
    with pytest.raises(InputError) as err:
        _load(tmp_path, json.dumps(doc))
    index = str(tmp_path / "suite.json")
    assert err.value.field.startswith(index), err.value.field  # names the file
    assert err.value.field.endswith(field), err.value.field  # and the field
    assert str(err.value).startswith(f"{index}")


@pytest.mark.parametrize("key", ["objective", "bound", "region_margin"])
@pytest.mark.parametrize("token", ["NaN", "Infinity", "-Infinity", '"NaN"', '"inf"', "1e999"])
def test_load_suite_refuses_non_finite_numbers(tmp_path: Path, key: str, token: str) -> None:
    """Python's json reads the non-standard tokens NaN and Infinity (what ``json.dumps`` writes
    for ``float('nan')``) and 1e999 as inf: each is refused, as is a number written as a
    string."""
    doc = _valid_doc()
    doc["instances"][0][key] = "@@"
    text = json.dumps(doc).replace('"@@"', token)
    assert token in text
    with pytest.raises(InputError) as err:
        _load(tmp_path, text)
    assert err.value.field == f"{tmp_path / 'suite.json'} instances[0]: {key}"
    assert "finite" in err.value.expected


def test_load_suite_refuses_a_nan_gap(tmp_path: Path) -> None:
    text = json.dumps(_valid_doc()).replace('"gap": 0.0001', '"gap": NaN')
    assert "NaN" in text
    with pytest.raises(InputError) as err:
        _load(tmp_path, text)
    assert err.value.field.endswith("suite.json: gap")


def test_load_suite_refuses_duplicate_names(tmp_path: Path) -> None:
    doc = _valid_doc()
    doc["instances"][2]["name"] = "stones-00-n05"
    with pytest.raises(InputError) as err:
        _load(tmp_path, json.dumps(doc))
    assert err.value.field.endswith("suite.json: instances")
    assert err.value.value == ["stones-00-n05"] and "unique" in err.value.expected


def test_load_suite_refuses_an_oversized_index(tmp_path: Path) -> None:
    from footfall.experiments import suite as suite_mod

    doc = _valid_doc()
    doc["pad"] = " " * suite_mod.MAX_INDEX_BYTES
    with pytest.raises(InputError) as err:
        _load(tmp_path, json.dumps(doc))
    assert err.value.field == "suite" and "bytes" in err.value.expected


def test_load_suite_refuses_an_integer_too_large_for_a_float(tmp_path: Path) -> None:
    doc = _valid_doc()
    doc["instances"][0]["objective"] = 10**400
    with pytest.raises(InputError):
        _load(tmp_path, json.dumps(doc))


def test_load_suite_refuses_an_integer_of_too_many_digits(tmp_path: Path) -> None:
    text = json.dumps(_valid_doc()).replace('"seed": 0', '"seed": ' + "9" * 5000)
    with pytest.raises(InputError):
        _load(tmp_path, text)


def test_instance_scene_reads_the_file_and_names_a_missing_one(
    certified: dict[str, Any],
) -> None:
    folder = certified["folder"]
    _, insts = load_suite(folder)
    scene = instance_scene(folder, insts[0])
    assert scene_to_yaml(scene) == scene_to_yaml(suite_terrain("stones", 0))
    gone = replace(insts[0], scene="scenes/gone.yaml")
    with pytest.raises(InputError) as err:
        instance_scene(folder, gone)
    assert err.value.field == "instance stones-00-n05: scene"


# --- agrees_with ----------------------------------------------------------------------------------


def _inst(status: str, objective: float | None, bound: float | None) -> SuiteInstance:
    return SuiteInstance(
        name="x", family="stones", seed=0, scene="scenes/x.yaml", n_steps=5, heading_segments=16,
        region_margin=0.0, status=status, objective=objective, bound=bound,
    )  # fmt: skip


REF = 1.6
NAN, INF = math.nan, math.inf


@pytest.mark.parametrize(
    ("status", "objective", "bound", "gap", "agrees"),
    [
        ("optimal", REF, REF, GAP, True),
        ("optimal", REF * (1 + 1.9e-4), REF, GAP, True),  # within 2 gaps above
        ("optimal", REF * (1 - 1.9e-4), REF * (1 - 1.9e-4), GAP, True),  # and below
        ("optimal", REF * (1 + 2.1e-4), REF, GAP, False),
        ("optimal", REF * (1 - 2.1e-4), REF * (1 - 2.1e-4), GAP, False),
        ("optimal", REF * 1.01, REF * 1.01, GAP, False),
        ("optimal", REF, REF * (1 + 1.9e-4), GAP, True),  # a bound a little above
        ("optimal", REF, REF * (1 + 2.1e-4), GAP, False),  # a bound above the optimum
        ("optimal", REF + 1e-10, REF, 0.0, True),  # gap 0: equal up to 1e-9
        ("optimal", REF * (1 + 1e-6), REF, 0.0, False),
        ("optimal", REF * (1 + 0.9e-2), REF, 5e-3, True),  # the tolerance follows the gap
        ("optimal", NAN, REF, GAP, False),
        ("feasible", REF, REF * 0.9, GAP, False),  # a plan without proof is not the status
        ("time_limit", REF, REF * 0.9, GAP, False),
        ("infeasible", NAN, INF, GAP, False),
        ("error", NAN, NAN, GAP, False),
    ],
)
def test_agrees_with_an_optimal_instance(
    status: str, objective: float, bound: float, gap: float, agrees: bool
) -> None:
    assert agrees_with(_inst("optimal", REF, REF), status, objective, bound, gap) is agrees


def test_agrees_with_an_optimal_instance_of_objective_zero() -> None:
    inst = _inst("optimal", 0.0, 0.0)
    assert agrees_with(inst, "optimal", 5e-10, 0.0, GAP)
    assert not agrees_with(inst, "optimal", 1e-6, 0.0, GAP)


@pytest.mark.parametrize(
    ("status", "agrees"),
    [("infeasible", True), ("optimal", False), ("feasible", False), ("time_limit", False)],
)
def test_agrees_with_an_infeasible_instance(status: str, agrees: bool) -> None:
    inst = _inst("infeasible", None, None)
    objective = NAN if status in ("infeasible", "time_limit") else REF
    bound = INF if status == "infeasible" else REF
    assert agrees_with(inst, status, objective, bound, GAP) is agrees


@pytest.mark.parametrize(
    ("known", "status", "objective", "bound", "agrees"),
    [
        # a plan of objective 2.0 is known, the optimum is at least 1.5
        ((2.0, 1.5), "infeasible", NAN, INF, False),  # contradicts the known plan
        ((2.0, 1.5), "optimal", 1.8, 1.8, True),  # a better plan, proven
        ((2.0, 1.5), "optimal", 2.0, 2.0, True),
        ((2.0, 1.5), "time_limit", NAN, 1.6, True),  # nothing contradicts the bracket
        ((2.0, 1.5), "feasible", 2.2, 1.7, True),  # a worse plan is no contradiction
        ((2.0, 1.5), "optimal", 2.1, 2.1, False),  # a bound above the known plan
        ((2.0, 1.5), "time_limit", NAN, 2.0 * (1 + 1.9e-4), True),
        ((2.0, 1.5), "time_limit", NAN, 2.0 * (1 + 2.1e-4), False),
        ((2.0, 1.5), "time_limit", NAN, NAN, True),
        # no plan known: any proof agrees
        ((None, 1.5), "infeasible", NAN, INF, True),
        ((None, 1.5), "optimal", 9.0, 9.0, True),
        ((None, None), "infeasible", NAN, INF, True),
        ((None, None), "error", NAN, NAN, True),
    ],
)
def test_agrees_with_an_open_instance(
    known: tuple[float | None, float | None], status: str, objective: float, bound: float,
    agrees: bool,
) -> None:  # fmt: skip
    inst = _inst("open", *known)
    assert agrees_with(inst, status, objective, bound, GAP) is agrees


# --- run_suite on a tiny certified suite ------------------------------------------------------


@pytest.fixture(scope="module")
def runs(certified: dict[str, Any]) -> list[SuiteRun]:
    seen: list[str] = []
    out = run_suite(
        certified["folder"], solver="bnb", threads=1, progress=lambda r: seen.append(r.name)
    )
    assert seen == [r.name for r in out]  # one progress call per run, in order
    return out


def test_run_suite_agrees_with_the_certificate(
    certified: dict[str, Any], runs: list[SuiteRun]
) -> None:
    assert [r.name for r in runs] == ["stones-00-n05", "stones-02-n05"]
    opt, inf = runs
    assert opt.agrees and inf.agrees
    assert (opt.status, opt.certified, opt.solver, opt.family, opt.n_steps) == (
        "optimal", "optimal", "bnb", "stones", 5,
    )  # fmt: skip
    # planned from the scene file: the optimum of the generated scene
    assert opt.objective == pytest.approx(certified["objective"], rel=2 * GAP)
    assert opt.certified_objective == certified["objective"]
    assert opt.bound <= opt.objective * (1 + 1e-9) and 0.0 <= opt.gap <= GAP
    assert isinstance(opt.nodes, int) and opt.nodes >= 1
    assert (inf.status, inf.certified, inf.certified_objective) == (
        "infeasible",
        "infeasible",
        None,
    )
    assert math.isnan(inf.objective) and inf.bound == math.inf


def test_run_suite_selects_instances_by_name(certified: dict[str, Any]) -> None:
    only = run_suite(certified["folder"], threads=1, names=["stones-02-n05"])
    assert [(r.name, r.status, r.agrees) for r in only] == [("stones-02-n05", "infeasible", True)]
    with pytest.raises(InputError) as err:
        run_suite(certified["folder"], threads=1, names=["stones-02-n05", "nope"])
    assert err.value.field == "instances" and err.value.value == "nope"


@pytest.mark.parametrize("factor", [1.01, 0.99])
def test_run_suite_disagrees_with_a_perturbed_objective(
    tmp_path: Path, certified: dict[str, Any], factor: float
) -> None:
    folder = _perturbed(tmp_path, certified, factor)
    (run,) = run_suite(folder, solver="bnb", threads=1, names=["stones-00-n05"])
    assert run.status == "optimal" and not run.agrees
    assert run.certified_objective == pytest.approx(certified["objective"] * factor)


def test_run_suite_disagrees_when_infeasibility_is_certified_for_a_plan(
    tmp_path: Path, certified: dict[str, Any]
) -> None:
    instances = copy.deepcopy(certified["instances"])
    instances[0].update(status="infeasible", objective=None, bound=None)
    folder = _write_suite(tmp_path / "wrong", instances)
    (run,) = run_suite(folder, threads=1, names=["stones-00-n05"])
    assert run.status == "optimal" and not run.agrees


def test_format_suite_table(runs: list[SuiteRun]) -> None:
    table = format_suite_table(runs)
    lines = table.splitlines()
    assert lines[0].startswith("| instance | family | N | certified |")
    assert len(lines) == 2 + len(runs) + 2
    opt_row, inf_row = lines[2], lines[3]
    assert opt_row.startswith("| stones-00-n05 | stones | 5 | optimal | 1.60193 | bnb | optimal |")
    assert opt_row.endswith("| yes |")
    assert inf_row.startswith(
        "| stones-02-n05 | stones | 5 | infeasible | - | bnb | infeasible | - | - |"
    )
    assert inf_row.endswith("| yes |")
    assert lines[-1] == "2 of 2 agree with the certificate."
    # a run that disagrees is marked, and counted
    bad = [runs[0], replace(runs[1], agrees=False)]
    table = format_suite_table(bad)
    assert table.splitlines()[3].endswith("| **no** |")
    assert table.splitlines()[-1] == "1 of 2 agree with the certificate."
    assert format_suite_table([]).splitlines()[-1] == "0 of 0 agree with the certificate."


def test_suite_runs_to_dict_is_strict_json_after_json_ready(runs: list[SuiteRun]) -> None:
    from footfall._io import json_ready

    rows = suite_runs_to_dict(runs)
    assert [r["name"] for r in rows] == ["stones-00-n05", "stones-02-n05"]
    assert set(rows[0]) == set(SuiteRun.__dataclass_fields__)
    back = json.loads(json.dumps(json_ready(rows), allow_nan=False))
    assert back[1]["objective"] is None and back[1]["bound"] is None  # NaN, inf: null
    assert back[0]["objective"] == runs[0].objective and back[0]["agrees"] is True


@pytest.mark.slow
def test_scip_agrees_with_the_bnb_certificate(certified: dict[str, Any]) -> None:
    """A solver that shares no code with bnb reaches the certified optimum of stones-00, N = 5."""
    pytest.importorskip("pyscipopt")
    gap, insts = load_suite(certified["folder"])
    run = solve_instance(certified["folder"], insts[0], solver="scip", time_limit=120.0, gap=gap)
    assert run.solver == "scip" and run.status == "optimal" and run.agrees
    assert run.objective == pytest.approx(certified["objective"], rel=2 * GAP)
    assert run.objective == pytest.approx(STONES_00_N5, rel=2e-4)


# --- footfall bench plan --suite ------------------------------------------------------------------


def _bench(folder: Path, out: Path, *extra: str) -> Any:
    from typer.testing import CliRunner

    from footfall.cli import app

    args = ["bench", "plan", "--suite", str(folder), "--solver", "bnb", "--time-limit-fast", "120"]
    return CliRunner().invoke(app, [*args, "--fast-threads", "1", *extra, "--out", str(out)])


def _strict_json(path: Path) -> Any:
    return json.loads(
        path.read_text(), parse_constant=lambda c: pytest.fail(f"non-strict JSON token {c}")
    )


def test_cli_bench_suite_writes_json_and_table(tmp_path: Path, certified: dict[str, Any]) -> None:
    out = tmp_path / "out"
    res = _bench(certified["folder"], out, "--instances", "stones-00-n05,stones-02-n05")
    assert res.exit_code == 0, res.output
    doc = _strict_json(out / "bench_suite.json")
    assert doc["suite"] == str(certified["folder"]) and doc["gap"] == GAP
    assert [(r["name"], r["status"], r["agrees"]) for r in doc["runs"]] == [
        ("stones-00-n05", "optimal", True),
        ("stones-02-n05", "infeasible", True),
    ]
    assert doc["runs"][0]["objective"] == pytest.approx(certified["objective"], rel=2 * GAP)
    assert doc["runs"][1]["objective"] is None
    md = (out / "bench_suite.md").read_text()
    assert "| stones-00-n05 |" in md and "| stones-02-n05 |" in md
    assert "2 of 2 agree with the certificate." in md
    assert not (out / "bench_plan.json").exists()


def test_cli_bench_suite_exits_1_when_a_run_disagrees(
    tmp_path: Path, certified: dict[str, Any]
) -> None:
    folder = _perturbed(tmp_path, certified, 1.01)
    out = tmp_path / "out"
    res = _bench(folder, out, "--instances", "stones-00-n05")
    assert res.exit_code == 1, res.output
    assert "DISAGREES" in res.output
    doc = _strict_json(out / "bench_suite.json")
    assert [(r["name"], r["agrees"]) for r in doc["runs"]] == [("stones-00-n05", False)]
    assert "0 of 1 agree with the certificate." in (out / "bench_suite.md").read_text()


def test_cli_bench_suite_refuses_an_unknown_solver(
    tmp_path: Path, certified: dict[str, Any]
) -> None:
    out = tmp_path / "out"
    r = footfall("bench", "plan", "--suite", str(certified["folder"]), "--solver", "nope",
                 "--out", str(out))  # fmt: skip
    assert "nope" in error_line(r, "solver")
    assert not out.exists()


def test_cli_bench_suite_refuses_a_folder_without_suite_json(tmp_path: Path) -> None:
    out = tmp_path / "out"
    r = footfall("bench", "plan", "--suite", str(tmp_path), "--out", str(out))
    assert "suite.json" in error_line(r, "suite")
    assert not out.exists()


def test_cli_bench_suite_refuses_suite_and_horizon_together(
    tmp_path: Path, certified: dict[str, Any]
) -> None:
    out = tmp_path / "out"
    r = footfall("bench", "plan", "--suite", str(certified["folder"]), "--horizon", "3",
                 "--out", str(out))  # fmt: skip
    line = error_line(r, "suite")
    assert "horizon" in line
    assert not out.exists()


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        (["--time-limit-fast", "0"], "time_limit_fast"),
        (["--instances", "nope"], "instances"),
    ],
)
def test_cli_bench_suite_refuses_bad_options_in_process(
    tmp_path: Path, certified: dict[str, Any], extra: list[str], field: str
) -> None:
    res = _bench(certified["folder"], tmp_path / "out", *extra)
    assert isinstance(res.exception, InputError), res.output
    assert res.exception.field == field
    assert not (tmp_path / "out" / "bench_suite.json").exists()


def test_cli_bench_suite_refuses_a_bad_suite_before_writing(tmp_path: Path) -> None:
    doc = _valid_doc()
    doc["gap"] = 2.0
    _write_suite(tmp_path / "bad", doc["instances"], gap=2.0)
    out = tmp_path / "out"
    res = _bench(tmp_path / "bad", out)
    assert isinstance(res.exception, InputError), res.output
    assert res.exception.field.endswith("suite.json: gap")
    assert not out.exists()


# --- the suite benchmarks/make_suite.py writes ---------------------------------------------------


def _make_suite_module() -> Any:
    spec = importlib.util.spec_from_file_location(
        "make_suite", ROOT / "benchmarks" / "make_suite.py"
    )
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_make_suite_output_reads_and_runs(tmp_path: Path) -> None:
    """make_suite.py resumed from a certify.jsonl holding the records it needs (so it solves
    nothing) writes a suite that load_suite reads and run_suite agrees with: corridor-00 at
    N = 5, bnb's record and a second optimal one 0.5 gap above it."""
    ms = _make_suite_module()
    scene = suite_terrain("corridor", 0)
    n0 = reachable_steps_bound(scene, scene.robot, _options(), 20).n_steps
    assert n0 == 5  # else make_suite would solve other N (slowly)
    bnb = ms._solve(scene, n0, "bnb", 120.0)
    assert bnb["status"] == "optimal"
    scip = dict(bnb, objective=bnb["objective"] * (1 + 0.5 * GAP))
    rec = {"name": "corridor-00-n05", "family": "corridor", "seed": 0,
           "scene": "scenes/corridor-00.yaml", "n_steps": 5, "bnb": bnb, "scip": scip}  # fmt: skip
    (tmp_path / "certify.jsonl").write_text(json.dumps(rec) + "\n")
    assert ms.main(["--out", str(tmp_path), "--seeds", "0", "--families", "corridor"]) == 0
    _strict_json(tmp_path / "suite.json")
    gap, (inst,) = load_suite(tmp_path)
    assert gap == ms.GAP == GAP
    assert (inst.name, inst.status, inst.n_steps) == ("corridor-00-n05", "optimal", 5)
    assert (inst.heading_segments, inst.region_margin) == (HEADING_SEGMENTS, 0.0)
    assert inst.objective == bnb["objective"]  # the lower of the two
    # a record without "model" that is not a proof of infeasibility is labelled: past
    # plan_footsteps' checks SCIP got the whole model
    assert inst.certificate == {"bnb": bnb, "scip": {**scip, "model": "direct"}}
    assert (tmp_path / inst.scene).read_text() == scene_to_yaml(scene)
    (run,) = run_suite(tmp_path, threads=1)
    assert run.agrees and run.status == "optimal"
    # the same terrain as an open instance: agrees unless its known plan is below the optimum
    for objective, bound, agrees in ((None, 0.5 * inst.objective, True),
                                     (0.9 * inst.objective, None, False)):  # fmt: skip
        entry = _entry("corridor-00-n05", "corridor", 0, 5, "open", objective, bound)
        (run,) = run_suite(_write_suite(tmp_path / f"open{agrees}", [entry]), threads=1)
        assert (run.status, run.certified, run.agrees) == ("optimal", "open", agrees)


# --- the shipped suite --------------------------------------------------------------------------
SHIPPED = ROOT / "benchmarks" / "suite"


def test_the_shipped_suite_is_whole_and_its_certificates_hold_together() -> None:
    """benchmarks/suite: at least 30 certified instances in eight families; every scene file is
    the family generator's terrain; every certificate is two proven results that agree (the
    suite's rule recomputed here from the solvers' records, not read from ``status``)."""
    from footfall.terrain.suite_families import SUITE_FAMILIES

    gap, instances = load_suite(SHIPPED)
    certified = [i for i in instances if i.status in ("optimal", "infeasible")]
    assert len(certified) >= 30
    assert {i.family for i in instances} == set(SUITE_FAMILIES)
    for inst in instances:
        text = (SHIPPED / inst.scene).read_text(encoding="utf-8")
        assert text == scene_to_yaml(suite_terrain(inst.family, inst.seed)), inst.name
        bnb, scip = inst.certificate["bnb"], inst.certificate["scip"]
        assert scip["model"] == "direct", inst.name
        if inst.status == "infeasible":
            assert bnb["status"] == scip["status"] == "infeasible", inst.name
        elif inst.status == "optimal":
            assert bnb["status"] == scip["status"] == "optimal", inst.name
            a, b = bnb["objective"], scip["objective"]
            assert abs(a - b) <= 2 * gap * min(abs(a), abs(b)) + 1e-9, inst.name
            assert inst.objective == min(a, b)
        else:  # open: not two agreeing proofs
            assert not bnb["status"] == scip["status"] == "infeasible", inst.name
            if bnb["status"] == scip["status"] == "optimal":
                a, b = bnb["objective"], scip["objective"]
                assert abs(a - b) > 2 * gap * min(abs(a), abs(b)) + 1e-9, inst.name


def test_the_shipped_suite_solves_to_its_certificates() -> None:
    """The quickest certified instance of every family, solved again by bnb, agrees."""
    _, instances = load_suite(SHIPPED)
    quickest: dict[str, Any] = {}
    for inst in instances:
        if inst.status == "open":
            continue
        t = inst.certificate["bnb"]["time_s"] or 0.0
        if inst.family not in quickest or t < quickest[inst.family][0]:
            quickest[inst.family] = (t, inst.name)
    names = [name for _, name in quickest.values()]
    runs = run_suite(SHIPPED, solver="bnb", threads=1, names=names)
    assert len(runs) == len(quickest)
    assert all(r.agrees for r in runs), [r for r in runs if not r.agrees]
