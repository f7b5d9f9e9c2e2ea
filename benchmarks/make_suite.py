"""Build and certify the footstep-planning instance suite (``benchmarks/suite``).

Usage (from the repository root; resumable: results so far are kept in OUT/certify.jsonl):

    OPENBLAS_NUM_THREADS=1 python benchmarks/make_suite.py --out benchmarks/suite \
        --seeds 0,1,2,3 --bnb-limit 600 --scip-limit 1800

For every family of :mod:`footfall.terrain.suite_families` and seed: the terrain's scene file is
written; N starts at the lower bound of :func:`footfall.planning.reachable_steps_bound`; ``bnb``
looks for the smallest N with a plan (at most 4 more), and each N it proves infeasible on the way
becomes an infeasible instance. Every instance is then solved by ``bnb`` and by SCIP (one thread
each, gap 1e-4) and certified as :mod:`footfall.experiments.suite` describes.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from footfall._io import write_json, write_text
from footfall.experiments.suite import SUITE_FORMAT
from footfall.planning import (
    PlannerOptions,
    build_footstep_problem,
    plan_footsteps,
    reachable_steps_bound,
)
from footfall.solvers import solve
from footfall.terrain.scene import scene_to_yaml
from footfall.terrain.suite_families import SUITE_FAMILIES, suite_terrain

GAP = 1e-4
HEADING_SEGMENTS = 16


def _scip_direct(scene, n, limit):  # type: ignore[no-untyped-def]
    """SCIP on the model itself: none of footfall's checks before a solve (the geometric and
    reachable-set proofs of infeasibility that plan_footsteps runs first), so a certificate of
    infeasibility shares no code with bnb's."""
    opts = PlannerOptions(time_limit=limit, threads=1, gap=GAP, heading_segments=HEADING_SEGMENTS)
    fp = build_footstep_problem(scene, scene.robot, n, opts)
    res = solve(fp.problem, "scip", opts.solver_options())
    return {
        "status": res.status.value,
        "objective": res.objective if res.x is not None else None,
        "bound": None if not math.isfinite(res.bound) else res.bound,
        "gap": None if not math.isfinite(res.gap) else res.gap,
        "time_s": round(res.solve_time, 3),
        "nodes": res.stats.get("nodes"),
        "model": "direct",
    }


def _solve(scene, n, solver, limit):  # type: ignore[no-untyped-def]
    if solver == "scip":
        return _scip_direct(scene, n, limit)
    opts = PlannerOptions(
        solver=solver, time_limit=limit, threads=1, gap=GAP, heading_segments=HEADING_SEGMENTS
    )
    plan = plan_footsteps(scene, n_steps=n, options=opts)
    status = plan.status.value
    return {
        "status": status,
        "objective": plan.objective if plan.has_solution else None,
        "bound": None if not math.isfinite(plan.bound) else plan.bound,
        "gap": None if not math.isfinite(plan.gap) else plan.gap,
        "time_s": round(float(plan.stats.get("solve_time", plan.solve_time or 0.0)), 3)
        if isinstance(plan.stats, dict)
        else None,
        "nodes": plan.stats.get("nodes") if isinstance(plan.stats, dict) else None,
    }


def _certify(bnb: dict, scip: dict) -> tuple[str, float | None, float | None]:  # type: ignore[type-arg]
    if bnb["status"] == "infeasible" and scip["status"] == "infeasible":
        return "infeasible", None, None
    if bnb["status"] == "optimal" and scip["status"] == "optimal":
        a, b = bnb["objective"], scip["objective"]
        if abs(a - b) <= 2 * GAP * min(abs(a), abs(b)) + 1e-9:
            bounds = [v for v in (bnb["bound"], scip["bound"]) if v is not None]
            return "optimal", min(a, b), max(bounds) if bounds else None
    objs = [r["objective"] for r in (bnb, scip) if r["objective"] is not None]
    bounds = [r["bound"] for r in (bnb, scip) if r["bound"] is not None]
    return "open", min(objs) if objs else None, max(bounds) if bounds else None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("benchmarks/suite"))
    ap.add_argument("--seeds", default="0,1,2,3")
    ap.add_argument("--families", default=",".join(SUITE_FAMILIES))
    ap.add_argument("--bnb-limit", type=float, default=600.0)
    ap.add_argument("--scip-limit", type=float, default=1800.0)
    args = ap.parse_args(argv)
    seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
    families = [f for f in args.families.split(",") if f.strip()]
    out: Path = args.out
    (out / "scenes").mkdir(parents=True, exist_ok=True)
    log = out / "certify.jsonl"
    done: dict[str, dict] = {}  # type: ignore[type-arg]
    if log.exists():
        for line in log.read_text().splitlines():
            rec = json.loads(line)
            done[rec["name"]] = rec
    instances = []
    for family in families:
        for seed in seeds:
            scene = suite_terrain(family, seed)
            scene_file = f"scenes/{scene.name}.yaml"
            write_text(out / scene_file, scene_to_yaml(scene))
            opts = PlannerOptions(threads=1, heading_segments=HEADING_SEGMENTS)
            n0 = reachable_steps_bound(scene, scene.robot, opts, 20).n_steps
            for n in range(n0, n0 + 5):
                name = f"{scene.name}-n{n:02d}"
                if name not in done:
                    bnb = _solve(scene, n, "bnb", args.bnb_limit)
                    scip = _solve(scene, n, "scip", args.scip_limit)
                    rec = {"name": name, "family": family, "seed": seed, "scene": scene_file,
                           "n_steps": n, "bnb": bnb, "scip": scip}  # fmt: skip
                    with log.open("a") as fh:
                        fh.write(json.dumps(rec) + "\n")
                    done[name] = rec
                    print(name, "bnb", bnb["status"], bnb["objective"], bnb["time_s"],
                          "| scip", scip["status"], scip["objective"], scip["time_s"],
                          flush=True)  # fmt: skip
                rec = done[name]
                if "model" not in rec["scip"] and rec["scip"]["status"] != "infeasible":
                    # an earlier build's SCIP result through plan_footsteps: past its checks
                    # (which only ever answer "infeasible") it hands the whole model to SCIP
                    # unchanged, the direct solve
                    rec["scip"]["model"] = "direct"
                if rec["scip"].get("model") != "direct":
                    # an earlier build took SCIP's infeasibility through plan_footsteps' checks
                    rec["scip"] = _solve(scene, n, "scip", args.scip_limit)
                    with log.open("a") as fh:
                        fh.write(json.dumps(rec) + "\n")
                    print(name, "scip again:", rec["scip"]["status"], rec["scip"]["time_s"])
                status, obj, bound = _certify(rec["bnb"], rec["scip"])
                instances.append(
                    {
                        "name": name,
                        "family": family,
                        "seed": seed,
                        "scene": scene_file,
                        "n_steps": n,
                        "heading_segments": HEADING_SEGMENTS,
                        "region_margin": 0.0,
                        "status": status,
                        "objective": obj,
                        "bound": bound,
                        "certificate": {"bnb": rec["bnb"], "scip": rec["scip"]},
                    }
                )
                if rec["bnb"]["status"] != "infeasible":
                    break
    write_json(out / "suite.json", {"format": SUITE_FORMAT, "gap": GAP, "instances": instances})
    counts = {
        s: sum(i["status"] == s for i in instances) for s in ("optimal", "infeasible", "open")
    }
    print(f"{len(instances)} instances: {counts}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
