"""Hostile input, as a new user would try it: one line naming the field, the value and what was
expected, exit 2, never a traceback; work that scales with the input is bounded before it starts;
public functions refuse NaN and overflow instead of returning them."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.models import ALIP
from footfall.models.lip import LIP
from tests.cli import error_line, footfall
from tests.planning.scenes import SHORT_FLAT


def _scene_file(tmp_path: Path, old: str, new: str) -> Path:
    assert old in SHORT_FLAT
    path = tmp_path / "scene.yaml"
    path.write_text(SHORT_FLAT.replace(old, new))
    return path


# --- the command line -----------------------------------------------------------------------------
def test_demo_into_a_file_is_refused(tmp_path: Path) -> None:
    (tmp_path / "afile").write_text("x")
    error_line(footfall("demo", "--out", str(tmp_path / "afile")), "out:")


def test_a_lip_sampling_period_that_would_fill_the_memory_is_refused(tmp_path: Path) -> None:
    line = error_line(footfall("lip", "--dt", "1e-9", "--out", str(tmp_path)), "dt:")
    assert "samples" in line


def test_a_height_map_fit_window_beyond_any_map_is_refused(tmp_path: Path) -> None:
    np.save(tmp_path / "m.npy", np.zeros((30, 30)))
    r = footfall("terrain", "from-heightmap", str(tmp_path / "m.npy"), "--resolution", "0.02",
             "--window", "100001", "--out", str(tmp_path / "s.yaml"))  # fmt: skip
    error_line(r, "window:")


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("robot: {n_nodes: 4}", "robot: {n_nodes: 4, mass: 1.0e-300}", "robot.mass"),
        ("robot: {n_nodes: 4}", "robot: {n_nodes: 4, t_ss: 50.0}", "t_ss"),
        ("name: short_flat", "name: " + "x" * 1_000_000, "name"),
        ("name: short_flat", "name: short_flat\nname: other", "yaml (line 3"),
        ("robot: {n_nodes: 4}", "robot: {n_nodes: 4}\nrobot: {n_nodes: 5}", "yaml (line 5"),
    ],
    ids=["mass-1e-300", "t_ss-50-time-constants", "1MB-name", "duplicate-name", "duplicate-robot"],
)
def test_a_hostile_scene_is_one_line_naming_the_field(
    tmp_path: Path, old: str, new: str, field: str
) -> None:
    scene = _scene_file(tmp_path, old, new)
    line = error_line(footfall("plan", str(scene), "--steps", "3", "--out", str(tmp_path)), field)
    assert len(line) < 600  # a 1 MB name is not echoed in full
    assert not (tmp_path / "plan.json").exists()


def test_a_duplicate_key_names_both_lines() -> None:
    from footfall.terrain import load_scene

    with pytest.raises(InputError) as e:
        load_scene(SHORT_FLAT.replace("name: short_flat", "name: short_flat\nname: other"))
    assert "line 3" in e.value.field and "twice (first on line 2)" in e.value.expected


def test_a_study_file_with_a_duplicate_key_is_refused() -> None:
    from footfall.experiments.study import parse_study

    with pytest.raises(InputError, match="twice"):
        parse_study("scenes: [flat]\nseeds: 3\nseeds: 4\n")


def test_a_plan_file_longer_than_any_plan_is_refused_before_checking(tmp_path: Path) -> None:
    """A 29,000-step plan (within the 20 MB file cap) made `check` run for minutes."""
    from footfall.planning import make_plan
    from footfall.terrain import load_scene

    sc = load_scene(SHORT_FLAT)
    data = json.loads(json.dumps(make_plan(sc, "kinematic", 3).to_dict(sc.name)))
    step = data["footsteps"][1]
    data["footsteps"] = [data["footsteps"][0]] + [dict(step, index=i) for i in range(1, 29_001)]
    plan_file = tmp_path / "long.json"
    plan_file.write_text(json.dumps(data))
    scene_file = _scene_file(tmp_path, "name: short_flat", "name: short_flat")
    line = error_line(footfall("check", str(plan_file), str(scene_file)), "footsteps")
    assert "29001 footsteps" in line and "at most 201" in line


def test_a_corrupted_study_json_iserror_line(tmp_path: Path) -> None:
    (tmp_path / "study.json").write_text('{"fingerprint": 3}')
    error_line(footfall("study", "--quick", "--out", str(tmp_path)), "study folder:")


# --- the library --------------------------------------------------------------------------------
def test_alip_discretisation_refuses_a_period_that_overflows() -> None:
    alip = ALIP(mass=32.0, com_height=0.6)
    with pytest.raises(InputError, match="dt"):
        alip.discretize(1e6)
    with pytest.raises(InputError, match="t_ds"):
        alip.reset_map(1e6)
    ad, _ = alip.discretize(100.0)  # long but representable: finite, and the exact ZOH
    w = alip.omega
    assert np.all(np.isfinite(ad)) and ad[0, 0] == pytest.approx(math.cosh(w * 100.0), rel=1e-9)


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (([0.0], [0.0], [0.0], [math.nan]), "t"),
        (([0.0], [0.0], [0.0], 1e6), "t"),
        (([math.nan], [0.0], [0.0], 0.5), "pos0"),
        (([0.0], [math.inf], [0.0], 0.5), "vel0"),
        (([0.0], [0.0], [math.nan], 0.5), "foot"),
    ],
)
def test_lip_state_refuses_nan_and_overflow(args: tuple[object, ...], field: str) -> None:
    with pytest.raises(InputError) as e:
        LIP(z_c=0.8).state_at(*args)  # type: ignore[arg-type]
    assert e.value.field == field


def test_zmp_refuses_a_nan_torque() -> None:
    alip = ALIP(mass=32.0, com_height=0.6)
    with pytest.raises(InputError) as e:
        alip.zmp(np.zeros(2), np.array([math.nan, 0.0]))
    assert e.value.field == "u"
    # and it is the closed form otherwise: tau_x = m g d_y, tau_y = -m g d_x
    np.testing.assert_allclose(
        alip.zmp(np.zeros(2), alip.torque_for_zmp([0.03, -0.01])), [0.03, -0.01], atol=1e-15
    )


def test_build_mpc_names_a_missing_robot() -> None:
    from footfall.control.mpc import build_mpc

    with pytest.raises(InputError) as e:
        build_mpc(None)  # type: ignore[arg-type]
    assert e.value.field == "robot"
