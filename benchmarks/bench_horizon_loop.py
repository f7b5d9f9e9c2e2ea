"""Does looking three footsteps ahead help the loop keep its feet on the terrain under pushes?

Reduced-order closed loop (``footfall.sim.simulate``, 500 Hz, the scene's reactive plan), one
horizontal push of ``--impulses`` N s over 0.1 s per walk, at ``--times`` [s] into the walk and in
``--directions`` (0 = forward, 90 = left, deg). Each condition is walked with the footstep kept
in its planned region (``planned``), the best region within reach (``nearby``, one step ahead)
and the region that the short-horizon MIQP picks from the measured state (``horizon``, 3
footsteps ahead, re-solved at 50 Hz). Reported per scene, mode and impulse: walks without a fall
(Wilson 95 % interval), and for each pair of modes the discordant conditions (one fell, the other
did not) with a two-sided exact sign test: the unit sampled is the push condition (time x
direction), paired across modes.

Usage: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_horizon_loop.py``
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import time
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

from footfall.experiments.study.stats import wilson
from footfall.planning.reactive import plan_reactive
from footfall.sim import Push, SimOptions, simulate
from footfall.terrain import builtin_scene

MODES = ("planned", "nearby", "horizon")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="narrow_stones_gap,stepping_stones")
    ap.add_argument("--impulses", default="10,14,18", help="push impulses [N s]")
    ap.add_argument("--times", default="0.9,1.05,1.2,1.35", help="push start times [s]")
    ap.add_argument("--directions", default="0,90,180,270", help="push directions [deg]")
    ap.add_argument("--out", type=Path, default=Path("out/horizon_loop"))
    ap.add_argument("--summary-only", action="store_true", help="re-summarise OUT/walks.json")
    args = ap.parse_args(argv)
    impulses = [float(v) for v in args.impulses.split(",")]
    times = [float(v) for v in args.times.split(",")]
    dirs = [float(v) for v in args.directions.split(",")]
    rows: list[dict] = []  # type: ignore[type-arg]
    if args.summary_only:
        rows = json.loads((args.out / "walks.json").read_text())
    for name in [] if args.summary_only else args.scenes.split(","):
        scene = builtin_scene(name)
        plan = plan_reactive(scene)
        regions = tuple(scene.terrain)
        for imp, t, d in itertools.product(impulses, times, dirs):
            push = Push.horizontal(t, imp, math.radians(d), 0.1)
            for mode in MODES:
                t0 = time.perf_counter()
                res = simulate(plan, SimOptions(pushes=(push,), region_aware=mode), regions=regions)
                m = res.metrics
                rows.append(
                    {
                        "scene": name,
                        "impulse": imp,
                        "time": t,
                        "direction": d,
                        "mode": mode,
                        "fell": bool(m.fell),
                        "off_regions": int(m.footsteps_off_regions),
                        "region_changes": list(m.region_changes),
                        "wall_s": time.perf_counter() - t0,
                    }
                )
                print(json.dumps(rows[-1]), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    if not args.summary_only:
        (args.out / "walks.json").write_text(json.dumps(rows, indent=1) + "\n")
    lines = [
        "| scene | impulse [N s] | " + " | ".join(f"{m}: no fall (95 % CI)" for m in MODES) + " |",
        "|---|---|" + "---|" * len(MODES),
    ]
    pairs = []
    for name in args.scenes.split(","):
        for imp in impulses:
            sel = [r for r in rows if r["scene"] == name and r["impulse"] == imp]
            cells = []
            ok = {}
            for mode in MODES:
                rs = [r for r in sel if r["mode"] == mode]
                k = sum(not r["fell"] for r in rs)
                lo, hi = wilson(k, len(rs))
                cells.append(f"{k}/{len(rs)} ({lo:.2f}-{hi:.2f})")
                ok[mode] = {(r["time"], r["direction"]): not r["fell"] for r in rs}
            lines.append(f"| {name} | {imp:g} | " + " | ".join(cells) + " |")
            for a, b in (("horizon", "planned"), ("horizon", "nearby"), ("nearby", "planned")):
                a_only = sum(ok[a][c] and not ok[b][c] for c in ok[a])
                b_only = sum(ok[b][c] and not ok[a][c] for c in ok[a])
                p = binomtest(a_only, a_only + b_only).pvalue if a_only + b_only else 1.0
                pairs.append(
                    f"{name} {imp:g} N s: {a} alone survived {a_only}, {b} alone {b_only} "
                    f"(sign test p = {p:.3g})"
                )
    # pooled over scenes and impulses: the unit is (scene, impulse, time, direction)
    by = {
        m: {(r["scene"], r["impulse"], r["time"], r["direction"]): not r["fell"] for r in rows
            if r["mode"] == m}
        for m in MODES
    }  # fmt: skip
    for a, b in (("horizon", "planned"), ("horizon", "nearby"), ("nearby", "planned")):
        a_only = sum(by[a][c] and not by[b][c] for c in by[a])
        b_only = sum(by[b][c] and not by[a][c] for c in by[a])
        p = binomtest(a_only, a_only + b_only).pvalue if a_only + b_only else 1.0
        n = len(by[a])
        pairs.append(
            f"all {n} conditions: {a} {sum(by[a].values())}/{n} survived, {b} "
            f"{sum(by[b].values())}/{n}; {a} alone {a_only}, {b} alone {b_only} "
            f"(sign test p = {p:.3g})"
        )
    text = "\n".join(lines) + "\n\n" + "\n".join(pairs) + "\n"
    (args.out / "summary.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
