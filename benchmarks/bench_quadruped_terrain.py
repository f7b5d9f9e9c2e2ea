"""Quadruped on every terrain, servo (document 001) vs whole-body control (issue 21): slopes up
and down, and the built-in quadruped scenes (side slope, varying slope, 10 cm stairs).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_terrain.py [--cycles 3] [--friction 1]

Each row walks one plan with both controllers back to back (so the speed ratio shares the
machine's state). Success: no fall, and the trunk ends within 25 % of the planned distance of
where the plan ends (a walk that slides down the slope fails).
CoP-ZMP: the measured centre of pressure against the planned ZMP (mean / max over the samples with
three or more feet planned and measured down). Slip: the largest sliding of one foot over one
stance. Drift: final trunk position against the plan's.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
from footfall.quadruped.scene import builtin_quadruped_scene, builtin_quadruped_scene_names
from footfall.sim.quadruped.mjcf import SimSettings
from footfall.sim.quadruped.sim import simulate

SLOPES_DEG = (-40, -35, -30, -25, -20, -15, 15, 20, 25, 30, 35, 40)
#: step length [m]: 0.4 m leaves the leg workspace beyond 30 degrees
STEEP_STEP = 0.25


def _cells(plan, settings: SimSettings | None) -> list[str]:  # type: ignore[no-untyped-def]
    out, servo_rtf = [], math.nan
    for ctrl in ("servo", "wbc"):
        res = simulate(plan, settings, controller=ctrl)
        m = res.metrics
        ok = not m.fell and m.trunk_drift_from_plan_m <= 0.25 * abs(m.planned_distance_up_slope_m)
        rtf = m.realtime_factor
        if ctrl == "servo":
            servo_rtf = rtf
        cop = (
            f"{100 * m.zmp_error_mean_m:.2f} / {100 * m.zmp_error_max_m:.2f}"
            if m.zmp_error_mean_m is not None and m.zmp_error_max_m is not None
            else "-"
        )
        fell = f" (fell {m.fall_time_s:.1f} s)" if m.fell else ""
        out += [
            f"{'yes' if ok else 'no'}{fell}",
            cop,
            f"{100 * m.foot_slip_max_m:.1f}",
            f"{100 * m.trunk_drift_from_plan_m:.1f}",
            f"{rtf:.1f}" + (f" ({rtf / servo_rtf:.2f})" if ctrl == "wbc" else ""),
        ]
    return out


HEADER = (
    "| {what} | servo ok | CoP-ZMP [cm] | slip [cm] | drift [cm] | x RT "
    "| wbc ok | CoP-ZMP [cm] | slip [cm] | drift [cm] | x RT (vs servo) |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|"
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cycles", type=int, default=3, help="gait cycles on the slopes")
    ap.add_argument("--friction", type=float, default=1.0)
    ap.add_argument("--slopes", default=",".join(str(s) for s in SLOPES_DEG))
    ap.add_argument("--no-scenes", action="store_true")
    args = ap.parse_args()
    robot = QuadrupedRobot()
    settings = SimSettings(friction=args.friction)
    print(f"friction {args.friction:g}, {args.cycles} cycles, body angle 2/3 of the slope\n")
    print(HEADER.format(what="slope (step)"))
    for deg in (float(s) for s in args.slopes.split(",")):
        step = 0.4 if abs(deg) <= 30 else STEEP_STEP
        params = GaitParams(
            slope=math.radians(deg),
            body_pitch=math.radians(2 * deg / 3),
            step=step,
            cycles=args.cycles,
        )
        cells = _cells(plan_gait(robot, params), settings)
        print(f"| {deg:+g}° ({step:g} m) | " + " | ".join(cells) + " |", flush=True)
    if args.no_scenes:
        return
    print("\n" + HEADER.format(what="scene (cycles)"))
    for name in builtin_quadruped_scene_names():
        sc = builtin_quadruped_scene(name)
        params = sc.params
        scene_settings = (
            settings if sc.friction is None else replace(settings, friction=sc.friction)
        )
        cells = _cells(plan_gait(robot, params), scene_settings)
        print(f"| {name} ({params.cycles}) | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
