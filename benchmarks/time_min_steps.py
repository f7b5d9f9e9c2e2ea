"""Time the MuJoCo walk's smallest-N search from a cold cache (issue 20).

``footfall walk --scene SCENE --planner miqcqp`` plans through
:func:`footfall.sim.biped.plans.plan_for_walk` without ``--steps``: the smallest-N search with the
walk's options (both reach frames, swing bound, half a sole of region margin, riser insets). This
runs that search without a cache and prints one JSON line: wall time [s], the N found, its
objective and every N tried (status, which model decided it, seconds).

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/time_min_steps.py discrete_steps 64 [THREADS]

THREADS: worker processes of the search (default: ``plan_for_walk``'s, two where two cores
exist; before that default existed walk plans used one).
"""

from __future__ import annotations

import json
import sys
import time

from footfall.sim.biped.plans import plan_for_walk
from footfall.terrain import builtin_scene


def main() -> None:
    scene, segments = sys.argv[1], int(sys.argv[2])
    extra = {"threads": int(sys.argv[3])} if len(sys.argv) > 3 else {}
    t0 = time.perf_counter()
    plan = plan_for_walk(
        builtin_scene(scene), "miqcqp", heading_segments=segments, cache_dir=None, **extra
    )
    print(
        json.dumps(
            {
                "scene": scene,
                "L": segments,
                "threads": plan.stats.get("workers"),
                "time": time.perf_counter() - t0,
                "N": plan.n_steps,
                "status": plan.status.value,
                "objective": plan.objective,
                "tried": plan.stats.get("tried"),
                "skipped": plan.stats.get("skipped"),
            }
        )
    )


if __name__ == "__main__":
    main()
