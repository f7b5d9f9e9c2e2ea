"""The benchmark scenes scaled to a smaller robot (``benchmarks/scenes/*_x04.yaml``) are the
built-in scenes with every height (and the gap) x 0.4: the same layout, start and goal."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from footfall.terrain import builtin_scene, load_scene

SCENES = Path(__file__).resolve().parents[2] / "benchmarks" / "scenes"
SCALE = 0.4


def _corners(scene_name: str) -> dict[str, np.ndarray]:
    return {
        r.name: np.asarray(r.vertices3d, dtype=float) for r in builtin_scene(scene_name).terrain
    }


@pytest.mark.parametrize(
    ("file", "built_in"),
    [
        ("discrete_steps_x04.yaml", "discrete_steps"),
        ("stairs_slope_gap_x04.yaml", "stairs_slope_gap"),
    ],
)
def test_a_scaled_scene_is_the_built_in_one_with_heights_x_04(file: str, built_in: str) -> None:
    scaled = load_scene(SCENES / file)
    base = builtin_scene(built_in)
    np.testing.assert_array_equal(scaled.start.left, base.start.left)
    np.testing.assert_array_equal(scaled.start.right, base.start.right)
    np.testing.assert_array_equal(scaled.goal.position, base.goal.position)
    corners = _corners(built_in)
    assert [r.name for r in scaled.terrain] == list(corners)
    for region in scaled.terrain:
        mine = np.asarray(region.vertices3d, dtype=float)
        np.testing.assert_allclose(mine[:, 2], SCALE * corners[region.name][:, 2], atol=1e-9)


def test_the_scaled_gap_is_04_of_the_built_in_one() -> None:
    """stairs_slope_gap's gap (ledge end to landing start) is 0.12 m; the scaled one 0.048 m, and
    every other corner is where the built-in scene has it."""
    scaled = {
        r.name: np.asarray(r.vertices, dtype=float)
        for r in load_scene(SCENES / "stairs_slope_gap_x04.yaml").terrain
    }
    base = {
        r.name: np.asarray(r.vertices, dtype=float)
        for r in builtin_scene("stairs_slope_gap").terrain
    }

    def gap(regions: dict[str, np.ndarray]) -> float:
        return float(regions["landing"][:, 0].min() - regions["ledge"][:, 0].max())

    assert gap(base) == pytest.approx(0.12)
    assert gap(scaled) == pytest.approx(SCALE * gap(base))
    for name, xy in base.items():
        if name != "landing":
            np.testing.assert_allclose(scaled[name], xy, atol=1e-12)
