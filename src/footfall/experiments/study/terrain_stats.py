"""Statistics of a study across terrain families, with the terrain as the random unit.

A family study (``families`` in the design) walks every planner on many generated terrains
(:mod:`footfall.terrain.families`) with a few pushed seeds each. Seeds on one terrain share its
plans, so they are not independent samples of "the planner on such terrain": the claim is about
terrains, and the terrain is the unit that is resampled.

For a family, a step mode and a (planner, baseline) pair at one push impulse:

- per terrain ``t``, the paired differences ``d_ts`` of the mean ZMP offset over the seeds ``s``
  where both walks succeeded (the same seed: the same push), and their mean ``dbar_t``;
- the estimate is the mean of ``dbar_t`` over terrains (each terrain weighs the same);
- its CI is the cluster bootstrap over terrains: resampling terrains with all their seeds and
  averaging the terrain means is resampling the ``dbar_t``, so it is the BCa bootstrap of the
  terrain means (:func:`~footfall.experiments.study.stats.mean_ci`, 4000 resamples, fixed seed);
- its test is the Wilcoxon signed-rank test of the ``dbar_t`` (one value per terrain);
- the hierarchical summary is the one-way random-effects split (method of moments) of the
  ``d_ts`` into a between-terrain and a within-terrain (seed) variance, and the share of the
  first (the intraclass correlation): how much of what one seed shows is the terrain's.

A plan stopped by the planner's time limit is not a proven optimum: a terrain where either plan
was is counted (``time_limited``) and the comparison is also given on the terrains where both
plans were proven (``proven_*``), so a time-limited plan never enters a comparison unmarked.
Terrains where a planner found no plan have no walks of it and are counted per planner.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats as sps

from footfall.experiments.study.stats import (
    ALPHA,
    CLAIMANT,
    in_mode,
    mean_ci,
    wilcoxon_p,
    zmp_differences,
)

#: plan statuses that are a proven optimum or a plan that claims no optimality (the reactive
#: planner's); everything else with a solution was stopped early
PROVEN = ("optimal", "feasible")


@dataclass(frozen=True)
class PlanInfo:
    """What a comparison needs to know of one plan: its status and N (None: no plan)."""

    status: str
    n_steps: int | None


def plan_info(planner: str, status: str, has_solution: bool, n_steps: int) -> PlanInfo:
    """The :class:`PlanInfo` of a plan. A reactive walk that stopped short of the goal
    (``incomplete``) is no plan of the goal: it has footsteps, but not the walk the study
    compares, so it counts as no plan (and its terrain leaves the comparison)."""
    walkable = has_solution and (planner != "reactive" or status in PROVEN)
    return PlanInfo(status, int(n_steps) if walkable else None)


def _proven(info: PlanInfo | None, planner: str) -> bool:
    if info is None:
        return False
    if planner == "reactive":
        return info.status in PROVEN
    return info.status == "optimal"


@dataclass(frozen=True)
class TerrainPaired:
    """One comparison across a family's terrains (see the module docstring); lengths in metres.

    Attributes:
        family, mode, impulse, planner, baseline: what is compared.
        terrains: terrains with at least one seed where both walks succeeded (the sample).
        pairs: seed pairs (both succeeded) over those terrains.
        diff, lo, hi, p: mean over terrains of the per-terrain mean difference (planner minus
            baseline), its cluster-bootstrap CI and the Wilcoxon p over terrains.
        sd_between, sd_within, icc: random-effects split of the seed differences.
        time_limited: terrains of the sample where either plan stopped at the time limit.
        unequal_n: terrains of the sample where the two plans have different N.
        proven_terrains, proven_diff, proven_lo, proven_hi, proven_p: the same on the terrains
            where both plans are proven.
        no_plan_planner, no_plan_baseline: family terrains without a plan of either.
        terrains_better, terrains_worse: terrains whose success rate is higher (lower) for the
            planner than for the baseline, and success_p: their two-sided sign test.
    """

    family: str
    mode: str
    impulse: float
    planner: str
    baseline: str
    terrains: int
    pairs: int
    diff: float
    lo: float
    hi: float
    p: float
    sd_between: float
    sd_within: float
    icc: float
    time_limited: int
    unequal_n: int
    proven_terrains: int
    proven_diff: float
    proven_lo: float
    proven_hi: float
    proven_p: float
    no_plan_planner: int
    no_plan_baseline: int
    terrains_better: int
    terrains_worse: int
    success_p: float

    @property
    def significant(self) -> bool:
        """Wilcoxon p < ``ALPHA`` over terrains and the CI excludes 0."""
        return _significant(self.p, self.lo, self.hi)

    @property
    def proven_significant(self) -> bool:
        """The same on the terrains with proven plans."""
        return _significant(self.proven_p, self.proven_lo, self.proven_hi)


def _significant(p: float, lo: float, hi: float) -> bool:
    return p < ALPHA and math.isfinite(lo) and (hi < 0 or lo > 0)


def variance_split(groups: Sequence[Sequence[float]]) -> tuple[float, float, float]:
    """One-way random-effects split (method of moments) of values grouped by terrain.

    Returns ``(sd_between, sd_within, icc)``: the within-group variance is the pooled variance
    around the group means, the between-group variance the variance of the group means less the
    mean of ``var_within / n_t`` (floored at 0), and ``icc = var_b / (var_b + var_w)``
    (nan where undefined)."""
    gs = [np.asarray(g, dtype=float) for g in groups if len(g) > 0]
    dof = sum(g.size - 1 for g in gs)
    var_w = sum(float(np.sum((g - g.mean()) ** 2)) for g in gs) / dof if dof > 0 else math.nan
    if len(gs) < 2:
        return math.nan, math.sqrt(var_w) if math.isfinite(var_w) else math.nan, math.nan
    means = np.array([g.mean() for g in gs])
    spread = float(np.var(means, ddof=1))
    noise = float(np.mean([var_w / g.size for g in gs])) if math.isfinite(var_w) else 0.0
    var_b = max(0.0, spread - noise)
    sd_w = math.sqrt(var_w) if math.isfinite(var_w) else math.nan
    total = var_b + (var_w if math.isfinite(var_w) else 0.0)
    icc = var_b / total if total > 0 and math.isfinite(var_w) else math.nan
    return math.sqrt(var_b), sd_w, icc


def _mode_key(planner: str, mode: str) -> str:
    return "goal" if planner == "reactive" else mode


def terrain_paired(
    rows: Sequence[dict[str, Any]],
    family: str,
    terrains: Sequence[str],
    plans: Mapping[tuple[str, str, str], PlanInfo],
    mode: str,
    impulse: float,
    planner: str,
    baseline: str,
) -> TerrainPaired:
    """The comparison of ``planner`` with ``baseline`` over the scenes ``terrains`` of
    ``family`` (see :class:`TerrainPaired`); ``plans`` by (scene, planner, mode), the reactive
    planner's under mode ``goal``."""
    names = set(terrains)
    sel = [r for r in in_mode(rows, mode) if r["scene"] in names and r["push_impulse"] == impulse]
    by: dict[tuple[str, str], dict[int, dict[str, Any]]] = {}
    for r in sel:
        by.setdefault((r["scene"], r["planner"]), {})[r["seed"]] = r
    diffs: dict[str, list[float]] = {}
    better = worse = 0
    for t in terrains:
        a, b = by.get((t, planner), {}), by.get((t, baseline), {})
        both = sorted(set(a) & set(b))
        d = zmp_differences(a, b, both)
        if d:
            diffs[t] = d
        if both:
            sa = sum(bool(a[s]["success"]) for s in both) / len(both)
            sb = sum(bool(b[s]["success"]) for s in both) / len(both)
            better += sa > sb
            worse += sa < sb
    info = {
        t: (
            plans.get((t, planner, _mode_key(planner, mode))),
            plans.get((t, baseline, _mode_key(baseline, mode))),
        )
        for t in terrains
    }
    for t in list(diffs):  # a terrain where either planner is known to have no plan is out
        if any(x is not None and x.n_steps is None for x in info[t]):
            del diffs[t]
    proven = [t for t in diffs if _proven(info[t][0], planner) and _proven(info[t][1], baseline)]
    unequal = 0
    for t in diffs:
        ia, ib = info[t]
        unequal += ia is not None and ib is not None and ia.n_steps != ib.n_steps

    def no_plan(p: str) -> int:
        return sum(
            1
            for t in terrains
            if (x := plans.get((t, p, _mode_key(p, mode)))) is None or x.n_steps is None
        )

    means = [float(np.mean(diffs[t])) for t in diffs]
    m, lo, hi = mean_ci(means)
    pm, plo, phi = mean_ci([float(np.mean(diffs[t])) for t in proven])
    sd_b, sd_w, icc = variance_split(list(diffs.values()))
    n_sign = better + worse
    return TerrainPaired(
        family=family,
        mode=mode,
        impulse=float(impulse),
        planner=planner,
        baseline=baseline,
        terrains=len(diffs),
        pairs=sum(len(d) for d in diffs.values()),
        diff=m,
        lo=lo,
        hi=hi,
        p=wilcoxon_p(means),
        sd_between=sd_b,
        sd_within=sd_w,
        icc=icc,
        time_limited=len(diffs) - len(proven),
        unequal_n=unequal,
        proven_terrains=len(proven),
        proven_diff=pm,
        proven_lo=plo,
        proven_hi=phi,
        proven_p=wilcoxon_p([float(np.mean(diffs[t])) for t in proven]),
        no_plan_planner=no_plan(planner),
        no_plan_baseline=no_plan(baseline),
        terrains_better=better,
        terrains_worse=worse,
        success_p=1.0 if n_sign == 0 else float(sps.binomtest(better, n_sign, 0.5).pvalue),
    )


