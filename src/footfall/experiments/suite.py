"""The footstep-planning instance suite: footstep MIQCQPs with certified optima, and a runner.

A suite is a folder (the shipped one is ``benchmarks/suite``; its README documents the format):

* ``suite.json``: ``{"format": 1, "gap": g, "instances": [...]}``; each instance names its
  ``scene`` file (relative to the folder), its family and seed, ``n_steps`` (N), the planner
  options that define the model (``heading_segments``, ``region_margin``) and what was proven:
  ``status`` (``optimal``, ``infeasible`` or ``open``), ``objective`` and ``bound``, and per
  solver of the certificate its status, objective, bound and time.
* ``scenes/NAME.yaml``: footfall scene files (start, goal, robot, convex regions).

The model of an instance is :func:`footfall.planning.build_footstep_problem` of the scene with
N and those options (document 000, eq. 5.11-5.18). An instance is *certified* when two solvers
that share no code (footfall's ``bnb`` and SCIP on the same model) both end proven: both optimal
with objectives within the relative gap of each other (the certified objective is the lower one,
the bound the higher of their bounds), or both infeasible. Otherwise it is ``open``, with the
best bound and objective found.

:func:`run_suite` solves every instance with any backend and compares with the certificate;
``footfall bench plan --suite DIR`` is its command.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from footfall.errors import InputError
from footfall.terrain.scene import Scene

#: the suite format this code reads and writes
SUITE_FORMAT = 1
#: largest suite.json read [bytes]
MAX_INDEX_BYTES = 2_000_000
STATUSES = ("optimal", "infeasible", "open")


@dataclass(frozen=True)
class SuiteInstance:
    """One instance of a suite (fields as in ``suite.json``)."""

    name: str
    family: str
    seed: int
    scene: str
    n_steps: int
    heading_segments: int
    region_margin: float
    status: str
    objective: float | None
    bound: float | None
    certificate: dict[str, dict[str, Any]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "family": self.family,
            "seed": self.seed,
            "scene": self.scene,
            "n_steps": self.n_steps,
            "heading_segments": self.heading_segments,
            "region_margin": self.region_margin,
            "status": self.status,
            "objective": self.objective,
            "bound": self.bound,
            "certificate": self.certificate,
        }


def _bad(where: str, fld: str, value: object, expected: str) -> InputError:
    return InputError(f"{where}: {fld}", value, expected)


def _instance(data: object, i: int, source: str) -> SuiteInstance:
    where = f"{source} instances[{i}]"
    if not isinstance(data, dict):
        raise _bad(where, "instance", data, "an object")
    need = {
        "name": str, "family": str, "seed": int, "scene": str, "n_steps": int,
        "heading_segments": int, "status": str,
    }  # fmt: skip
    for key, typ in need.items():
        v = data.get(key)
        if not isinstance(v, typ) or isinstance(v, bool):
            raise _bad(where, key, v, f"a {typ.__name__}")
        if isinstance(v, str) and not v.strip():
            raise _bad(where, key, v, "a non-empty string")
    if data["seed"] < 0:
        raise _bad(where, "seed", data["seed"], "an integer >= 0")
    if data["heading_segments"] < 4:
        raise _bad(where, "heading_segments", data["heading_segments"], "an integer >= 4")
    if data["status"] not in STATUSES:
        raise _bad(where, "status", data["status"], f"one of {', '.join(STATUSES)}")
    scene = data["scene"]
    if Path(scene).is_absolute() or ".." in Path(scene).parts:
        raise _bad(where, "scene", scene, "a path inside the suite folder")
    if data["n_steps"] < 1:
        raise _bad(where, "n_steps", data["n_steps"], "an integer >= 1")
    nums: dict[str, float | None] = {}
    for key in ("objective", "bound", "region_margin"):
        v = data.get(key, 0.0 if key == "region_margin" else None)
        if v is not None:
            try:
                ok = not isinstance(v, bool) and isinstance(v, int | float) and math.isfinite(v)
            except OverflowError:  # an integer beyond any float
                ok = False
            if not ok:
                raise _bad(where, key, v, "a finite number or null")
        nums[key] = None if v is None else float(v)
    if (nums["region_margin"] or 0.0) < 0.0:
        raise _bad(where, "region_margin", nums["region_margin"], "a distance >= 0 [m]")
    if data["status"] == "optimal" and nums["objective"] is None:
        raise _bad(where, "objective", None, "a number for an optimal instance")
    cert = data.get("certificate", {})
    if not isinstance(cert, dict):
        raise _bad(where, "certificate", cert, "an object")
    return SuiteInstance(
        name=data["name"],
        family=data["family"],
        seed=data["seed"],
        scene=scene,
        n_steps=data["n_steps"],
        heading_segments=data["heading_segments"],
        region_margin=float(nums["region_margin"] or 0.0),
        status=data["status"],
        objective=nums["objective"],
        bound=nums["bound"],
        certificate=cert,
    )


def load_suite(folder: Path) -> tuple[float, list[SuiteInstance]]:
    """The gap and instances of the suite in ``folder`` (errors name the file and field)."""
    folder = Path(folder)
    index = folder / "suite.json"
    if not index.is_file():
        raise InputError("suite", str(folder), "a folder holding suite.json")
    if index.stat().st_size > MAX_INDEX_BYTES:
        raise InputError("suite", str(index), f"a suite.json of at most {MAX_INDEX_BYTES} bytes")
    try:
        data = json.loads(index.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError, or an integer too long
        raise InputError("suite", str(index), f"JSON ({exc})") from None
    fmt = data.get("format") if isinstance(data, dict) else None
    if not isinstance(fmt, int) or isinstance(fmt, bool) or fmt != SUITE_FORMAT:
        raise InputError(
            f"{index}: format",
            data.get("format") if isinstance(data, dict) else data,
            f"{SUITE_FORMAT}",
        )
    gap = data.get("gap")
    if isinstance(gap, bool) or not isinstance(gap, int | float) or not 0 <= gap < 1:
        raise InputError(f"{index}: gap", gap, "a relative gap in [0, 1)")
    items = data.get("instances")
    if not isinstance(items, list) or not items:
        raise InputError(f"{index}: instances", items, "a non-empty list")
    out = [_instance(d, i, str(index)) for i, d in enumerate(items)]
    names = [x.name for x in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"{index}: instances", dup, "unique instance names")
    return float(gap), out


def instance_scene(folder: Path, inst: SuiteInstance) -> Scene:
    """The scene of ``inst`` (its file is read as YAML data: nothing in it can run code)."""
    from footfall.terrain.scene import load_scene

    path = Path(folder) / inst.scene
    if not path.is_file():
        raise InputError(f"instance {inst.name}: scene", str(path), "an existing scene file")
    return load_scene(path)


@dataclass(frozen=True)
class SuiteRun:
    """One instance solved by one solver, against its certificate."""

    name: str
    family: str
    n_steps: int
    solver: str
    status: str
    objective: float
    bound: float
    gap: float
    time: float
    certified: str
    certified_objective: float | None
    agrees: bool
    nodes: int | None = None


def agrees_with(
    inst: SuiteInstance, status: str, objective: float, bound: float, gap: float
) -> bool:
    """Whether a result is consistent with what ``inst`` certifies: the same status, an
    objective within the relative ``gap`` of the certified one (and a bound not above it);
    for an ``open`` instance, not contradicting its bracket."""
    tol = 1e-9
    if inst.status == "infeasible":
        return status == "infeasible"
    if inst.status == "optimal":
        assert inst.objective is not None
        ref = inst.objective
        scale = max(abs(ref), tol)
        if status != "optimal" or not math.isfinite(objective):
            return False
        return (
            abs(objective - ref) <= 2.0 * gap * scale + tol and bound <= ref * (1 + 2 * gap) + tol
        )
    # open: no claim of infeasibility when a plan is known, no bound above a known plan, no
    # plan below the proven bound
    if status == "infeasible":
        return inst.objective is None
    if inst.objective is not None and math.isfinite(bound):
        if bound > inst.objective + 2 * gap * abs(inst.objective) + tol:
            return False
    if inst.bound is not None and math.isfinite(objective):
        if objective < inst.bound - 2 * gap * abs(inst.bound) - tol:
            return False
    return True


def solve_instance(
    folder: Path,
    inst: SuiteInstance,
    solver: str = "bnb",
    time_limit: float = 600.0,
    threads: int = 1,
    gap: float = 1e-4,
) -> SuiteRun:
    """Solve ``inst`` with ``solver`` (a footfall backend name) and compare with its certificate."""
    from footfall.planning import PlannerOptions, plan_footsteps

    scene = instance_scene(folder, inst)
    opts = PlannerOptions(
        solver=solver,
        time_limit=time_limit,
        threads=threads,
        gap=gap,
        heading_segments=inst.heading_segments,
        region_margin=inst.region_margin,
    )
    t0 = time.perf_counter()
    plan = plan_footsteps(scene, n_steps=inst.n_steps, options=opts)
    elapsed = time.perf_counter() - t0
    status = plan.status.value
    objective = plan.objective if plan.has_solution else math.nan
    bound = plan.bound if plan.bound is not None else math.nan
    if status == "infeasible":
        bound = math.inf
    nodes = plan.stats.get("nodes") if isinstance(plan.stats, dict) else None
    return SuiteRun(
        name=inst.name,
        family=inst.family,
        n_steps=inst.n_steps,
        solver=solver,
        status=status,
        objective=float(objective),
        bound=float(bound),
        gap=float(plan.gap) if plan.gap is not None else math.inf,
        time=elapsed,
        certified=inst.status,
        certified_objective=inst.objective,
        agrees=agrees_with(inst, status, float(objective), float(bound), gap),
        nodes=int(nodes) if isinstance(nodes, int) else None,
    )


def run_suite(
    folder: Path,
    solver: str = "bnb",
    time_limit: float = 600.0,
    threads: int = 1,
    names: Sequence[str] = (),
    progress: Callable[[SuiteRun], None] | None = None,
) -> list[SuiteRun]:
    """Solve every instance of the suite (or those in ``names``) with ``solver``, at the suite's
    gap."""
    gap, instances = load_suite(folder)
    if names:
        known = {i.name for i in instances}
        for n in names:
            if n not in known:
                raise InputError("instances", n, "names of the suite's instances")
        instances = [i for i in instances if i.name in set(names)]
    out = []
    for inst in instances:
        run = solve_instance(folder, inst, solver, time_limit, threads, gap)
        out.append(run)
        if progress is not None:
            progress(run)
    return out


def format_suite_table(runs: Sequence[SuiteRun]) -> str:
    """Markdown table of a run: one row per instance, then the count that agree."""
    lines = [
        "| instance | family | N | certified | certified objective | solver | status | "
        "objective | gap | time [s] | agrees |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in runs:
        cert = "-" if r.certified_objective is None else f"{r.certified_objective:.6g}"
        obj = "-" if not math.isfinite(r.objective) else f"{r.objective:.6g}"
        gap = "-" if not math.isfinite(r.gap) else f"{r.gap:.1e}"
        lines.append(
            f"| {r.name} | {r.family} | {r.n_steps} | {r.certified} | {cert} | {r.solver} | "
            f"{r.status} | {obj} | {gap} | {r.time:.2f} | {'yes' if r.agrees else '**no**'} |"
        )
    ok = sum(r.agrees for r in runs)
    lines.append("")
    lines.append(f"{ok} of {len(runs)} agree with the certificate.")
    return "\n".join(lines)


def suite_runs_to_dict(runs: Sequence[SuiteRun]) -> list[dict[str, Any]]:
    from dataclasses import asdict

    return [asdict(r) for r in runs]
