"""Real quadrupeds from their URDFs (Go2, Solo-12, ANYmal C of example-robot-data) walking
document 001's gait with the whole-body controller: 15 and 20 degrees up, 15 down, and the
built-in quadruped scenes, the gait and the scenes' lengths scaled to each robot.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_robots.py [--robots go2,solo12,anymal_c] [--cycles 6]
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_robots.py --speed   # x real time only
    ... bench_quadruped_robots.py --robots document,go2 --cop-weight 100   # another CoP weight

One walk per robot and ground (the simulation is deterministic). Success: no fall, and the trunk
ends within 25 % of the planned distance of where the plan ends. CoP-ZMP: the measured centre of
pressure against the planned ZMP (mean / max over the samples with three or more feet planned and
measured down). Slip: the largest sliding of one foot over one stance (friction 0.8 on the
planes, as the robots issue asks; the scenes' own otherwise). x RT: simulated over wall time on
one core. A ground whose gait the planner refuses (the legs do not reach) is reported with the
planner's reason.
"""

from __future__ import annotations

import argparse
import math

from footfall.errors import InputError
from footfall.quadruped import GaitParams, plan_gait
from footfall.quadruped.scaling import scale_gait
from footfall.quadruped.scene import builtin_quadruped_scene, builtin_quadruped_scene_names
from footfall.robots.quadruped import resolve_quadruped
from footfall.sim.quadruped.mjcf import robot_settings
from footfall.sim.quadruped.sim import simulate
from footfall.sim.quadruped.wbc import QuadrupedWbcGains

PLANES_DEG = (15.0, 20.0, -15.0)
PLANE_FRICTION = 0.8


def _row(
    robot_name: str,
    label: str,
    params: GaitParams,
    friction: float | None,
    gains: QuadrupedWbcGains,
) -> str:
    robot = resolve_quadruped(robot_name)
    try:
        scaled = scale_gait(robot, params)
        plan = plan_gait(robot, scaled)
    except InputError as e:
        return f"| {robot_name} | {label} | infeasible: {e.field} ({e.expected}) | | | | |"
    res = simulate(plan, robot_settings(robot, friction), controller="wbc", wbc_gains=gains)
    m = res.metrics
    ok = not m.fell and m.trunk_drift_from_plan_m <= 0.25 * abs(m.planned_distance_up_slope_m)
    cop = (
        f"{100 * m.zmp_error_mean_m:.2f} / {100 * m.zmp_error_max_m:.2f}"
        if m.zmp_error_mean_m is not None and m.zmp_error_max_m is not None
        else "-"
    )
    return (
        f"| {robot_name} | {label} | {'yes' if ok else 'no'}{' (fell)' if m.fell else ''} | "
        f"{scaled.step:.3f}{'' if scaled.lateral_share == 1 else f' (w {scaled.lateral_share:g})'} | {cop} | {100 * m.foot_slip_max_m:.2f} | {m.realtime_factor:.1f} |"
    )


def _speed(names: list[str]) -> None:
    slope = math.radians(15.0)
    for rep in range(2):
        for name in names:
            robot = resolve_quadruped(name)
            params = scale_gait(robot, GaitParams(slope=slope, body_pitch=slope * 2 / 3, cycles=2))
            res = simulate(plan_gait(robot, params), robot_settings(robot), controller="wbc")
            tr = res.trace
            steps = tr.sim_time / robot_settings(robot).timestep
            print(
                f"run {rep + 1} {name}: {res.metrics.realtime_factor:.1f}x real time, "
                f"{steps / tr.wall_time:.0f} physics steps/s",
                flush=True,
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robots", default="go2,solo12,anymal_c")
    ap.add_argument("--cycles", type=int, default=6)
    ap.add_argument(
        "--speed",
        action="store_true",
        help="only x real time: document and each robot, 2 cycles up 15 deg, twice, back to back",
    )
    ap.add_argument(
        "--cop-weight",
        type=float,
        default=QuadrupedWbcGains.cop_weight,
        help="the whole-body QP's CoP weight [1/m^2] (QuadrupedWbcGains.cop_weight)",
    )
    args = ap.parse_args()
    gains = QuadrupedWbcGains(cop_weight=args.cop_weight)
    if args.speed:
        _speed(["document", *args.robots.split(",")])
        return
    print(
        "| robot | ground | success | step [m] | CoP-ZMP mean / max [cm] | slip max [cm] | x RT |"
    )
    print("|---|---|---|---|---|---|---|")
    for name in args.robots.split(","):
        for deg in PLANES_DEG:
            body = 2.0 / 3.0 * deg
            params = GaitParams(
                slope=math.radians(deg), body_pitch=math.radians(body), cycles=args.cycles
            )
            print(_row(name, f"{deg:+.0f} deg", params, PLANE_FRICTION, gains), flush=True)
        for scene in builtin_quadruped_scene_names():
            sc = builtin_quadruped_scene(scene)
            params = sc.params
            print(_row(name, scene, params, sc.friction, gains), flush=True)


if __name__ == "__main__":
    main()