def family_comparisons(
    rows: Sequence[dict[str, Any]],
    families: Mapping[str, Sequence[str]],
    plans: Mapping[tuple[str, str, str], PlanInfo],
    modes: Sequence[str],
    impulse: float,
    planners: Sequence[str],
    claimant: str = CLAIMANT,
) -> list[TerrainPaired]:
    """``claimant`` against every other planner, per family (its terrains' scene names) and
    step mode, at ``impulse``."""
    if claimant not in planners:
        return []
    return [
        terrain_paired(rows, family, terrains, plans, mode, impulse, claimant, base)
        for family, terrains in families.items()
        for mode in modes
        for base in planners
        if base != claimant
    ]


def _mm(x: float) -> str:
    return f"{1000 * x:+.2f}"


def _judged(diff: float, lo: float, hi: float, p: float, significant: bool) -> str:
    ci = f"{_mm(diff)} mm (95 % CI {_mm(lo)} to {_mm(hi)} mm, Wilcoxon p = {p:.2g})"
    if not significant:
        return f"not significant, {ci}"
    if diff < 0:
        return f"the claim holds, {ci}"
    return f"the claim does NOT hold (the baseline is lower), {ci}"


def family_verdict(pairs: Sequence[TerrainPaired], terrains: Mapping[str, int]) -> list[str]:
    """Document 000's claim judged per family, step mode and baseline with the terrain as the
    unit, one line each; ``terrains``: the family's terrain count. Every line names the sample
    (terrains, seed pairs), the time-limited terrains and, where there are any, the result on the
    terrains with proven plans."""
    lines = []
    for p in pairs:
        head = (
            f"{p.family} ({terrains.get(p.family, 0)} terrains), {p.mode} N, {p.planner} vs "
            f"{p.baseline}, push {p.impulse:g} N s"
        )
        if p.terrains < 2:
            lines.append(
                f"- {head}: cannot be judged: {p.terrains} terrain(s) where both walks "
                "succeeded on a seed."
            )
            continue
        sample = f"{p.terrains} terrains, {p.pairs} seed pairs"
        what = _judged(p.diff, p.lo, p.hi, p.p, p.significant)
        marked = f"; {p.time_limited} of the {p.terrains} with a time-limited plan"
        if p.time_limited and p.proven_terrains >= 2:
            marked += (
                f" (on the {p.proven_terrains} with proven plans: "
                + _judged(p.proven_diff, p.proven_lo, p.proven_hi, p.proven_p, p.proven_significant)
                + ")"
            )
        elif p.time_limited:
            marked += f" ({p.proven_terrains} with proven plans: too few to judge)"
        if p.unequal_n:
            marked += f"; N differs on {p.unequal_n}"
        icc = "" if not math.isfinite(p.icc) else f"; terrain share of the variance {p.icc:.0%}"
        lines.append(f"- {head}: {what} over {sample}{marked}{icc}.")
    return lines


