"""Quadruped push survival, servo vs whole-body control: lateral pushes on the trunk during the
walk gait on the document's 15 degree slope; success (no fall, >= 90 % of the servo walk's
distance without a push) per impulse and controller, Wilson 95 % intervals, paired McNemar.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_pushes.py --seeds 10 --impulses 20,40,60
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_pushes.py --scene stairs_10cm --cycles 8

Trial ``s`` pushes sideways for 0.1 s: the seed's draw of the one disturbance sampler
(:meth:`footfall.sim.disturbance.Disturbance.of_seed`: a swing in 30-70 % of the walk, a phase of
it, a direction) with the direction turned to the nearer of +y and -y; both controllers get the
same push (paired).
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

from scipy import stats

from footfall.experiments.study.stats import wilson
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
from footfall.quadruped.scene import resolve_quadruped_scene
from footfall.sim.disturbance import Disturbance
from footfall.sim.quadruped.sim import simulate
from footfall.sim.quadruped.trial import QuadrupedPlant
from footfall.sim.trial import run_trial


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--impulses", default="20,40,60", help="N s, comma-separated")
    ap.add_argument("--slope-deg", type=float, default=15.0)
    ap.add_argument("--body-deg", type=float, default=10.0)
    ap.add_argument("--cycles", type=int, default=4)
    ap.add_argument(
        "--scene", default=None, help="a quadruped scene (name or YAML) instead of the slope"
    )
    args = ap.parse_args()
    if args.scene is not None:
        sc = resolve_quadruped_scene(args.scene)
        params = replace(sc.params, cycles=args.cycles)
        what = sc.name
    else:
        params = GaitParams(
            slope=math.radians(args.slope_deg),
            body_pitch=math.radians(args.body_deg),
            cycles=args.cycles,
        )
        what = f"{args.slope_deg:g} deg"
    plan = plan_gait(QuadrupedRobot(), params)
    base = simulate(plan).metrics.distance_up_slope_m
    print(
        f"{what}, {args.cycles} cycles ({plan.duration:.1f} s), "
        f"servo distance without push {base:.2f} m"
    )
    for imp in (float(x) for x in args.impulses.split(",")):
        ok: dict[str, list[bool]] = {"servo": [], "wbc": []}
        for seed in range(args.seeds):
            d = Disturbance.of_seed(seed, impulse=imp)
            side = math.copysign(math.pi / 2, math.sin(d.direction))
            d = replace(d, direction=side)
            for ctrl in ok:
                m = run_trial(QuadrupedPlant(ctrl), None, plan, d).detail.metrics
                ok[ctrl].append(bool(not m.fell and m.distance_up_slope_m >= 0.9 * base))
        line = [f"{imp:5.1f} N s:"]
        for ctrl, v in ok.items():
            k, n = sum(v), len(v)
            lo, hi = wilson(k, n)
            line.append(f"{ctrl} {k}/{n} ({100 * lo:.0f}-{100 * hi:.0f} %)")
        a = sum(x and not y for x, y in zip(ok["wbc"], ok["servo"], strict=True))
        b = sum(y and not x for x, y in zip(ok["wbc"], ok["servo"], strict=True))
        p = 1.0 if a + b == 0 else stats.binomtest(a, a + b, 0.5).pvalue
        line.append(f"wbc-only {a}, servo-only {b}, McNemar p = {p:.2g}")
        print("  ".join(line), flush=True)


if __name__ == "__main__":
    main()
