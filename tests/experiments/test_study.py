"""`footfall study` without walking: the design file, the statistics against hand values and scipy
used directly, and the Parquet store (the paired disturbance: tests/sim/test_disturbance.py)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy import stats as sps

from footfall.errors import InputError
from footfall.experiments.study import (
    BUILTIN_STUDIES,
    COLUMNS,
    StudyDesign,
    builtin_study,
    load_study,
    parse_study,
)
from footfall.experiments.study import stats as st
from footfall.experiments.study import store as store_mod
from footfall.experiments.study.design import MAX_TRIALS, study_from_dict
from footfall.experiments.study.store import TrialStore, read_rows
from footfall.experiments.study.trials import normalise_row
from tests.experiments.rows import study_row

Z95 = 1.959963984540054  # standard normal quantile at 0.975

# ---------------------------------------------------------------------------------------------
# design


def _reduced(**kw: Any) -> dict[str, Any]:
    base: dict[str, Any] = {
        "name": "t",
        "simulator": "reduced",
        "scenes": ["flat"],
        "planners": ["miqcqp", "reactive"],
        "steps": ["smallest"],
        "seeds": 2,
        "push_levels": [],
        "level_seeds": 0,
    }
    return base | kw


@pytest.mark.parametrize("name", BUILTIN_STUDIES)
def test_builtin_studies_load(name: str) -> None:
    d = builtin_study(name)
    assert d.name == name
    assert d.max_trials() > 0
    assert {"quick", "section55"} <= set(BUILTIN_STUDIES)


def test_region_aware_reaches_the_fingerprint_only_when_on() -> None:
    """Folders of studies run before the field existed (all ``off``) keep their fingerprint; a
    region-aware study cannot resume a folder of walks without it."""
    base = {"name": "s", "simulator": "reduced"}
    off = study_from_dict(base)
    assert off.region_aware == "off" and "region_aware" not in off.fingerprint()
    on = study_from_dict(base | {"region_aware": "planned"})
    assert on.fingerprint() == off.fingerprint() | {"region_aware": "planned"}


def test_builtin_study_values() -> None:
    quick, s55 = builtin_study("quick"), builtin_study("section55")
    assert quick.simulator == "reduced" and quick.controller is None
    assert s55.simulator == "mujoco" and s55.controller == "wbc"
    assert s55.seeds == 200 and s55.level_steps == ("smallest",)
    with pytest.raises(InputError) as e:
        builtin_study("nope")
    assert e.value.field == "study"


@pytest.mark.parametrize(
    ("data", "field"),
    [
        ({"simulator": "x"}, "simulator"),
        ({"controller": "wbc"}, "controller"),
        ({"simulator": "mujoco", "noise_pos": 0.01}, "noise_pos"),
        ({"simulator": "mujoco", "placement_error": 0.01}, "placement_error"),
        ({"default_push": -1.0}, "default_push"),
        ({"planners": ["miqcqp", "miqcqp"]}, "planners[1]"),
        ({"planners": ["astar"]}, "planners[0]"),
        ({"scenes": ["no_such_scene"]}, "scenes[0]"),
        ({"level_steps": ["equal"]}, "level_steps[0]"),
        ({"seeds": 0}, "seeds"),
        ({"seeds": True}, "seeds"),
        ({"push_levels": [1.0, 1.0], "level_seeds": 1}, "push_levels"),
        ({"push_levels": [2.0], "level_seeds": 0}, "level_seeds"),
        ({"push_duration": 0.0}, "push_duration"),
        ({"time_limit": float("nan")}, "time_limit"),
        ({"seeds": 10**7}, "seeds"),
        ({"region_aware": "maybe"}, "region_aware"),
        ({"region_aware": 1}, "region_aware"),
    ],
)
def test_bad_values_name_their_field(data: dict[str, Any], field: str) -> None:
    with pytest.raises(InputError) as e:
        study_from_dict(_reduced(**data))
    assert e.value.field == field


def test_unknown_key_and_missing_name_are_refused() -> None:
    with pytest.raises(InputError) as e:
        parse_study(yaml.safe_dump(_reduced(colour="red")), "s.yaml")
    assert "colour" in e.value.field
    data = _reduced()
    del data["name"]
    with pytest.raises(InputError) as e:
        parse_study(yaml.safe_dump(data), "s.yaml")
    assert "name" in e.value.field


def test_a_non_text_key_is_an_input_error() -> None:
    # YAML keys may be numbers; the error must still be an InputError naming the key
    with pytest.raises(InputError) as e:
        parse_study("name: a\nsimulator: reduced\n1: 2\n", "s.yaml")
    assert "1" in e.value.field


def test_a_huge_study_is_refused_before_anything_runs() -> None:
    per_seed = 3  # miqcqp, kinematic and reactive, one scene, one step mode, one impulse
    seeds = MAX_TRIALS // per_seed + 1
    with pytest.raises(InputError) as e:
        StudyDesign(
            name="big",
            simulator="reduced",
            controller=None,
            scenes=("flat",),
            planners=("miqcqp", "kinematic", "reactive"),
            steps=("smallest",),
            seeds=seeds,
            push_levels=(),
            level_seeds=0,
        )
    assert e.value.field == "seeds"
    # one seed fewer fits exactly
    ok = StudyDesign(
        name="big",
        simulator="reduced",
        controller=None,
        scenes=("flat",),
        planners=("miqcqp", "kinematic", "reactive"),
        steps=("smallest",),
        seeds=MAX_TRIALS // per_seed,
        push_levels=(),
        level_seeds=0,
    )
    assert ok.max_trials() == per_seed * (MAX_TRIALS // per_seed)


def test_yaml_with_a_python_tag_is_refused_and_runs_nothing(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    text = f'name: !!python/object/apply:os.system ["touch {marker}"]\nsimulator: reduced\n'
    f = tmp_path / "evil.yaml"
    f.write_text(text)
    with pytest.raises(InputError):
        load_study(f)
    with pytest.raises(InputError):
        parse_study(text)
    assert not marker.exists()


def test_load_study_refuses_missing_file_folder_and_bad_yaml(tmp_path: Path) -> None:
    with pytest.raises(InputError) as e:
        load_study(tmp_path / "missing.yaml")
    assert e.value.field == "study file"
    with pytest.raises(InputError) as e:
        load_study(tmp_path)
    assert e.value.field == "study file"
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    with pytest.raises(InputError):
        load_study(bad)
    good = tmp_path / "good.yaml"
    good.write_text(yaml.safe_dump(_reduced()))
    d = load_study(good)
    assert d.controller is None and d.planners == ("miqcqp", "reactive")


def test_max_trials_hand_counted() -> None:
    d = StudyDesign(
        name="count",
        simulator="reduced",
        controller=None,
        scenes=("flat", "discrete_steps"),
        planners=("miqcqp", "kinematic", "reactive"),
        steps=("smallest", "equal"),
        default_push=3.0,
        seeds=5,
        push_levels=(0.0, 3.0, 6.0),
        level_seeds=2,
        level_steps=("smallest",),
    )
    # per scene, impulses 3 (default), 0, 6:
    #   horizon planners (2) x [3 N s: 5 smallest + 5 equal; 0 and 6 N s: 2 smallest each] = 28
    #   reactive: 5 + 2 + 2 = 9
    assert d.max_trials() == 2 * (2 * (5 + 5 + 2 + 2) + 9) == 74
    assert d.impulses() == (3.0, 0.0, 6.0)
    assert list(d.seeds_at(0.0, "equal")) == []
    assert list(d.seeds_at(6.0, "smallest")) == [0, 1]
    assert list(d.seeds_at(6.0, "goal")) == [0, 1]
    # without level_steps the equal mode is walked at every level too
    e = replace(d, level_steps=None)
    assert e.level_steps == ("smallest", "equal")
    assert e.max_trials() == 2 * (2 * (5 + 5 + 2 + 2 + 2 + 2) + 9) == 90


# ---------------------------------------------------------------------------------------------
# statistics


def _wilson_ref(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


@pytest.mark.parametrize(("k", "n"), [(45, 50), (1, 3), (7, 10), (50, 50), (3, 200)])
def test_wilson_matches_the_closed_form(k: int, n: int) -> None:
    lo, hi = st.wilson(k, n)
    rlo, rhi = _wilson_ref(k, n)
    assert lo == pytest.approx(max(0.0, rlo), abs=1e-12)
    assert hi == pytest.approx(min(1.0, rhi), abs=1e-12)


def test_wilson_published_value_and_edges() -> None:
    lo, hi = st.wilson(45, 50)
    assert lo == pytest.approx(0.786, abs=5e-4) and hi == pytest.approx(0.957, abs=5e-4)
    lo0, hi0 = st.wilson(0, 20)
    assert lo0 == pytest.approx(0.0, abs=1e-12) and 0 < hi0 < 0.2
    assert hi0 == pytest.approx(Z95**2 / (20 + Z95**2), rel=1e-12)
    assert all(math.isnan(x) for x in st.wilson(0, 0))
    # a 99 % interval is wider
    lo99, hi99 = st.wilson(45, 50, level=0.99)
    assert lo99 < lo and hi99 > hi


def _binom_two_sided(a: int, b: int) -> float:
    n = a + b
    tail = sum(math.comb(n, i) for i in range(min(a, b) + 1)) / 2**n
    return min(1.0, 2 * tail)


@pytest.mark.parametrize(("a", "b"), [(1, 9), (0, 6), (3, 12), (5, 5), (9, 1), (0, 0), (2, 1)])
def test_mcnemar_is_the_exact_binomial_test(a: int, b: int) -> None:
    p = st.mcnemar_p(a, b)
    assert p == pytest.approx(_binom_two_sided(a, b), rel=1e-12)
    if a + b:
        assert p == pytest.approx(sps.binomtest(a, a + b, 0.5).pvalue, rel=1e-12)
    assert st.mcnemar_p(1, 9) == pytest.approx(22 / 1024)


def test_mean_ci() -> None:
    x = [0.011, 0.013, 0.012, 0.020, 0.009, 0.015, 0.010, 0.014]
    m, lo, hi = st.mean_ci(x)
    assert m == pytest.approx(math.fsum(x) / len(x), rel=1e-14)
    assert min(x) <= lo < m < hi <= max(x)
    # roughly the t interval's width (BCa of a well-behaved sample)
    t_half = sps.t.ppf(0.975, len(x) - 1) * np.std(x, ddof=1) / math.sqrt(len(x))
    assert 0.4 * t_half < (hi - lo) / 2 < 1.5 * t_half
    assert st.mean_ci(x) == (m, lo, hi)  # fixed bootstrap seed: reproducible
    assert st.mean_ci([0.02, 0.02, 0.02]) == (0.02, 0.02, 0.02)
    m1, lo1, hi1 = st.mean_ci([0.5])
    assert m1 == 0.5 and math.isnan(lo1) and math.isnan(hi1)
    assert all(math.isnan(v) for v in st.mean_ci([]))
    # non-finite values and None are left out
    assert st.mean_ci([1.0, math.nan, None, 3.0, math.inf])[0] == 2.0  # type: ignore[list-item]


def test_wilcoxon_p_matches_scipy() -> None:
    d = [-0.003, -0.001, 0.0005, -0.004, -0.002, -0.0025, 0.001, -0.0035]
    assert st.wilcoxon_p(d) == pytest.approx(sps.wilcoxon(d).pvalue, rel=1e-12)
    assert st.wilcoxon_p([0.0, 0.0]) == 1.0
    assert math.isnan(st.wilcoxon_p([]))


_row = study_row


def _paired_rows() -> list[dict[str, Any]]:
    rows = []
    a_b = {0: (0.010, 0.015), 1: (0.012, 0.014), 2: (0.011, 0.020)}
    for s, (za, zb) in a_b.items():  # both succeed
        rows += [_row("miqcqp", s, True, za), _row("kinematic", s, True, zb)]
    rows += [_row("miqcqp", 3, True, 0.010), _row("kinematic", 3, False, 0.300)]  # planner only
    rows += [_row("miqcqp", 4, False, 0.500), _row("kinematic", 4, True, 0.010)]  # baseline only
    rows += [_row("miqcqp", 5, False, 0.400), _row("kinematic", 5, False, 0.100)]  # neither
    # an error: seed 6 is not walked by both
    rows += [_row("miqcqp", 6, True, 0.001), _row("kinematic", 6, True, 0.0, error="Boom: x")]
    rows += [_row("miqcqp", 7, False, 0.002)]  # no baseline walk at all
    # other step mode, other impulse, other scene: all left out
    rows += [
        _row("miqcqp", 8, True, 0.001, smallest=False, equal=True),
        _row("kinematic", 8, True, 0.900, smallest=False, equal=True),
        _row("miqcqp", 0, True, 0.001, impulse=0.0),
        _row("kinematic", 0, False, 0.900, impulse=0.0),
        _row("miqcqp", 0, False, 0.001, scene="other"),
        _row("kinematic", 0, True, 0.900, scene="other"),
    ]
    return rows


def test_paired_counts_and_difference_by_hand() -> None:
    p = st.paired(_paired_rows(), "s", "smallest", 3.0, "miqcqp", "kinematic")
    diffs = [0.010 - 0.015, 0.012 - 0.014, 0.011 - 0.020]
    assert p.pairs == 3
    assert p.zmp_diff == pytest.approx(-0.016 / 3, abs=1e-15)
    assert p.zmp_lo <= p.zmp_diff <= p.zmp_hi
    assert p.zmp_p == pytest.approx(sps.wilcoxon(diffs).pvalue)
    assert p.seeds == 6  # seeds 0-5: walked by both without error
    assert (p.only_planner, p.only_baseline) == (1, 1)
    assert p.success_p == 1.0
    # the equal mode holds only seed 8 (one pair): mean difference exact
    q = st.paired(_paired_rows(), "s", "equal", 3.0, "miqcqp", "kinematic")
    assert (q.pairs, q.seeds) == (1, 1)
    assert q.zmp_diff == pytest.approx(0.001 - 0.900)
    # swapping planner and baseline swaps the sign and the discordant counts
    r = st.paired(_paired_rows(), "s", "smallest", 3.0, "kinematic", "miqcqp")
    assert r.zmp_diff == pytest.approx(-p.zmp_diff)
    assert (r.only_planner, r.only_baseline) == (1, 1)


def test_paired_mcnemar_from_discordant_seeds() -> None:
    rows = []
    for s in range(12):
        a_ok = s < 10  # miqcqp succeeds on 10 of 12
        b_ok = s < 2 or s >= 10  # kinematic on 2 shared + 2 of its own
        rows += [_row("miqcqp", s, a_ok, 0.01), _row("kinematic", s, b_ok, 0.01)]
    p = st.paired(rows, "s", "smallest", 3.0, "miqcqp", "kinematic")
    assert (p.seeds, p.only_planner, p.only_baseline, p.pairs) == (12, 8, 2, 2)
    assert p.success_p == pytest.approx(sps.binomtest(8, 10, 0.5).pvalue)


def _pairs_with_diffs(diffs: list[float]) -> st.Paired:
    rows = []
    for s, d in enumerate(diffs):
        rows += [_row("miqcqp", s, True, 0.02 + d), _row("kinematic", s, True, 0.02)]
    return st.paired(rows, "s", "smallest", 3.0, "miqcqp", "kinematic")


NSTEPS = {("s", "miqcqp", "smallest"): 7, ("s", "kinematic", "smallest"): 9}


def test_verdict_wording() -> None:
    rng = np.random.default_rng(3)
    noise = rng.normal(0.0, 0.004, 20)
    zero_mean = list(noise - noise.mean())
    lower = list(-0.005 + rng.normal(0.0, 0.0005, 20))
    higher = [-x for x in lower]
    (ns,) = st.verdict([_pairs_with_diffs(zero_mean)], NSTEPS)
    (holds,) = st.verdict([_pairs_with_diffs(lower)], NSTEPS)
    (fails,) = st.verdict([_pairs_with_diffs(higher)], NSTEPS)
    (few,) = st.verdict([_pairs_with_diffs([-0.01])], NSTEPS)
    assert "not significant" in ns and "holds" not in ns and "NOT" not in ns
    assert "the claim holds" in holds and "not significant" not in holds
    assert "does NOT hold" in fails and "holds:" not in fails.replace("NOT hold", "")
    assert "cannot be judged" in few
    for line in (ns, holds, fails):
        assert "miqcqp N = 7" in line and "kinematic N = 9" in line and "20 pairs" in line
    # the printed mean difference is the hand mean, in mm
    assert f"{1000 * np.mean(lower):+.2f} mm" in holds


def test_a_comparison_of_two_modes_with_the_same_walks_is_judged_once() -> None:
    """Where both planners have the same N in both step modes the two comparisons are the same
    walks: one verdict line naming both modes; with another N both lines stay."""
    lower = list(-0.005 + np.random.default_rng(4).normal(0.0, 0.0005, 12))
    small = _pairs_with_diffs(lower)
    equal = replace(small, mode="equal")
    same_n = NSTEPS | {("s", "miqcqp", "equal"): 7, ("s", "kinematic", "equal"): 9}
    (one,) = st.distinct([small, equal], same_n)
    assert one.mode == "smallest=equal" and one.zmp_diff == small.zmp_diff
    (line,) = st.verdict([one], same_n)
    assert "s, smallest = equal N (miqcqp N = 7, kinematic N = 9)" in line
    other_n = NSTEPS | {("s", "miqcqp", "equal"): 9, ("s", "kinematic", "equal"): 9}
    both = st.distinct([small, equal], other_n)
    assert [p.mode for p in both] == ["smallest", "equal"]
    assert len(st.verdict(both, other_n)) == 2


def test_fragility_curves_keep_every_mode_and_name_its_n() -> None:
    """A curve whose walks are two modes' is drawn once and labelled with both (it used to be
    dropped, the survivor labelled "equal N"); curves of different N stay apart, each naming N."""
    from footfall.viz.study_plots import fragility_curves

    def pts(planner: str, mode: str, n: int, wins: tuple[int, ...]) -> list[dict[str, Any]]:
        return [
            {"scene": "s", "planner": planner, "mode": mode, "impulse": float(i), "walks": 10,
             "successes": k, "lo": 0.1 * k - 0.1, "hi": min(1.0, 0.1 * k + 0.1), "n_steps": n}
            for i, k in enumerate(wins)
        ]  # fmt: skip

    points = (
        pts("miqcqp", "equal", 11, (10, 8))
        + pts("miqcqp", "smallest", 11, (10, 8))
        + pts("reactive", "equal", 11, (9, 5))
        + pts("reactive", "smallest", 11, (9, 5))
    )
    labels = [c["label"] for c in fragility_curves(points)]
    assert labels == ["miqcqp (smallest = equal N = 11)", "reactive (smallest = equal N = 11)"]
    points = pts("miqcqp", "equal", 11, (10, 8)) + pts("miqcqp", "smallest", 9, (10, 6))
    curves = fragility_curves(points)
    assert [c["label"] for c in curves] == ["miqcqp (equal N = 11)", "miqcqp (smallest N = 9)"]
    assert curves[1]["rate"] == [1.0, 0.6]


def test_zmp_significant_needs_both_the_test_and_the_interval() -> None:
    p = _pairs_with_diffs(list(-0.005 + np.linspace(-0.0005, 0.0005, 20)))
    assert p.zmp_significant
    assert not replace(p, zmp_p=0.2).zmp_significant
    assert not replace(p, zmp_hi=0.001).zmp_significant


def test_cells_success_counts_and_wilson() -> None:
    zmps = [0.010, 0.012, 0.014, 0.016, 0.018, 0.020, 0.022, 0.5, 0.6, 0.7]
    rows = [_row("miqcqp", s, s < 7, z) for s, z in enumerate(zmps)]
    rows.append(_row("miqcqp", 10, True, 0.0, error="RuntimeError: x"))
    rows += [_row("reactive", s, True, 0.03, smallest=True, equal=True, n_steps=11) for s in (0, 1)]
    out = st.cells(rows, ["smallest", "equal"])
    by = {(c.planner, c.mode): c for c in out}
    assert set(by) == {("miqcqp", "smallest"), ("reactive", "smallest"), ("reactive", "equal")}
    c = by["miqcqp", "smallest"]
    assert (c.walks, c.errors, c.successes, c.n_steps) == (10, 1, 7, 7)
    assert c.success_rate == 0.7
    lo, hi = _wilson_ref(7, 10)
    assert c.success_lo == pytest.approx(lo) and c.success_hi == pytest.approx(hi)
    assert c.zmp_mean == pytest.approx(np.mean(zmps[:7]))  # successful walks only
    assert c.zmp_max_mean == pytest.approx(2 * np.mean(zmps[:7]))
    r = by["reactive", "equal"]
    assert (r.walks, r.successes, r.n_steps) == (2, 2, 11)
    assert r.success_lo == pytest.approx(_wilson_ref(2, 2)[0])
    frag = st.fragility(out)
    f0 = frag[0]
    assert (f0.planner, f0.mode, f0.successes, f0.walks) == ("miqcqp", "smallest", 7, 10)


# ---------------------------------------------------------------------------------------------
# store


def _design(**kw: Any) -> StudyDesign:
    return study_from_dict(_reduced(**kw))


def _rows(n: int) -> list[dict[str, Any]]:
    out = []
    for s in range(n):
        out.append(
            normalise_row(
                {
                    "key": f"flat|reactive|N=11|J=4|seed={s}",
                    "scene": "flat",
                    "planner": "reactive",
                    "n_steps": 11,
                    "smallest_n": True,
                    "equal_n": True,
                    "push_impulse": 4.0,
                    "seed": s,
                    "simulator": "reduced",
                    "controller": None,
                    "push_step": 5,
                    "push_time": 2.5 + s / 7,
                    "push_direction": s / 3,
                    "success": s % 2 == 0,
                    "fell": s % 2 == 1,
                    "zmp_offset_mean": 0.01 * s if s != 2 else math.nan,
                    "zmp_offset_max": 0.02 * s,
                    "footstep_error_mean": 1e-3,
                    "goal_error": 0.1,
                    "steps_landed": 11,
                    "wall_time": 0.1,
                    "error": "ValueError: x" if s == 3 else None,
                }
            )
        )
    return out


def _same(a: dict[str, Any], b: dict[str, Any]) -> bool:
    for k in a.keys() | b.keys():
        x, y = a[k], b[k]
        if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
            continue
        if x != y or type(x) is not type(y):
            return False
    return True


def test_store_round_trip(tmp_path: Path) -> None:
    d = _design()
    rows = _rows(5)
    s = TrialStore(tmp_path, d)
    for r in rows:
        s.add(r)
    s.flush()
    parts = list((tmp_path / "trials.parts").glob("part-*.parquet"))
    assert parts, "rows are on disk before close"
    assert not (tmp_path / "trials.parquet").exists()
    path = s.close()
    assert path == tmp_path / "trials.parquet" and path.is_file()
    assert not (tmp_path / "trials.parts").exists()
    again = TrialStore(tmp_path, d)
    assert set(again.rows) == {r["key"] for r in rows}
    for r in rows:
        assert again.done(r["key"])
        assert _same(again.rows[r["key"]], r), (again.rows[r["key"]], r)
    assert not again.done("flat|reactive|N=11|J=4|seed=99")
    # the file is sorted by key with the documented columns and types
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    assert table.column_names == [c for c, _ in COLUMNS]
    assert table.column("key").to_pylist() == sorted(r["key"] for r in rows)
    assert str(table.schema.field("success").type) == "bool"
    assert str(table.schema.field("n_steps").type) == "int64"


def test_every_row_is_on_disk_when_added_and_a_crash_keeps_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A finished walk is reported done after its row was added: the row must already be on
    disk (rows used to wait for 25 rows or 10 s, so a crash lost 3 of 5 finished walks)."""
    monkeypatch.setattr(store_mod, "COMPACT_PARTS", 3)
    d = _design()
    rows = _rows(5)
    s = TrialStore(tmp_path, d)
    for k, r in enumerate(rows):
        s.add(r)
        # no close (a crash right after the walk was reported): a new store sees every row
        assert set(TrialStore(tmp_path, d).rows) == {r["key"] for r in rows[: k + 1]}
    # 3 parts were merged into the table, the last 2 rows are parts
    assert len(list((tmp_path / "trials.parts").glob("part-*.parquet"))) == 2
    assert {r["key"] for r in read_rows(tmp_path / "trials.parquet")} == {
        r["key"] for r in rows[:3]
    }
    s.close()
    assert set(TrialStore(tmp_path, d).rows) == {r["key"] for r in rows}
    assert not (tmp_path / "trials.parts").exists()