@dataclass(frozen=True)
class FamilyCell:
    """One (family, step mode, planner) at one impulse, the terrain as the unit.

    Attributes: family, mode, planner, impulse [N s]; terrains (with walks), walks;
    success / success_lo / success_hi: mean over terrains of the terrain's success rate and its
    cluster-bootstrap CI; zmp / zmp_lo / zmp_hi: mean over terrains of the terrain's mean ZMP
    offset of its successful walks and its CI [m].
    """

    family: str
    mode: str
    planner: str
    impulse: float
    terrains: int
    walks: int
    success: float
    success_lo: float
    success_hi: float
    zmp: float
    zmp_lo: float
    zmp_hi: float


def family_cells(
    rows: Sequence[dict[str, Any]],
    families: Mapping[str, Sequence[str]],
    modes: Sequence[str],
    impulse: float,
    planners: Sequence[str],
) -> list[FamilyCell]:
    """Per family, step mode and planner at ``impulse``: success and ZMP offset with the
    terrain as the unit (see :class:`FamilyCell`)."""
    out = []
    for family, terrains in families.items():
        names = set(terrains)
        for mode in modes:
            sel = [
                r
                for r in in_mode(rows, mode)
                if r["scene"] in names and r["push_impulse"] == impulse
            ]
            for planner in planners:
                per: dict[str, list[dict[str, Any]]] = {}
                for r in sel:
                    if r["planner"] == planner:
                        per.setdefault(r["scene"], []).append(r)
                rates = [sum(bool(r["success"]) for r in rs) / len(rs) for rs in per.values()]
                ok = [
                    [
                        r["zmp_offset_mean"]
                        for r in rs
                        if r["success"] and math.isfinite(r["zmp_offset_mean"])
                    ]
                    for rs in per.values()
                ]
                s, slo, shi = mean_ci(rates)
                z, zlo, zhi = mean_ci([float(np.mean(v)) for v in ok if v])
                out.append(
                    FamilyCell(
                        family,
                        mode,
                        planner,
                        float(impulse),
                        len(per),
                        sum(len(rs) for rs in per.values()),
                        s,
                        slo,
                        shi,
                        z,
                        zlo,
                        zhi,
                    )
                )
    return out


