"""Statistics across terrain families with the terrain as the unit
(footfall.experiments.study.terrain_stats), against hand values and scipy used directly."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest
from scipy import stats as sps

from footfall.experiments.study.runner import PlanEntry
from footfall.experiments.study.terrain_stats import (
    PlanInfo,
    TerrainPaired,
    family_cells,
    family_plans,
    family_verdict,
    plan_info,
    terrain_paired,
    variance_split,
)
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.solvers.base import SolveStatus
from tests.experiments.rows import study_row

T = [f"discrete_steps-t{i:04d}" for i in range(8)]
OTHER_FAMILY = "stairs_slope_gap-t0000"


_row = study_row


def _bca(values: list[float]) -> tuple[float, float]:
    res = sps.bootstrap(
        (np.asarray(values, dtype=float),),
        np.mean,
        confidence_level=0.95,
        n_resamples=4000,
        method="BCa",
        rng=np.random.default_rng(0),
    )
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


# ---------------------------------------------------------------------------------------------
# variance split


def test_variance_split_unbalanced_by_hand() -> None:
    groups = [[1.0, 2.0, 3.0], [4.0, 6.0], [10.0]]
    # within: squared deviations from the group means, (1 + 0 + 1) + (1 + 1) + 0, over
    # (3 - 1) + (2 - 1) + (1 - 1) degrees of freedom
    var_w = 4.0 / 3.0
    means = [2.0, 5.0, 10.0]
    grand = sum(means) / 3
    spread = sum((m - grand) ** 2 for m in means) / 2
    noise = (var_w / 3 + var_w / 2 + var_w / 1) / 3
    var_b = spread - noise
    assert var_b > 0
    sd_b, sd_w, icc = variance_split(groups)
    assert sd_w == pytest.approx(math.sqrt(var_w), rel=1e-12)
    assert sd_b == pytest.approx(math.sqrt(var_b), rel=1e-12)
    assert icc == pytest.approx(var_b / (var_b + var_w), rel=1e-12)
    # numpy directly for the two pieces
    assert var_w == pytest.approx(
        sum(np.var(g, ddof=0) * len(g) for g in groups) / sum(len(g) - 1 for g in groups)
    )
    assert spread == pytest.approx(np.var(means, ddof=1))
    # an empty group is no group
    assert variance_split([[1.0, 2.0, 3.0], [], [4.0, 6.0], [10.0]]) == (sd_b, sd_w, icc)


def test_variance_split_floors_the_between_variance_at_zero() -> None:
    groups = [[0.0, 10.0], [1.0, 11.0]]
    var_w = (25 + 25 + 25 + 25) / 2  # 50
    spread = np.var([5.0, 6.0], ddof=1)  # 0.5
    assert spread - var_w / 2 < 0  # the moment estimate is negative
    sd_b, sd_w, icc = variance_split(groups)
    assert sd_b == 0.0
    assert sd_w == pytest.approx(math.sqrt(var_w), rel=1e-12)
    assert icc == 0.0


def test_variance_split_undefined_parts_are_nan() -> None:
    sd_b, sd_w, icc = variance_split([[1.0, 2.0, 4.0]])
    assert math.isnan(sd_b) and math.isnan(icc)
    assert sd_w == pytest.approx(np.std([1.0, 2.0, 4.0], ddof=1), rel=1e-12)
    # one value per group: no within-group spread to estimate
    sd_b, sd_w, icc = variance_split([[1.0], [2.0], [4.0]])
    assert math.isnan(sd_w) and math.isnan(icc)
    assert sd_b == pytest.approx(np.std([1.0, 2.0, 4.0], ddof=1), rel=1e-12)


# ---------------------------------------------------------------------------------------------
# terrain-paired comparison

#: (planner ZMP, baseline ZMP) of the seeds where both succeeded, per terrain: 1, 2, 3 and 5 seeds
PAIRS: dict[str, list[tuple[float, float]]] = {
    T[0]: [(0.010, 0.020)],
    T[1]: [(0.020, 0.022), (0.016, 0.020)],
    T[2]: [(0.021, 0.020), (0.012, 0.015), (0.018, 0.019)],
    T[3]: [(0.010, 0.016), (0.011, 0.016), (0.012, 0.019), (0.013, 0.017), (0.009, 0.017)],
}


def _hand_means() -> list[float]:
    return [float(np.mean([a - b for a, b in PAIRS[t]])) for t in T[:4]]


def _paired_rows() -> list[dict[str, Any]]:
    rows = []
    for t, pairs in PAIRS.items():
        for s, (za, zb) in enumerate(pairs):
            rows += [_row("miqcqp", s, True, za, scene=t), _row("kinematic", s, True, zb, scene=t)]
    # T1 seed 5: the planner fell: not a ZMP pair
    rows += [
        _row("miqcqp", 5, False, 0.300, scene=T[1]),
        _row("kinematic", 5, True, 0.001, scene=T[1]),
    ]
    # T2 seed 6: the baseline's walk is an error: not walked by both
    rows += [
        _row("miqcqp", 6, True, 0.900, scene=T[2]),
        _row("kinematic", 6, True, 0.0, scene=T[2], error="Boom: x"),
    ]
    # left out: other step mode, other impulse, other planner, other family, errors
    rows += [
        _row("miqcqp", 7, True, 0.001, scene=T[0], smallest=False, equal=True),
        _row("kinematic", 7, True, 0.900, scene=T[0], smallest=False, equal=True),
        _row("miqcqp", 0, True, 0.001, scene=T[3], impulse=0.0),
        _row("kinematic", 0, True, 0.900, scene=T[3], impulse=0.0),
        _row("reactive", 0, True, 0.900, scene=T[2], equal=True, n_steps=11),
        _row("miqcqp", 0, True, 0.001, scene=OTHER_FAMILY),
        _row("kinematic", 0, True, 0.900, scene=OTHER_FAMILY),
        _row("miqcqp", 8, True, 0.001, scene=T[3], error="Boom: y"),
        _row("kinematic", 8, True, 0.900, scene=T[3], error="Boom: z"),
    ]
    return rows


def _all_proven(planners: tuple[str, ...] = ("miqcqp", "kinematic")) -> dict[Any, PlanInfo]:
    return {(t, p, "smallest"): PlanInfo("optimal", 7) for t in T[:4] for p in planners}


def test_terrain_paired_weighs_each_terrain_the_same() -> None:
    rows = _paired_rows()
    tp = terrain_paired(
        rows, "discrete_steps", T[:4], _all_proven(), "smallest", 3.0, "miqcqp", "kinematic"
    )
    means = _hand_means()
    pooled = float(np.mean([a - b for t in T[:4] for a, b in PAIRS[t]]))
    mean_of_means = float(np.mean(means))
    assert abs(mean_of_means - pooled) > 1e-4  # the example tells the two apart
    assert tp.diff == pytest.approx(mean_of_means, rel=1e-12)
    assert tp.diff != pytest.approx(pooled, rel=1e-3)
    assert (tp.terrains, tp.pairs) == (4, 11)
    assert (tp.family, tp.mode, tp.impulse, tp.planner, tp.baseline) == (
        "discrete_steps",
        "smallest",
        3.0,
        "miqcqp",
        "kinematic",
    )
    # the Wilcoxon test and the BCa bootstrap of the four terrain means
    assert tp.p == pytest.approx(sps.wilcoxon(means, zero_method="wilcox").pvalue, rel=1e-12)
    lo, hi = _bca(means)
    assert tp.lo == pytest.approx(lo, abs=1e-12)
    assert tp.hi == pytest.approx(hi, abs=1e-12)
    # the variance split of the seed differences grouped by terrain, by hand
    groups = [[a - b for a, b in PAIRS[t]] for t in T[:4]]
    dof = sum(len(g) - 1 for g in groups)
    var_w = sum(sum((x - np.mean(g)) ** 2 for x in g) for g in groups) / dof
    var_b = max(0.0, np.var(means, ddof=1) - np.mean([var_w / len(g) for g in groups]))
    assert tp.sd_within == pytest.approx(math.sqrt(var_w), rel=1e-9)
    assert tp.sd_between == pytest.approx(math.sqrt(var_b), rel=1e-9)
    # every plan proven and of equal N: nothing marked
    assert (tp.time_limited, tp.unequal_n, tp.proven_terrains) == (0, 0, 4)
    assert tp.proven_diff == tp.diff and (tp.proven_lo, tp.proven_hi) == (tp.lo, tp.hi)
    assert (tp.no_plan_planner, tp.no_plan_baseline) == (0, 0)
    # success over the seeds both walked: only T1 differs (seed 5: the planner fell)
    assert (tp.terrains_better, tp.terrains_worse) == (0, 1)
    assert tp.success_p == pytest.approx(sps.binomtest(0, 1, 0.5).pvalue)


def test_terrain_paired_marks_time_limits_unequal_n_and_missing_plans() -> None:
    """The planner (miqcqp) against the reactive planner, whose plans are keyed under ``goal``."""
    diffs = {
        T[0]: [-0.004, -0.006],
        T[1]: [-0.002],
        T[2]: [-0.020, -0.010],  # the planner's plan stopped at the time limit
        T[3]: [0.001, -0.003, -0.002],  # the two plans have different N
        T[4]: [-0.001, -0.002],
    }
    rows = []
    for t, ds in diffs.items():
        for s, d in enumerate(ds):
            rows += [
                _row("miqcqp", s, True, 0.02 + d, scene=t),
                _row("reactive", s, True, 0.02, scene=t, equal=True, n_steps=11),
            ]
    # T5: no miqcqp plan (no walks of it); T6: missing from the plan map altogether
    rows += [_row("reactive", 0, True, 0.02, scene=T[5], equal=True, n_steps=11)]
    terrains = T[:7]
    plans: dict[tuple[str, str, str], PlanInfo] = {}
    for t in T[:6]:
        plans[t, "miqcqp", "smallest"] = PlanInfo("optimal", 11)
        plans[t, "reactive", "goal"] = PlanInfo("feasible", 11)
    plans[T[2], "miqcqp", "smallest"] = PlanInfo("time_limit", 11)
    plans[T[3], "miqcqp", "smallest"] = PlanInfo("optimal", 9)
    plans[T[5], "miqcqp", "smallest"] = PlanInfo("infeasible", None)
    # decoys: the reactive planner's plans are not looked up under the step mode
    for t in terrains:
        plans[t, "reactive", "smallest"] = PlanInfo("time_limit", 5)
    tp = terrain_paired(
        rows, "discrete_steps", terrains, plans, "smallest", 3.0, "miqcqp", "reactive"
    )
    # the walked differences, as the code sees them: (0.02 + d) - 0.02
    means = {t: float(np.mean([(0.02 + d) - 0.02 for d in ds])) for t, ds in diffs.items()}
    assert (tp.terrains, tp.pairs) == (5, 10)
    assert tp.diff == pytest.approx(np.mean(list(means.values())), rel=1e-12)
    assert tp.time_limited == 1
    assert tp.proven_terrains == 4
    proven = [means[t] for t in (T[0], T[1], T[3], T[4])]
    assert tp.proven_diff == pytest.approx(np.mean(proven), rel=1e-12)
    assert tp.proven_p == pytest.approx(sps.wilcoxon(proven).pvalue, rel=1e-12)
    lo, hi = _bca(proven)
    assert (tp.proven_lo, tp.proven_hi) == (
        pytest.approx(lo, abs=1e-12),
        pytest.approx(hi, abs=1e-12),
    )
    assert tp.unequal_n == 1
    assert tp.no_plan_planner == 2  # T5 (no solution) and T6 (not in the map)
    assert tp.no_plan_baseline == 1  # T6
    line = family_verdict([tp], {"discrete_steps": 7})[0]
    assert "1 of the 5 with a time-limited plan" in line
    assert "on the 4 with proven plans" in line
    assert "N differs on 1" in line


def _success_rows() -> list[dict[str, Any]]:
    """Four seeds per terrain; success (planner, baseline) per terrain."""
    wins = {
        T[0]: ((1, 1, 1, 1), (1, 1, 1, 0)),  # better
        T[1]: ((1, 1, 1, 0), (1, 1, 0, 0)),  # better
        T[2]: ((1, 1, 0, 0), (0, 1, 0, 0)),  # better
        T[3]: ((1, 0, 0, 0), (1, 1, 1, 0)),  # worse
        T[4]: ((1, 1, 0, 0), (0, 0, 1, 1)),  # equal rates
    }
    rows = []
    for t, (a, b) in wins.items():
        for s in range(4):
            rows += [
                _row("miqcqp", s, bool(a[s]), 0.010 + 0.001 * s, scene=t),
                _row("kinematic", s, bool(b[s]), 0.012 + 0.001 * s, scene=t),
            ]
    # not walked by both: an error, a walk of one planner only
    rows += [
        _row("miqcqp", 4, True, 0.01, scene=T[3]),
        _row("kinematic", 4, True, 0.01, scene=T[3], error="Boom: x"),
        _row("miqcqp", 5, True, 0.01, scene=T[3]),
        _row("miqcqp", 0, True, 0.01, scene=T[5]),  # T5: only the planner walked
    ]
    return rows


def test_terrain_paired_success_sign_test() -> None:
    plans = _all_proven()
    tp = terrain_paired(
        _success_rows(), "discrete_steps", T[:6], plans, "smallest", 3.0, "miqcqp", "kinematic"
    )
    assert (tp.terrains_better, tp.terrains_worse) == (3, 1)
    assert tp.success_p == pytest.approx(sps.binomtest(3, 4, 0.5).pvalue, rel=1e-12)
    # swapped: the counts swap, the two-sided p stays
    tq = terrain_paired(
        _success_rows(), "discrete_steps", T[:6], plans, "smallest", 3.0, "kinematic", "miqcqp"
    )
    assert (tq.terrains_better, tq.terrains_worse) == (1, 3)
    assert tq.success_p == pytest.approx(tp.success_p, rel=1e-12)


# ---------------------------------------------------------------------------------------------
# verdict


def _base() -> TerrainPaired:
    return terrain_paired(
        _paired_rows(),
        "discrete_steps",
        T[:4],
        _all_proven(),
        "smallest",
        3.0,
        "miqcqp",
        "kinematic",
    )


def test_family_verdict_wording() -> None:
    base = _base()
    holds = replace(base, diff=-0.005, lo=-0.007, hi=-0.003, p=0.01)
    fails = replace(base, diff=0.005, lo=0.003, hi=0.007, p=0.01)
    ns_p = replace(base, diff=-0.005, lo=-0.007, hi=-0.003, p=0.2)
    ns_ci = replace(base, diff=-0.005, lo=-0.007, hi=0.001, p=0.01)  # the CI holds 0
    few = replace(base, terrains=1, pairs=3)
    lines = family_verdict([holds, fails, ns_p, ns_ci, few], {"discrete_steps": 12})
    assert len(lines) == 5
    h, f, n1, n2, c = lines
    assert "the claim holds" in h and "not significant" not in h and "NOT" not in h
    assert "-5.00 mm" in h and "-7.00" in h and "-3.00" in h
    assert "does NOT hold" in f and "the claim holds" not in f and "+5.00 mm" in f
    for line in (n1, n2):
        assert "not significant" in line and "holds" not in line
    assert "cannot be judged" in c and "1 terrain(s)" in c
    for line in lines:
        assert line.startswith("- discrete_steps (12 terrains), smallest N, miqcqp vs kinematic")
    for line in lines[:4]:
        assert f"{base.terrains} terrains, {base.pairs} seed pairs" in line
        assert "0 of the 4 with a time-limited plan" in line and "proven plans" not in line


def test_family_verdict_marks_time_limited_terrains() -> None:
    base = _base()
    marked = replace(
        base,
        diff=-0.005,
        lo=-0.007,
        hi=-0.003,
        p=0.01,
        time_limited=1,
        proven_terrains=3,
        proven_diff=0.002,
        proven_lo=0.001,
        proven_hi=0.003,
        proven_p=0.01,
    )
    (line,) = family_verdict([marked], {"discrete_steps": 4})
    assert "time-limited" in line and "proven plans" in line
    assert "1 of the 4 with a time-limited plan" in line
    # the claim holds over all terrains but not on those with proven plans: both are said
    assert "the claim holds" in line and "does NOT hold" in line and "+2.00 mm" in line
    too_few = replace(marked, time_limited=3, proven_terrains=1)
    (line,) = family_verdict([too_few], {"discrete_steps": 4})
    assert "time-limited" in line and "1 with proven plans: too few to judge" in line


# ---------------------------------------------------------------------------------------------
# cells


def test_family_cells_average_terrains_not_walks() -> None:
    walks = {  # (success, ZMP) per seed: 4, 1, 5 and 2 seeds
        T[0]: [(True, 0.01), (True, 0.02), (True, 0.03), (False, 0.5)],
        T[1]: [(True, 0.05)],
        T[2]: [(False, 0.6), (False, 0.7), (True, 0.04), (False, 0.8), (True, 0.06)],
        T[3]: [(False, 0.9), (False, 0.9)],
    }
    rows = [
        _row("miqcqp", s, ok, z, scene=t) for t, ws in walks.items() for s, (ok, z) in enumerate(ws)
    ]
    rows += [
        _row("kinematic", 0, True, 0.03, scene=T[0]),
        _row("kinematic", 1, False, 0.9, scene=T[0]),
        _row("miqcqp", 9, True, 0.0, scene=T[1], error="Boom: x"),  # an error: left out
        _row("miqcqp", 9, True, 0.5, scene=T[1], smallest=False, equal=True),  # other mode
        _row("miqcqp", 9, True, 0.5, scene=T[1], impulse=0.0),  # other impulse
        _row("miqcqp", 0, False, 0.5, scene=OTHER_FAMILY),  # other family
    ]
    cells = family_cells(
        rows, {"discrete_steps": T[:4]}, ["smallest"], 3.0, ["miqcqp", "kinematic"]
    )
    by = {c.planner: c for c in cells}
    assert set(by) == {"miqcqp", "kinematic"}
    c = by["miqcqp"]
    rates = [3 / 4, 1 / 1, 2 / 5, 0 / 2]
    zmps = [(0.01 + 0.02 + 0.03) / 3, 0.05, (0.04 + 0.06) / 2]  # T3: no successful walk
    pooled_rate = 6 / 12
    pooled_zmp = (0.01 + 0.02 + 0.03 + 0.05 + 0.04 + 0.06) / 6
    assert (c.family, c.mode, c.impulse, c.terrains, c.walks) == (
        "discrete_steps",
        "smallest",
        3.0,
        4,
        12,
    )
    assert c.success == pytest.approx(sum(rates) / 4, rel=1e-12)
    assert abs(c.success - pooled_rate) > 0.03  # 0.5375 against 0.5
    assert c.zmp == pytest.approx(sum(zmps) / 3, rel=1e-12)
    assert abs(c.zmp - pooled_zmp) > 1e-3
    lo, hi = _bca(rates)
    assert (c.success_lo, c.success_hi) == (
        pytest.approx(lo, abs=1e-12),
        pytest.approx(hi, abs=1e-12),
    )
    k = by["kinematic"]
    assert (k.terrains, k.walks, k.success, k.zmp) == (1, 2, 0.5, 0.03)
    assert math.isnan(k.success_lo) and math.isnan(k.zmp_lo)  # one terrain: no interval


# ---------------------------------------------------------------------------------------------
# plan outcomes

ROBOT = BipedParams()


def _plan(planner: str, status: str, n: int | None, solve_time: float, gap: float) -> FootstepPlan:
    if n is None:
        return FootstepPlan.empty(
            planner, SolveStatus(status), ROBOT, "no plan", solve_time=solve_time, gap=gap
        )
    k = ROBOT.n_nodes
    sides = tuple(Side.RIGHT if i % 2 == 0 else Side.LEFT for i in range(n + 1))
    return FootstepPlan(
        planner=planner,
        status=SolveStatus(status),
        robot=ROBOT,
        footsteps=np.array([[0.2 * i, 0.1 if i % 2 else -0.1, 0.0] for i in range(n + 1)]),
        headings=np.zeros(n + 1),
        sides=sides,
        regions=("r",) * (n + 1),
        states=np.zeros((n, k, 4)),
        torques=np.zeros((n, k - 1, 2)),
        final_state=np.zeros(4),
        solve_time=solve_time,
        gap=gap,
    )


def test_family_plans_counts_and_medians() -> None:
    spec = [  # (terrain, status, N, solve time, gap) of the miqcqp smallest-N plans
        (T[0], "optimal", 7, 1.0, 0.0),
        (T[1], "optimal", 9, 3.0, 0.0),
        (T[2], "time_limit", 11, 30.0, 0.2),
        (T[3], "time_limit", 8, 31.0, 0.4),
        (T[4], "feasible", 10, 32.0, math.inf),  # stopped early, gap unknown
        (T[5], "time_limit", None, 33.0, math.inf),  # stopped without a plan
    ]
    entries = [
        PlanEntry(t, "miqcqp", "smallest", _plan("miqcqp", s, n, st, g), 0.0)
        for t, s, n, st, g in spec
    ]
    entries += [
        PlanEntry(T[0], "reactive", "goal", _plan("reactive", "feasible", 12, 0.5, math.inf), 0.0),
        PlanEntry(T[1], "reactive", "goal", _plan("reactive", "feasible", 14, 0.7, math.inf), 0.0),
        PlanEntry(OTHER_FAMILY, "miqcqp", "smallest", _plan("miqcqp", "optimal", 5, 2.0, 0.0), 0.0),
    ]
    out = family_plans(entries, {"discrete_steps": T[:6], "stairs_slope_gap": [OTHER_FAMILY]})
    by = {(f.family, f.planner, f.mode): f for f in out}
    assert set(by) == {
        ("discrete_steps", "miqcqp", "smallest"),
        ("discrete_steps", "reactive", "goal"),
        ("stairs_slope_gap", "miqcqp", "smallest"),
    }
    m = by["discrete_steps", "miqcqp", "smallest"]
    assert (m.terrains, m.optimal, m.time_limited, m.no_plan) == (6, 2, 3, 1)
    assert m.n_median == 9.0  # median of 7, 9, 11, 8, 10
    assert m.time_median == 30.5  # median of 1, 3, 30, 31, 32, 33
    assert m.gap_median == pytest.approx(0.3, rel=1e-12)  # median of 0.2 and 0.4 (inf left out)
    r = by["discrete_steps", "reactive", "goal"]
    assert (r.terrains, r.optimal, r.time_limited, r.no_plan) == (2, 2, 0, 0)
    assert (r.n_median, r.time_median) == (13.0, pytest.approx(0.6, rel=1e-12))
    assert math.isnan(r.gap_median)
    o = by["stairs_slope_gap", "miqcqp", "smallest"]
    assert (o.terrains, o.optimal, o.time_limited, o.no_plan, o.n_median) == (1, 1, 0, 0, 5.0)


def test_a_reactive_walk_short_of_the_goal_is_no_plan_and_leaves_the_comparison() -> None:
    """A reactive plan that stopped before the goal (``incomplete``) has footsteps but is not the
    walk the study compares: it counts as no plan, and its terrain's rows are left out."""
    assert plan_info("reactive", "incomplete", True, 3) == PlanInfo("incomplete", None)
    assert plan_info("reactive", "feasible", True, 3) == PlanInfo("feasible", 3)
    assert plan_info("miqcqp", "time_limit", True, 9) == PlanInfo("time_limit", 9)
    assert plan_info("miqcqp", "time_limit", False, 0) == PlanInfo("time_limit", None)
    entries = [
        PlanEntry(T[0], "reactive", "goal", _plan("reactive", "incomplete", 3, 0.5, math.inf), 0.0),
        PlanEntry(T[1], "reactive", "goal", _plan("reactive", "feasible", 12, 0.5, math.inf), 0.0),
    ]
    (r,) = family_plans(entries, {"discrete_steps": T[:2]})
    assert (r.terrains, r.optimal, r.time_limited, r.no_plan) == (2, 1, 0, 1)
    rows = []
    for t, (za, zb) in ((T[0], (0.010, 0.050)), (T[1], (0.020, 0.025))):
        rows += [
            _row("miqcqp", 0, True, za, scene=t),
            _row("reactive", 0, True, zb, scene=t),
        ]
    infos = {
        (T[0], "miqcqp", "smallest"): PlanInfo("optimal", 7),
        (T[1], "miqcqp", "smallest"): PlanInfo("optimal", 7),
        (T[0], "reactive", "goal"): plan_info("reactive", "incomplete", True, 3),
        (T[1], "reactive", "goal"): plan_info("reactive", "feasible", True, 7),
    }
    p = terrain_paired(rows, "discrete_steps", T[:2], infos, "smallest", 3.0, "miqcqp", "reactive")
    assert (p.terrains, p.pairs, p.no_plan_baseline, p.time_limited) == (1, 1, 1, 0)
    assert p.diff == pytest.approx(0.020 - 0.025, abs=1e-15)
