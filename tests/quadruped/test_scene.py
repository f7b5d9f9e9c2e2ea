"""Quadruped scenes in YAML: the built-ins load and plan, and bad files name the field and line."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from footfall.errors import SceneError
from footfall.quadruped import QuadrupedRobot, plan_gait
from footfall.quadruped.ground import PlaneGround, Stairs, VaryingSlope
from footfall.quadruped.scene import (
    builtin_quadruped_scene,
    builtin_quadruped_scene_names,
    load_quadruped_scene,
    resolve_quadruped_scene,
)

EXPECTED = {"downhill_20", "side_slope", "slope_15", "stairs_10cm", "varying_slope"}


def test_builtin_scenes_load_and_plan() -> None:
    assert set(builtin_quadruped_scene_names()) == EXPECTED
    for name in sorted(EXPECTED):
        sc = builtin_quadruped_scene(name)
        assert sc.name == name
        plan = plan_gait(QuadrupedRobot(), sc.params)
        assert plan.duration > 0


def test_builtin_grounds_are_what_their_names_say() -> None:
    assert builtin_quadruped_scene("slope_15").ground == PlaneGround(math.radians(15))
    assert builtin_quadruped_scene("slope_15").params.body_pitch == pytest.approx(math.radians(10))
    side = builtin_quadruped_scene("side_slope").ground
    assert isinstance(side, PlaneGround) and side.side_slope == pytest.approx(math.radians(15))
    stairs = builtin_quadruped_scene("stairs_10cm").ground
    assert isinstance(stairs, Stairs) and stairs.rise == pytest.approx(0.10)
    hill = builtin_quadruped_scene("varying_slope").ground
    assert isinstance(hill, VaryingSlope) and len(hill.knots_x) == 5


def test_a_scene_file_loads(tmp_path: Path) -> None:
    f = tmp_path / "mine.yaml"
    f.write_text(
        "name: mine\nground:\n  kind: stairs\n  rise: 0.08\n  steps: 2\n"
        "gait: {swing_height: 0.15, cycles: 3}\nfriction: 0.8\n"
    )
    sc = resolve_quadruped_scene(str(f))
    assert sc.ground == Stairs(rise=0.08, steps=2)
    assert sc.friction == 0.8 and sc.params.cycles == 3


@pytest.mark.parametrize(
    ("text", "field", "line"),
    [
        ("name: a\nground: {kind: plane, rise: 0.1}\n", "ground.rise", 2),
        ("name: a\nground: {kind: hill}\n", "ground.kind", 2),
        ("name: a\nground:\n  kind: plane\n  slope_deg: 75\n", "ground.slope_deg", 4),
        ("name: a\nground:\n  kind: stairs\n  rise: -0.1\n", "ground.rise", 4),
        ("name: a\nground:\n  kind: stairs\n  start: 0\n", "ground.start", 4),
        ("name: a\nground: {kind: varying}\n", "ground.knots", 2),
        (
            "name: a\nground:\n  kind: varying\n  knots:\n  - [0, 0]\n  - [0, 5]\n",
            "ground.knots[1]",
            6,
        ),
        ("name: a\nground: {kind: stairs}\ngait: {body_deg: 5}\n", "gait.body_deg", 3),
        ("name: a\nground: {kind: plane}\ngait: {body_ratio: 0.5}\n", "gait.body_ratio", 3),
        (
            "name: a\nground: {kind: plane, slope_deg: 10}\ngait: {body_deg: 20}\n",
            "gait.body_deg",
            3,
        ),
        ("name: a\nground: {kind: plane}\ngait: {cycles: '3'}\n", "gait.cycles", 3),
        ("name: a\nground: {kind: plane}\ngait: {stride: 3}\n", "gait.stride", 3),
        ("name: a\nground: {kind: plane}\nfriction: 0\n", "friction", 3),
        ("name: a\n", "ground", 1),
        ("- 1\n- 2\n", "<document>", 1),
    ],
)
def test_bad_scenes_name_the_field_and_line(text: str, field: str, line: int) -> None:
    with pytest.raises(SceneError) as err:
        load_quadruped_scene(text)
    assert err.value.field.startswith(field), err.value.field
    assert f"line {line}" in err.value.field


def test_unknown_builtin_is_listed() -> None:
    with pytest.raises(SceneError) as err:
        builtin_quadruped_scene("moon")
    assert "stairs_10cm" in err.value.expected