@dataclass(frozen=True)
class FamilyPlans:
    """The plans of one (family, planner, step mode): how many terrains got each outcome.

    Attributes: family, planner, mode; terrains; optimal (proven; ``feasible`` for the reactive
    planner, which claims no optimality); time_limited (stopped with a plan); no_plan;
    n_median (N of the plans); time_median (solve time [s]); gap_median (relative gap of the
    time-limited plans; nan without any)."""

    family: str
    planner: str
    mode: str
    terrains: int
    optimal: int
    time_limited: int
    no_plan: int
    n_median: float
    time_median: float
    gap_median: float


def family_plans(plans: Sequence[Any], families: Mapping[str, Sequence[str]]) -> list[FamilyPlans]:
    """Plan outcomes per family, planner and mode, from the study's
    :class:`~footfall.experiments.study.runner.PlanEntry` list."""
    out = []
    for family, terrains in families.items():
        names = set(terrains)
        keys = dict.fromkeys((p.planner, p.mode) for p in plans if p.scene in names)
        for planner, mode in keys:
            sel = [p for p in plans if p.scene in names and (p.planner, p.mode) == (planner, mode)]
            infos = [
                plan_info(planner, p.plan.status.value, p.plan.has_solution, p.plan.n_steps)
                for p in sel
            ]
            solved = [p for p, i in zip(sel, infos, strict=True) if i.n_steps is not None]
            proven = [p for p in solved if _proven(PlanInfo(p.plan.status.value, 0), planner)]
            limited = [p for p in solved if p not in proven]
            gaps = [p.plan.gap for p in limited if math.isfinite(p.plan.gap)]
            out.append(
                FamilyPlans(
                    family,
                    planner,
                    mode,
                    len(sel),
                    len(proven),
                    len(limited),
                    len(sel) - len(solved),
                    float(np.median([p.plan.n_steps for p in solved])) if solved else math.nan,
                    float(np.median([p.plan.solve_time for p in sel])) if sel else math.nan,
                    float(np.median(gaps)) if gaps else math.nan,
                )
            )
    return out
