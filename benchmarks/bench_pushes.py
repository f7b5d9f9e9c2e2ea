"""Push recovery of a MuJoCo humanoid: success against push size, per scene and controller.

Run (from the repository root, about 10-20 minutes on 2 cores)::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_pushes.py \\
        --controllers wbc,servo --impulses 4,6,8,10,12,15 --seeds 10 --seed-start 0 --out out/pushes

Any robot, pushes as velocity changes (impulse = robot mass x Δv [m/s]), e.g. the measure per
robot of RESULTS.md, Δv = 0.1 m/s on seeds 0-49 with Wilson intervals::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_pushes.py --robot g1 \\
        --controllers wbc --scenes flat_long --dv 0.1 --seeds 50 --out out/pushes-g1

``--robot`` takes what ``footfall walk --robot`` takes (a built-in name or a robot file); seed
``s`` draws the same push as ``footfall walk --push-dv DV --seed s``.

``--region-aware planned,horizon`` walks every case once per region mode of the walker's MPC
(:attr:`footfall.sim.biped.options.WalkOptions.region_aware`) and adds a paired comparison of each
mode against the first: walks that only one mode survived, and the exact two-sided sign test
(McNemar's exact test) on them.

Every walk follows the scene's miqcqp plan (``plan_for_walk``, cached in ``OUT/plans``) with one
horizontal push of ``impulse`` N s (or robot mass x ``dv`` m/s) over 0.1 s, its direction, step
and phase drawn from the seed (:meth:`footfall.sim.disturbance.Disturbance.of_seed`, the draw of ``footfall walk --seed`` and
of the study's trials): seed ``s`` gives both controllers the same push. Success = the goal reached without a fall. Per scene,
controller and impulse the table gives the successes, the rate with its Wilson 95 % interval, and
the impulse at which the success rate crosses 50 % (linear interpolation between the levels
around it; "> max" when it never falls that low). Rows go to ``OUT/pushes.csv``.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
from dataclasses import replace
from multiprocessing import Pool
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# imported after the BLAS setting above
from footfall.experiments.study.stats import wilson

#: the scenes and their step counts (the walks' smallest N with 64 heading segments, except the
#: 20 steps of flat_long)
SCENES = {"flat_long": 20, "discrete_steps": 15, "stairs_slope_gap": 16}
#: the two ways to give a push's size: an impulse [N s] or a velocity change [m/s]
IMPULSE, DV = "impulse_Ns", "dv_m_s"


def crossing(levels: list[float], rates: list[float], level: float = 0.5) -> str:
    """The push size where the success rate first falls below ``level`` (linear interpolation)."""
    if rates and rates[0] < level:
        return f"< {levels[0]:g}"
    for i in range(len(levels) - 1):
        x0, r0, x1, r1 = levels[i], rates[i], levels[i + 1], rates[i + 1]
        if r0 >= level > r1:
            return f"{x0 + (r0 - level) / (r0 - r1) * (x1 - x0):.3g}"
    return f"> {levels[-1]:g}"


def _levels(ap: argparse.ArgumentParser, flag: str, text: str) -> list[float]:
    """The push sizes of ``text`` (comma separated, each finite and > 0), sorted."""
    try:
        levels = sorted(float(x) for x in text.split(","))
    except ValueError:
        ap.error(f"{flag}: {text!r} is not a comma-separated list of numbers")
    if not levels or not all(math.isfinite(x) and x > 0 for x in levels):
        ap.error(f"{flag}: {text!r}: every value must be a finite number > 0")
    return levels


def _walk(
    job: tuple[str, str, str, float, int, str, str, str, int, float, bool],
) -> dict[str, object]:
    from footfall.sim.biped.options import WalkOptions
    from footfall.sim.biped.plans import plan_for_walk, robot_model
    from footfall.sim.biped.trial import MujocoBipedPlant
    from footfall.sim.disturbance import Disturbance
    from footfall.sim.trial import run_trial
    from footfall.terrain.scene import builtin_scene

    scene_name, controller, region, size, seed, cache, robot, unit, steps, leg, literal, timing = (
        job
    )
    scene = builtin_scene(scene_name)
    model = robot_model(robot)
    n = steps or SCENES.get(scene_name)
    plan = plan_for_walk(scene, "miqcqp", n, 600.0, Path(cache), model=model)
    options = WalkOptions(controller=controller, region_aware=region, leg_momentum=leg)
    if literal:
        options = replace(options, torque_weight_mass=None)
    if timing is not None:
        options = replace(options, step_timing=timing == "on")
    plant = MujocoBipedPlant(options, robot=model)
    push = (
        Disturbance.of_seed(seed, dv=size)
        if unit == DV
        else Disturbance.of_seed(seed, impulse=size)
    )
    out = run_trial(plant, scene, plan, push)
    return {
        "robot": robot,
        "scene": scene_name,
        "controller": controller,
        "region_aware": region,
        unit: size,
        "impulse_Ns": push.impulse_for(plan.robot.mass),
        "seed": seed,
        "success": out.success,
        "fell": out.fell,
        "fall_time_s": out.fall_time,
        "zmp_mean_m": out.zmp_offset_mean,
        "wall_s": out.wall_time,
        "sim_s": out.sim_time,
    }


def _paired(rows: list[dict[str, object]], modes: list[str], unit: str) -> None:
    """Each region mode against the first, paired by (scene, controller, push size, seed): the
    walks only one of the two survived and the exact two-sided sign test on them."""
    from scipy.stats import binomtest

    ok = {
        (r["scene"], r["controller"], r[unit], r["seed"], r["region_aware"]): bool(r["success"])
        for r in rows
    }
    keys = sorted({k[:4] for k in ok}, key=str)
    print(f"\n| mode vs {modes[0]} | pairs | both | only {modes[0]} | only mode | p (sign test) |")
    print("|---|---|---|---|---|---|")
    for mode in modes[1:]:
        a = [ok[(*k, modes[0])] for k in keys]
        b = [ok[(*k, mode)] for k in keys]
        only_a = sum(x and not y for x, y in zip(a, b, strict=True))
        only_b = sum(y and not x for x, y in zip(a, b, strict=True))
        both = sum(x and y for x, y in zip(a, b, strict=True))
        n = only_a + only_b
        p = binomtest(only_b, n).pvalue if n else 1.0
        print(f"| {mode} | {len(keys)} | {both} | {only_a} | {only_b} | {p:.3g} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--controllers", default="wbc,servo")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument(
        "--region-aware",
        default="horizon",
        help="region modes, comma-separated (default: the walker's)",
    )
    ap.add_argument("--impulses", default="4,6,8,10,12,15", help="push impulses [N s]")
    ap.add_argument(
        "--dv", default="", help="pushes as velocity changes [m/s] (impulse = mass x dv) instead"
    )
    ap.add_argument("--robot", default="biped", help="biped, g1, talos or a robot file (.yaml)")
    ap.add_argument(
        "--steps", type=int, default=0, help="footsteps N of every scene (0: each scene's own)"
    )
    ap.add_argument(
        "--leg-momentum",
        type=float,
        default=None,
        help="WalkOptions.leg_momentum: share of the legs' forecast momentum (0: off; "
        "default: the walker's, 0.5 with wbc, 0 with servo)",
    )
    ap.add_argument(
        "--literal-torque-weight",
        action="store_true",
        help="WalkOptions.torque_weight_mass=None: the MPC's ankle-torque weight R the same for "
        "every robot (default: scaled by the robot's mass, the same weight per metre of CoP)",
    )
    ap.add_argument(
        "--step-timing",
        choices=("on", "off"),
        default=None,
        help="WalkOptions.step_timing: the MPC may end a single support sooner (default: the "
        "walker's, on)",
    )
    ap.add_argument("--seeds", type=int, default=10, help="walks per scene, controller, impulse")
    ap.add_argument("--seed-start", type=int, default=0, help="first seed (held-out seeds)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("out/pushes"))
    a = ap.parse_args()
    unit = DV if a.dv else IMPULSE
    levels = _levels(ap, "--dv" if a.dv else "--impulses", a.dv or a.impulses)
    scenes = a.scenes.split(",")
    for sc in scenes:
        if sc not in SCENES and a.steps <= 0:
            ap.error(
                f"--scenes: {sc!r} has no default N (one of {', '.join(SCENES)}); give --steps"
            )
    if a.steps < 0 or a.seeds < 1:
        ap.error("--steps must be >= 0 and --seeds >= 1")
    from footfall.errors import FootfallError
    from footfall.sim.biped.plans import robot_model
    from footfall.terrain.scene import builtin_scene

    try:
        robot_model(a.robot)
    except FootfallError as e:
        ap.error(f"--robot: {e}")
    from footfall.sim.biped.options import WalkOptions

    for ctl in a.controllers.split(","):
        try:
            WalkOptions(controller=ctl, leg_momentum=a.leg_momentum)
        except FootfallError as e:
            ap.error(f"--controllers / --leg-momentum: {e}")
    for sc in scenes:
        try:
            builtin_scene(sc)
        except FootfallError as e:
            ap.error(f"--scenes: {e}")
    controllers = a.controllers.split(",")
    modes = a.region_aware.split(",")
    variants = [(ctl, mode) for ctl in controllers for mode in modes]
    a.out.mkdir(parents=True, exist_ok=True)
    cache = str(a.out / "plans")
    common = (a.robot, unit, a.steps, a.leg_momentum, a.literal_torque_weight, a.step_timing)
    jobs = [
        (sc, ctl, mode, imp, seed, cache, *common)
        for sc in scenes
        for ctl, mode in variants
        for imp in levels
        for seed in range(a.seed_start, a.seed_start + a.seeds)
    ]
    # plan once per scene before the pool (the cache then serves every worker)
    for sc in scenes:
        try:
            _walk((sc, controllers[0], modes[0], levels[0], 0, cache, *common))
        except FootfallError as e:
            ap.error(f"--scenes / --steps: {sc}: {e}")
    with Pool(a.workers) as pool:
        rows = pool.map(_walk, jobs, chunksize=1)
    with (a.out / "pushes.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    label = "m/s" if unit == DV else "N s"
    print(f"{a.robot}, pushes as {'velocity changes' if unit == DV else 'impulses'} [{label}]")
    print(
        "| scene | controller | region mode | "
        + " | ".join(f"{x:g} {label}" for x in levels)
        + " | 50 % at |"
    )
    print("|---|---|---|" + "---|" * len(levels) + "---|")
    for sc in scenes:
        for ctl, mode in variants:
            cells, rates = [], []
            for imp in levels:
                rs = [
                    r
                    for r in rows
                    if (r["scene"], r["controller"], r["region_aware"], r[unit])
                    == (sc, ctl, mode, imp)
                ]
                k = sum(bool(r["success"]) for r in rs)
                lo, hi = wilson(k, len(rs))
                rates.append(k / len(rs))
                cells.append(f"{k}/{len(rs)} [{100 * lo:.0f}-{100 * hi:.0f} %]")
            print(
                f"| {sc} | {ctl} | {mode} | "
                + " | ".join(cells)
                + f" | {crossing(levels, rates)} {label} |"
            )
    if len(modes) > 1:
        _paired(rows, modes, unit)
    wall = sum(float(r["wall_s"]) for r in rows)
    sim = sum(float(r["sim_s"]) for r in rows)
    print(f"\n{len(rows)} walks, {sim / wall:.1f}x real time per walk (mean over workers)")


if __name__ == "__main__":
    main()
