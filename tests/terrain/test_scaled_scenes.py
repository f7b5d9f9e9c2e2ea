"""The benchmark scenes scaled to a smaller robot (``benchmarks/scenes/*_x04.yaml``) are the
built-in scenes with every height (and the gap) x 0.4: the same layout, start and goal."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from footfall.terrain import Scene, builtin_scene, load_scene

SCENES = Path(__file__).resolve().parents[2] / "benchmarks" / "scenes"
SCALE = 0.4


def _corners(scene: Scene) -> dict[str, np.ndarray]:
    """Each region's 3-D corners (n, 3) [m] by name, in the scene's order."""
    return {r.name: np.asarray(r.vertices3d, dtype=float) for r in scene.terrain}


@pytest.mark.parametrize(
    ("file", "built_in", "moved"),
    [
        ("discrete_steps_x04.yaml", "discrete_steps", ()),
        ("stairs_slope_gap_x04.yaml", "stairs_slope_gap", ("landing",)),
    ],
)
def test_a_scaled_scene_is_the_built_in_one_with_heights_x_04(
    file: str, built_in: str, moved: tuple[str, ...]
) -> None:
    """Start, goal and region order as built in; every corner's height x 0.4; every corner in
    plan view where the built-in scene has it, but for the regions ``moved`` (the gap's)."""
    scaled, base = load_scene(SCENES / file), builtin_scene(built_in)
    np.testing.assert_array_equal(scaled.start.left, base.start.left)
    np.testing.assert_array_equal(scaled.start.right, base.start.right)
    np.testing.assert_array_equal(scaled.goal.position, base.goal.position)
    mine, theirs = _corners(scaled), _corners(base)
    assert list(mine) == list(theirs)
    for name, corners in theirs.items():
        np.testing.assert_allclose(mine[name][:, 2], SCALE * corners[:, 2], atol=1e-9)
        if name not in moved:
            np.testing.assert_allclose(mine[name][:, :2], corners[:, :2], atol=1e-12)


def test_the_scaled_gap_is_04_of_the_built_in_one() -> None:
    """stairs_slope_gap's gap (ledge end to landing start) is 0.12 m, the scaled one 0.048 m."""

    def gap(scene: Scene) -> float:
        regions = _corners(scene)
        return float(regions["landing"][:, 0].min() - regions["ledge"][:, 0].max())

    base = builtin_scene("stairs_slope_gap")
    assert gap(base) == pytest.approx(0.12)
    assert gap(load_scene(SCENES / "stairs_slope_gap_x04.yaml")) == pytest.approx(SCALE * gap(base))
