"""Same-run A/B of two source trees on the instance suite: seconds per instance and their ratio.

Usage (from the repository root; BASE is another checkout's ``src``, e.g. from
``git worktree add /tmp/base 6b6cb7c``):

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_suite_ab.py --base /tmp/base/src \
        --suite benchmarks/suite --threads 1 --repeats 1 --out out/suite_ab

Each instance is planned with ``bnb`` by a fresh Python process per tree (so the trees' imports
do not mix), alternating base and head, each timing only ``plan_footsteps`` (``perf_counter``)
on its second call (the first also pays the tree's lazy imports).
Both must reach the certified result; the table gives both times and head / base.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

CHILD = r"""
import json, sys, time
from footfall.planning import PlannerOptions, plan_footsteps
from footfall.terrain import load_scene
scene_file, n, hs, margin, gap, threads, limit = sys.argv[1:8]
scene = load_scene(scene_file)
opts = PlannerOptions(time_limit=float(limit), threads=int(threads), gap=float(gap),
                      heading_segments=int(hs), region_margin=float(margin))
t0 = time.perf_counter()
plan = plan_footsteps(scene, n_steps=int(n), options=opts)
first = time.perf_counter() - t0
t0 = time.perf_counter()  # again: the first call also pays the tree's lazy imports
plan = plan_footsteps(scene, n_steps=int(n), options=opts)
dt = time.perf_counter() - t0
obj = plan.objective if plan.has_solution else None
print(json.dumps({"status": plan.status.value, "objective": obj, "time": dt, "first": first}))
"""


def _run(src: Path, args: list[str]) -> dict:  # type: ignore[type-arg]
    env = dict(os.environ, PYTHONPATH=str(src), OPENBLAS_NUM_THREADS="1")
    res = subprocess.run(
        [sys.executable, "-c", CHILD, *args], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(res.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=Path, required=True, help="the base tree's src folder")
    ap.add_argument("--head", type=Path, default=Path("src"), help="the head tree's src folder")
    ap.add_argument("--suite", type=Path, default=Path("benchmarks/suite"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--time-limit", type=float, default=600.0)
    ap.add_argument("--out", type=Path, default=Path("out/suite_ab"))
    args = ap.parse_args(argv)
    data = json.loads((args.suite / "suite.json").read_text())
    gap = data["gap"]
    rows = []
    for inst in data["instances"]:
        a = [
            str(args.suite / inst["scene"]),
            str(inst["n_steps"]),
            str(inst["heading_segments"]),
            str(inst.get("region_margin", 0.0)),
            str(gap),
            str(args.threads),
            str(args.time_limit),
        ]
        base_t, head_t, statuses = [], [], set()
        for _ in range(args.repeats):
            for tree, times in ((args.base, base_t), (args.head, head_t)):
                r = _run(tree, a)
                times.append(r["time"])
                ok = r["status"] == inst["status"] or (
                    inst["status"] == "open" and r["status"] != "infeasible"
                )
                if inst["status"] == "optimal":
                    ref = inst["objective"]
                    ok = ok and abs(r["objective"] - ref) <= 2 * gap * abs(ref) + 1e-9
                statuses.add("ok" if ok else f"{tree.parent.name}: {r['status']}")
        row = {
            "name": inst["name"],
            "certified": inst["status"],
            "base_s": statistics.median(base_t),
            "head_s": statistics.median(head_t),
            "checks": sorted(statuses),
        }
        row["ratio"] = row["head_s"] / row["base_s"] if row["base_s"] > 0 else float("nan")
        rows.append(row)
        print(
            f"{row['name']}: base {row['base_s']:.3f} s, head {row['head_s']:.3f} s, "
            f"head/base {row['ratio']:.2f}, {','.join(row['checks'])}",
            flush=True,
        )
    args.out.mkdir(parents=True, exist_ok=True)
    ratios = [r["ratio"] for r in rows]
    lines = [
        "| instance | certified | base [s] | head [s] | head / base | checks |",
        "|---|---|---|---|---|---|",
        *(
            f"| {r['name']} | {r['certified']} | {r['base_s']:.3f} | {r['head_s']:.3f} | "
            f"{r['ratio']:.2f} | {', '.join(r['checks'])} |"
            for r in rows
        ),
        "",
        f"median head / base {statistics.median(ratios):.2f} over {len(rows)} instances "
        f"(min {min(ratios):.2f}, max {max(ratios):.2f})",
    ]
    (args.out / "suite_ab.md").write_text("\n".join(lines) + "\n")
    (args.out / "suite_ab.json").write_text(json.dumps(rows, indent=1) + "\n")
    print("\n".join(lines))
    return 0 if all(r["checks"] == ["ok"] for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
