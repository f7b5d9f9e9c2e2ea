"""Walk again a sample of a built-in study's trials and compare rows: bit-identity of a code change.

Run the same sample with two versions of footfall (``PYTHONPATH=<tree>/src``), then compare::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=<before>/src python benchmarks/rewalk_study.py section55_reduced 200 --dump before.json
    OPENBLAS_NUM_THREADS=1 PYTHONPATH=<after>/src python benchmarks/rewalk_study.py section55_reduced 200 --dump after.json
    python benchmarks/rewalk_study.py --compare before.json after.json

The sample is a fixed shuffle of the study's trial keys (the first K); plans come from the shipped
folder's plan cache (``benchmarks/study/NAME/plans``), so nothing is planned. Every column a row
has in both files is compared exactly, ``wall_time`` excepted.
"""

from __future__ import annotations

import argparse
import json
import math
import random
from pathlib import Path

FOLDER = Path(__file__).parent / "study"


def dump(name: str, k: int, out: Path) -> None:
    from footfall.experiments.study import builtin_study
    from footfall.experiments.study.runner import make_plans, make_trials
    from footfall.experiments.study.trials import run_trial

    design = builtin_study(name)
    trials = make_trials(design, make_plans(design, FOLDER / name / "plans"))
    keys = sorted(t.key for t in trials)
    random.Random(1).shuffle(keys)
    by_key = {t.key: t for t in trials}
    rows = [run_trial(by_key[key]) for key in keys[:k]]
    out.write_text(json.dumps(rows, default=str))


def compare(a: Path, b: Path) -> None:
    old, new = json.loads(a.read_text()), json.loads(b.read_text())
    same = 0
    for ra, rb in zip(old, new, strict=True):
        diff = [
            (c, v, rb[c])
            for c, v in ra.items()
            if c in rb and c != "wall_time" and not _equal(v, rb[c])
        ]
        if diff:
            print("DIFF", ra["key"], diff[:3])
        else:
            same += 1
    print(f"{same} of {len(old)} rows identical")


def _equal(x: object, y: object) -> bool:
    nan = isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y)
    return nan or x == y


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?")
    ap.add_argument("k", nargs="?", type=int, default=50)
    ap.add_argument("--dump", type=Path)
    ap.add_argument("--compare", nargs=2, type=Path)
    a = ap.parse_args()
    if a.compare:
        compare(*a.compare)
    elif a.study and a.dump:
        dump(a.study, a.k, a.dump)
    else:
        ap.error("give STUDY K --dump FILE, or --compare A B")


if __name__ == "__main__":
    main()
