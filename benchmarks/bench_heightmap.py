"""Height maps to convex regions (issue 22): speed on a 4 m x 4 m map at 2 cm, round-trip quality.

Run (from the repository root; needs the ``terrain`` extra):

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_heightmap.py [--repeats 7] [--seeds 5]

1. Speed: a synthetic 4 m x 4 m map at 2 cm (200 x 200 = 40,000 cells) with a floor, a 10 deg
   ramp to a platform, three 6 cm stairs, twelve stepping stones between unknown gaps, an
   occluded (unknown) patch and 1 cm Gaussian noise; ``regions_from_heightmap`` timed after one
   warm-up run, median / min / max over ``--repeats`` runs, and ``scene_from_heightmap`` (regions
   plus placing start and goal and validating the scene) the same way.
2. Round trip: every built-in scene rasterised at 1 cm and 2 cm, 1 cm noise with seeds
   0..``--seeds``-1, recovered, and scored as in ``tests/terrain/test_heightmap.py``: coverage of
   the original terrain cells by the recovered polygons (matplotlib point-in-polygon), worst
   height error of a recovered plane over the terrain cells it covers, worst tilt between a
   recovered plane and the original region under its centroid, covered cells off the terrain.
   Worst case over the seeds.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from matplotlib.path import Path as MplPath

from footfall.terrain import builtin_scene, builtin_scene_names
from footfall.terrain.heightmap import (
    HeightMap,
    rasterize_scene,
    regions_from_heightmap,
    scene_from_heightmap,
)

SIDE, RES, NOISE = 4.0, 0.02, 0.01


def speed_map(seed: int = 0) -> HeightMap:
    """The 4 m x 4 m benchmark terrain (see the module doc), heights (200, 200) [m]."""
    n = round(SIDE / RES)
    x, y = np.meshgrid(RES * np.arange(n), RES * np.arange(n))
    z = np.zeros((n, n))
    ramp = (x >= 1.0) & (x < 2.0) & (y < 2.0)
    z[ramp] = math.tan(math.radians(10.0)) * (x[ramp] - 1.0)
    z[(x >= 2.0) & (y < 2.0)] = math.tan(math.radians(10.0))  # platform at the ramp's top
    for k in range(3):  # stairs along x
        z[(x >= 1.0 + k / 3) & (x < 1.0 + (k + 1) / 3) & (y >= 2.0)] = 0.06 * (k + 1)
    stones = (x >= 2.0) & (y >= 2.0)
    z[stones] = np.nan
    for i in range(4):
        for j in range(3):
            x0, y0 = 2.05 + 0.45 * i, 2.1 + 0.6 * j
            stone = (x >= x0) & (x < x0 + 0.35) & (y >= y0) & (y < y0 + 0.45)
            z[stone] = 0.15 + 0.02 * ((i + j) % 4)
    z[np.hypot(x - 0.5, y - 3.0) < 0.2] = np.nan  # occluded patch of the floor
    rng = np.random.default_rng(seed)
    return HeightMap(z + rng.normal(0.0, NOISE, z.shape), RES, np.zeros(2))


def timed(fn, repeats: int) -> tuple[float, float, float]:  # type: ignore[no-untyped-def]
    fn()  # warm-up (imports, first-call costs)
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), min(times), max(times)


def round_trip(name: str, res: float, seed: int) -> tuple[float, float, float, int, float]:
    """Coverage, worst height error [m], worst tilt [deg], region count and covered cells off
    the terrain (fraction of the terrain cells) of one round trip."""
    original = builtin_scene(name)
    clean = rasterize_scene(original, res)
    rng = np.random.default_rng(seed)
    noisy = HeightMap(clean.heights + rng.normal(0, NOISE, clean.heights.shape), res, clean.origin)
    mid = 0.5 * (original.start.left + original.start.right)
    g = original.goal.position
    rec, _ = scene_from_heightmap(
        noisy,
        start=(mid[0], mid[1], original.start.heading),
        goal=(g[0], g[1], original.goal.heading),
    )
    gx, gy = clean.cell_centres()
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    truth = clean.heights.ravel()
    terrain = ~np.isnan(truth)
    covered = np.zeros(len(pts), dtype=bool)
    dz_max = tilt_max = 0.0
    for r in rec.terrain:
        inside = MplPath(r.vertices).contains_points(pts)
        covered |= inside
        on = inside & terrain
        dz_max = max(dz_max, float(np.max(np.abs(r.height_at(pts[on]) - truth[on]))))
        below = [o for o in original.terrain if o.signed_distance(r.centroid[:2]) <= 0.0]
        tilt = min(math.degrees(math.acos(min(1.0, float(r.normal @ o.normal)))) for o in below)
        tilt_max = max(tilt_max, tilt)
    coverage = np.count_nonzero(covered & terrain) / np.count_nonzero(terrain)
    off = np.count_nonzero(covered & ~terrain) / np.count_nonzero(terrain)
    return coverage, dz_max, tilt_max, len(rec.terrain), off


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args()

    hm = speed_map()
    n_regions = len(regions_from_heightmap(hm).regions)
    print(f"## Speed: {hm.shape[0]} x {hm.shape[1]} = {hm.heights.size} cells at {RES} m\n")
    print("| call | median [s] | min [s] | max [s] | regions |")
    print("|---|---|---|---|---|")
    for label, fn in (
        ("regions_from_heightmap", lambda: regions_from_heightmap(hm)),
        ("scene_from_heightmap", lambda: scene_from_heightmap(hm, start=(0.5, 1.0))),
    ):
        med, lo, hi = timed(fn, args.repeats)
        print(f"| {label} | {med:.3f} | {lo:.3f} | {hi:.3f} | {n_regions} |")

    print(f"\n## Round trip, 1 cm noise, worst of seeds 0-{args.seeds - 1}\n")
    print("| scene | resolution [m] | coverage (min) | height error (max) [cm] | tilt (max) [deg] | regions | off terrain (max) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for name in builtin_scene_names():
        for res in (0.01, 0.02):
            runs = [round_trip(name, res, s) for s in range(args.seeds)]
            cov = min(r[0] for r in runs)
            dz = max(r[1] for r in runs)
            tilt = max(r[2] for r in runs)
            counts = sorted({r[3] for r in runs})
            regions = str(counts[0]) if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"
            off = max(r[4] for r in runs)
            print(
                f"| {name} | {res} | {cov:.4f} | {100 * dz:.2f} | {tilt:.2f} | {regions} | {off:.4f} |"
            )


if __name__ == "__main__":
    main()
