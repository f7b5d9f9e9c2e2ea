"""Quadruped slip guard (issue 21): the walk on slippery slopes with the guard off and with
``stop``, both controllers, the same plan for each pair.

Per run: total slip (the lengths of every foot's sliding displacement over its planned stances,
summed), the largest slip in one stance, whether it fell, the distance walked along the slope,
when the guard fired (leg, time, hold time) and how far the trunk moved while holding.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_slip.py [--cycles 3] [--friction 0.6]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from footfall._mjcf import SimSettings
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
from footfall.sim.quadruped.sim import simulate
from footfall.sim.quadruped.slip import DEFAULT_SLIP_LIMIT, SlipGuard


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cycles", type=int, default=3)
    ap.add_argument("--friction", type=float, default=0.6)
    ap.add_argument("--limit", type=float, default=DEFAULT_SLIP_LIMIT, help="slip limit [m]")
    ap.add_argument("--slopes", default="25,30,-25,-30", help="slopes [deg], comma-separated")
    args = ap.parse_args()
    settings = SimSettings(friction=args.friction)
    print(
        f"friction {args.friction:g}, {args.cycles} cycles, body at 2/3 of the slope, step 0.4 m, "
        f"limit {100 * args.limit:g} cm"
    )
    print(
        "| slope | controller | guard | total slip [cm] | max slip per stance [cm] | fell "
        "| distance [m] | stopped (leg, at, hold from) [s] | trunk moved while holding [cm] |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for slope in (float(s) for s in args.slopes.split(",")):
        params = GaitParams(
            slope=math.radians(slope), body_pitch=math.radians(2 * slope / 3), cycles=args.cycles
        )
        plan = plan_gait(QuadrupedRobot(), params)
        for ctrl in ("servo", "wbc"):
            for guard in (None, SlipGuard(limit=args.limit)):
                res = simulate(plan, settings, controller=ctrl, slip_guard=guard)
                m = res.metrics
                total = sum(s.slip_m for s in m.stance_slips)
                fell = f"yes ({m.fall_time_s:.1f} s)" if m.fell else "no"
                ev = res.slip_stop
                if ev is None:
                    stopped, moved = "-", "-"
                else:
                    stopped = f"{ev.leg}, {ev.time_s:.2f}, {ev.hold_time_s:.2f}"
                    hold = res.trace.trunk_pos[res.trace.t >= ev.hold_time_s - 1e-9]
                    moved = f"{100 * float(np.linalg.norm(hold[-1] - hold[0])):.1f}"
                print(
                    f"| {slope:+g}° | {ctrl} | {'stop' if guard else 'off'} | {100 * total:.1f} "
                    f"| {100 * m.foot_slip_max_m:.1f} | {fell} | {m.distance_up_slope_m:.2f} "
                    f"| {stopped} | {moved} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
