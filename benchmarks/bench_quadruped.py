"""Speed of the document-001 quadruped slope walk (issue 6).

Run: ``PYTHONPATH=src python benchmarks/bench_quadruped.py [--slope-deg 15 --body-deg 10]``.
Prints JSON: simulated seconds per wall second of the closed loop (goal >= 5x, one core, no
video) against bare ``mj_step`` on the same model, and the 10-cycle plan time (goal < 50 ms).
"""

from __future__ import annotations

import argparse
import json
import os

# one core: keep BLAS from spreading numpy work over threads
for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

from footfall.experiments.bench import benchmark_quadruped  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--slope-deg", type=float, default=15.0)
    ap.add_argument("--body-deg", type=float, default=10.0)
    ap.add_argument("--sim-cycles", type=int, default=6)
    ap.add_argument("--plan-cycles", type=int, default=10)
    args = ap.parse_args()
    out = benchmark_quadruped(args.slope_deg, args.body_deg, args.sim_cycles, args.plan_cycles)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