def test_store_close_survives_a_temporary_file_left_by_a_crash(tmp_path: Path) -> None:
    d = _design()
    s = TrialStore(tmp_path, d)
    s.add(_rows(1)[0])
    s.flush()
    # a crash in write_rows leaves its temporary file beside the parts
    (tmp_path / "trials.parts" / ".part-00000000000000000001-1-00000.parquet.1.tmp").write_bytes(
        b"x"
    )
    s2 = TrialStore(tmp_path, d)
    s2.add(_rows(2)[1])
    s2.close()
    assert set(TrialStore(tmp_path, d).rows) == {r["key"] for r in _rows(2)}


def test_store_refuses_a_folder_of_another_study(tmp_path: Path) -> None:
    d = _design(initial_impulse=0.5)
    TrialStore(tmp_path, d).close()
    with pytest.raises(InputError) as e:
        TrialStore(tmp_path, replace(d, initial_impulse=0.9))
    assert e.value.field == "--out"
    assert "initial_impulse" in str(e.value)
    with pytest.raises(InputError) as e:
        TrialStore(tmp_path, replace(d, noise_vel=0.1))
    assert e.value.field == "--out"
    # a study that only grows (more seeds, planners, pushes) reuses the folder
    TrialStore(tmp_path, replace(d, seeds=9, planners=("kinematic", "miqcqp", "reactive")))


def test_store_refuses_a_damaged_table_or_meta(tmp_path: Path) -> None:
    d = _design()
    s = TrialStore(tmp_path, d)
    s.add(_rows(1)[0])
    s.close()
    (tmp_path / "trials.parquet").write_bytes(b"PAR1 this is not parquet PAR1")
    with pytest.raises(InputError) as e:
        TrialStore(tmp_path, d)
    assert e.value.field == "trials file"
    (tmp_path / "trials.parquet").unlink()
    (tmp_path / "study.json").write_text("{not json")
    with pytest.raises(InputError) as e:
        TrialStore(tmp_path, d)
    assert e.value.field == "study folder"


@pytest.mark.parametrize("meta", ['{"fingerprint": 3}', '{"fingerprint": ["seeds"]}', "[1, 2]"])
def test_store_refuses_an_edited_meta_with_one_line(tmp_path: Path, meta: str) -> None:
    """A study.json that is JSON but not the store's (a fingerprint that is not a mapping) is an
    InputError naming it, not a TypeError from comparing the fingerprints."""
    (tmp_path / "study.json").write_text(meta)
    with pytest.raises(InputError) as e:
        TrialStore(tmp_path, _design())
    assert e.value.field == "study folder"
