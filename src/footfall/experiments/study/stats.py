"""Statistics of a study table: cell means with bootstrap CIs, paired planner differences, success
rates with Wilson intervals, fragility curves and a verdict written from the numbers.

Rows are the dicts of ``trials.parquet`` (:data:`~footfall.experiments.study.trials.COLUMNS`).
Conventions:

- A step mode selects rows: ``smallest`` the rows flagged ``smallest_n``, ``equal`` those flagged
  ``equal_n`` (the reactive walk is in both).
- Rows with an ``error`` are counted and left out of every statistic.
- The ZMP offset (document 000's metric: the single-support CoP offset from the sole centre) is
  summarised over the walks that succeeded: a fall ends the walk early, and its offsets describe
  falling, not walking the plan. Paired ZMP differences use the seeds where both planners
  succeeded; paired success differences use every seed both walked (exact McNemar test).
- Intervals are 95 %; bootstrap CIs are BCa with 4000 resamples from a fixed seed (so a table is
  reproducible), percentile where BCa is undefined (all values equal).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import stats

#: confidence level of every interval
LEVEL = 0.95
#: significance level of the verdict's tests
ALPHA = 0.05
#: bootstrap resamples
RESAMPLES = 4000
#: the planner whose claim the verdict judges (document 000's full-horizon planner)
CLAIMANT = "miqcqp"


def wilson(k: int, n: int, level: float = LEVEL) -> tuple[float, float]:
    """Wilson score interval of a success rate ``k / n`` (nan, nan for n = 0)."""
    if n <= 0:
        return math.nan, math.nan
    z = float(stats.norm.ppf(0.5 + level / 2))
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, mid - half), min(1.0, mid + half)


def mean_ci(
    values: Sequence[float], level: float = LEVEL, seed: int = 0
) -> tuple[float, float, float]:
    """Mean and bootstrap CI of ``values`` (finite values only; nan for fewer than 2)."""
    x = np.asarray([v for v in values if v is not None and math.isfinite(v)], dtype=float)
    if x.size == 0:
        return math.nan, math.nan, math.nan
    m = float(np.mean(x))
    if x.size < 2:
        return m, math.nan, math.nan
    if np.all(x == x[0]):
        return m, m, m
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # BCa warns on near-degenerate samples; checked below
        for method in ("BCa", "percentile"):  # percentile where BCa is undefined
            res = stats.bootstrap(
                (x,),
                np.mean,
                confidence_level=level,
                n_resamples=RESAMPLES,
                method=method,
                rng=np.random.default_rng(seed),
            )
            lo, hi = float(res.confidence_interval.low), float(res.confidence_interval.high)
            if math.isfinite(lo) and math.isfinite(hi):
                break
    return m, lo, hi


def wilcoxon_p(diff: Sequence[float]) -> float:
    """Two-sided Wilcoxon signed-rank p-value of paired differences (1 when all are zero)."""
    d = np.asarray(diff, dtype=float)
    if d.size == 0:
        return math.nan
    if np.all(d == 0):
        return 1.0
    return float(stats.wilcoxon(d, zero_method="wilcox").pvalue)


def mcnemar_p(only_a: int, only_b: int) -> float:
    """Exact McNemar p-value (two-sided binomial test on the discordant pairs)."""
    n = only_a + only_b
    return 1.0 if n == 0 else float(stats.binomtest(only_a, n, 0.5).pvalue)


def in_mode(rows: Sequence[dict[str, Any]], mode: str) -> list[dict[str, Any]]:
    """The rows of step mode ``smallest`` or ``equal`` that ran without error."""
    flag = "smallest_n" if mode == "smallest" else "equal_n"
    return [r for r in rows if r[flag] and r["error"] is None]


@dataclass(frozen=True)
class Cell:
    """One (scene, planner, step mode, push impulse) of the study.

    Attributes: scene, planner, mode, impulse [N s], n_steps (N of its plan), walks (without
    errors), errors, successes, success_lo / success_hi (Wilson), zmp_mean / zmp_lo / zmp_hi
    (mean single-support ZMP offset over the successful walks and its bootstrap CI) [m],
    zmp_max_mean (mean of the per-walk max) [m], footstep_error (mean) [m].
    """

    scene: str
    planner: str
    mode: str
    impulse: float
    n_steps: int
    walks: int
    errors: int
    successes: int
    success_lo: float
    success_hi: float
    zmp_mean: float
    zmp_lo: float
    zmp_hi: float
    zmp_max_mean: float
    footstep_error: float

    @property
    def success_rate(self) -> float:
        """successes / walks (nan without walks)."""
        return self.successes / self.walks if self.walks else math.nan


def cells(rows: Sequence[dict[str, Any]], modes: Sequence[str]) -> list[Cell]:
    """Every cell with rows, sorted by scene, mode, planner, impulse."""
    out = []
    for mode in modes:
        flag = "smallest_n" if mode == "smallest" else "equal_n"
        sel = [r for r in rows if r[flag]]
        keys = sorted({(r["scene"], r["planner"], r["push_impulse"]) for r in sel})
        for scene, planner, imp in keys:
            rs = [
                r
                for r in sel
                if r["scene"] == scene and r["planner"] == planner and r["push_impulse"] == imp
            ]
            ok = [r for r in rs if r["error"] is None]
            wins = [r for r in ok if r["success"]]
            lo, hi = wilson(len(wins), len(ok))
            m, zlo, zhi = mean_ci([r["zmp_offset_mean"] for r in wins])
            zmax = [r["zmp_offset_max"] for r in wins if math.isfinite(r["zmp_offset_max"])]
            fe = [r["footstep_error_mean"] for r in ok if math.isfinite(r["footstep_error_mean"])]
            out.append(
                Cell(
                    scene,
                    planner,
                    mode,
                    float(imp),
                    int(rs[0]["n_steps"]),
                    len(ok),
                    len(rs) - len(ok),
                    len(wins),
                    lo,
                    hi,
                    m,
                    zlo,
                    zhi,
                    float(np.mean(zmax)) if zmax else math.nan,
                    float(np.mean(fe)) if fe else math.nan,
                )
            )
    out.sort(key=lambda c: (c.scene, c.mode, c.planner, c.impulse))
    return out


@dataclass(frozen=True)
class Paired:
    """``planner`` minus ``baseline`` on the same seeds (negative: ``planner`` lower).

    Attributes: scene, mode, impulse, planner, baseline; pairs (seeds where both succeeded),
    zmp_diff / zmp_lo / zmp_hi (mean paired difference of the mean ZMP offset and its bootstrap
    CI) [m], zmp_p (Wilcoxon signed-rank); seeds (both walked), only_planner / only_baseline
    (seeds only one of them succeeded on), success_p (exact McNemar).
    """

    scene: str
    mode: str
    impulse: float
    planner: str
    baseline: str
    pairs: int
    zmp_diff: float
    zmp_lo: float
    zmp_hi: float
    zmp_p: float
    seeds: int
    only_planner: int
    only_baseline: int
    success_p: float

    @property
    def zmp_significant(self) -> bool:
        """Wilcoxon p < ``ALPHA`` and the CI excludes 0."""
        return (
            self.zmp_p < ALPHA
            and math.isfinite(self.zmp_lo)
            and (self.zmp_hi < 0 or self.zmp_lo > 0)
        )


def zmp_differences(
    a: dict[int, dict[str, Any]], b: dict[int, dict[str, Any]], seeds: Sequence[int]
) -> list[float]:
    """The paired differences ``a - b`` of the mean ZMP offset over ``seeds`` (rows by seed),
    on the seeds where both walks succeeded with a finite offset."""
    return [
        a[s]["zmp_offset_mean"] - b[s]["zmp_offset_mean"]
        for s in seeds
        if a[s]["success"]
        and b[s]["success"]
        and math.isfinite(a[s]["zmp_offset_mean"])
        and math.isfinite(b[s]["zmp_offset_mean"])
    ]


def paired(
    rows: Sequence[dict[str, Any]],
    scene: str,
    mode: str,
    impulse: float,
    planner: str,
    baseline: str,
) -> Paired:
    """The paired comparison of ``planner`` with ``baseline`` (see :class:`Paired`)."""
    sel = [r for r in in_mode(rows, mode) if r["scene"] == scene and r["push_impulse"] == impulse]
    a = {r["seed"]: r for r in sel if r["planner"] == planner}
    b = {r["seed"]: r for r in sel if r["planner"] == baseline}
    both = sorted(set(a) & set(b))
    d = zmp_differences(a, b, both)
    m, lo, hi = mean_ci(d)
    only_a = sum(bool(a[s]["success"]) and not b[s]["success"] for s in both)
    only_b = sum(bool(b[s]["success"]) and not a[s]["success"] for s in both)
    return Paired(
        scene,
        mode,
        float(impulse),
        planner,
        baseline,
        len(d),
        m,
        lo,
        hi,
        wilcoxon_p(d),
        len(both),
        only_a,
        only_b,
        mcnemar_p(only_a, only_b),
    )


def comparisons(
    rows: Sequence[dict[str, Any]],
    scenes: Sequence[str],
    modes: Sequence[str],
    impulse: float,
    planners: Sequence[str],
    claimant: str = CLAIMANT,
) -> list[Paired]:
    """``claimant`` against every other planner, per scene and step mode, at ``impulse``."""
    if claimant not in planners:
        return []
    return [
        paired(rows, scene, mode, impulse, claimant, base)
        for scene in scenes
        for mode in modes
        for base in planners
        if base != claimant
    ]


@dataclass(frozen=True)
class FragilityPoint:
    """Success at one push impulse: scene, planner, mode, impulse [N s], walks, successes and the
    Wilson interval (lo, hi)."""

    scene: str
    planner: str
    mode: str
    impulse: float
    walks: int
    successes: int
    lo: float
    hi: float
    n_steps: int = 0


def fragility(all_cells: Sequence[Cell]) -> list[FragilityPoint]:
    """Success against push impulse per scene, planner and mode (from :func:`cells`)."""
    return [
        FragilityPoint(
            c.scene,
            c.planner,
            c.mode,
            c.impulse,
            c.walks,
            c.successes,
            c.success_lo,
            c.success_hi,
            c.n_steps,
        )
        for c in sorted(all_cells, key=lambda c: (c.scene, c.planner, c.mode, c.impulse))
    ]


#: how a comparison's two step modes are named when they are the same walks
SAME_MODES = "smallest=equal"


def distinct(pairs: Sequence[Paired], n_steps: dict[tuple[str, str, str], int]) -> list[Paired]:
    """The comparisons, each once: where both planners have the same N in two step modes (on a
    scene where the smallest N is the reactive planner's, say), the two comparisons are the same
    walks; the first is kept with the modes joined by ``=`` and the other dropped, so no verdict
    line, table row or count holds it twice."""
    out: list[Paired] = []
    seen: dict[tuple[object, ...], int] = {}
    for p in pairs:
        n_a = n_steps.get((p.scene, p.planner, p.mode))
        n_b = n_steps.get((p.scene, p.baseline, p.mode))
        key = (p.scene, p.planner, p.baseline, p.impulse, n_a, n_b)
        if n_a is None or n_b is None or key not in seen:
            seen[key] = len(out)
            out.append(p)
            continue
        first = out[seen[key]]
        if p.mode not in first.mode.split("="):
            out[seen[key]] = replace(first, mode=f"{first.mode}={p.mode}")
    return out


def _mm(x: float) -> str:
    return f"{1000 * x:+.2f}"


def verdict(pairs: Sequence[Paired], n_steps: dict[tuple[str, str, str], int]) -> list[str]:
    """Document 000's claim (the full-horizon planner has the smaller single-support ZMP offset)
    judged from the paired differences, one line per scene, step mode and baseline (give the
    pairs through :func:`distinct`: a comparison that is two modes' is one line).

    ``n_steps``: N per (scene, planner, mode), so each line says which N it holds for."""
    lines = []
    for p in pairs:
        mode = p.mode.split("=")[0]
        n_a = n_steps.get((p.scene, p.planner, mode))
        n_b = n_steps.get((p.scene, p.baseline, mode))
        head = (
            f"{p.scene}, {p.mode.replace('=', ' = ')} N ({p.planner} N = {n_a}, {p.baseline} "
            f"N = {n_b}), push {p.impulse:g} N s"
        )
        if p.pairs < 2:
            lines.append(
                f"- {head}: cannot be judged: {p.pairs} seed(s) where both walks succeeded."
            )
            continue
        ci = f"{_mm(p.zmp_diff)} mm (95 % CI {_mm(p.zmp_lo)} to {_mm(p.zmp_hi)} mm, Wilcoxon p = {p.zmp_p:.2g}, {p.pairs} pairs)"
        if not p.zmp_significant:
            what = f"not significant: {p.planner} - {p.baseline} = {ci}"
        elif p.zmp_diff < 0:
            what = f"the claim holds: {p.planner} - {p.baseline} = {ci}"
        else:
            what = f"the claim does NOT hold ({p.baseline} is lower): {p.planner} - {p.baseline} = {ci}"
        succ = (
            f"; success differs on {p.only_planner + p.only_baseline} of {p.seeds} seeds "
            f"({p.planner} only {p.only_planner}, {p.baseline} only {p.only_baseline}, "
            f"McNemar p = {p.success_p:.2g})"
        )
        lines.append(f"- {head}: {what}{succ}.")
    return lines
