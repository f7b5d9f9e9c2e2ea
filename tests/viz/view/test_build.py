"""The page's scene as data: region slabs, soles, the CoM path, the camera fit (pure functions)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from footfall.models.biped import Side
from footfall.terrain import builtin_scene
from footfall.viz.view import build

#: exact arithmetic (plane heights, rotations)
EXACT_TOL = 1e-9


def _project(cam: build.Camera, pts: np.ndarray, aspect: float) -> np.ndarray:
    """Normalised image coordinates (x / half width, y / half height) of points."""
    u = cam.position - cam.look_at
    u /= np.linalg.norm(u)
    right = np.cross([0.0, 0.0, 1.0], u)
    right /= np.linalg.norm(right)
    up = np.cross(u, right)
    d = pts - cam.position
    depth = -(d @ u)
    t = math.tan(cam.fov / 2)
    return np.column_stack([(d @ right) / (depth * t * aspect), (d @ up) / (depth * t)])


@given(
    st.lists(
        st.tuples(*(st.floats(-5, 5, allow_nan=False),) * 2, st.floats(0, 1, allow_nan=False)),
        min_size=2,
        max_size=30,
    )
)
def test_the_camera_fits_every_point_and_fills_the_picture(raw: list) -> None:
    pts = np.array(raw, dtype=float)
    if np.ptp(pts, axis=0).max() < 1e-3:
        return
    aspect = 16 / 9
    cam = build.fit_camera(pts, aspect=aspect)
    xy = _project(cam, pts, aspect)
    assert np.all(np.abs(xy) <= 1.0 - build.CAMERA_MARGIN + 1e-6)  # all inside, margin kept
    if np.linalg.norm(cam.position - cam.look_at) > 0.5 + 1e-9:  # not at the closest distance
        # some point touches the edge of the kept area: the points fill the picture
        assert np.abs(xy).max() >= 1.0 - build.CAMERA_MARGIN - 1e-6


def test_region_slabs_sit_on_their_planes_coloured_by_height() -> None:
    scene = builtin_scene("discrete_steps")
    meshes = build.region_meshes(scene)
    assert len(meshes) == len(scene.terrain)
    heights = []
    for m, r in zip(meshes, scene.terrain.regions, strict=True):
        v = len(r.vertices)
        top = m.vertices[:v]
        assert np.allclose(top[:, 2], r.height_at(top[:, :2]), atol=EXACT_TOL)
        assert np.allclose(m.vertices[v:, 2], top[:, 2] - build.SLAB, atol=EXACT_TOL)
        heights.append(top[:, 2].mean())
    # the highest region gets the brightest colour (viridis runs dark to bright)
    lum = [sum(m.rgb) for m in meshes]
    assert np.argmax(lum) == np.argmax(heights) and np.argmin(lum) == np.argmin(heights)


def test_soles_are_the_robots_feet_at_their_headings() -> None:
    corners = build.sole_polygon(np.array([1.0, 2.0, 0.3]), math.pi / 2, 0.2, 0.1, lift=0.0)
    # turned a quarter: the length runs along y
    assert np.ptp(corners[:, 1]) == pytest.approx(0.2) and np.ptp(corners[:, 0]) == pytest.approx(
        0.1
    )
    assert np.allclose(corners.mean(axis=0), [1.0, 2.0, 0.3], atol=EXACT_TOL)


def test_footsteps_and_the_com_path_of_a_plan() -> None:
    from footfall.planning import make_plan

    scene = builtin_scene("flat")
    plan = make_plan(scene, "reactive")
    soles, labels, ticks = build.footstep_nodes(plan, scene)
    assert len(soles) == len(labels) == plan.n_steps + 1 == ticks.segments.shape[0]
    assert [lb.text.split()[1] for lb in labels] == [
        "L" if s is Side.LEFT else "R" for s in plan.sides
    ]
    com = build.com_path(plan)
    # one polyline through every ALIP node, com_height above the flat ground
    assert com.segments.shape[0] == plan.states.shape[0] * plan.states.shape[1] - 1
    assert np.allclose(com.segments[:, :, 2], plan.robot.com_height, atol=EXACT_TOL)


def test_support_polygon_closes_over_the_stance_feet() -> None:
    feet = np.array([[0.3, 0.2, 0], [0.3, -0.2, 0], [-0.3, -0.2, 0], [-0.3, 0.2, 0]], dtype=float)
    seg = build.support_polygon(feet, np.array([True, True, False, True]))
    assert seg.shape == (3, 2, 3)
    assert np.allclose(seg[:, 1], np.roll(seg[:, 0], -1, axis=0))  # a closed ring
    assert build.support_polygon(feet, np.array([True, False, False, False])).shape == (0, 2, 3)


def test_framing_leaves_out_far_terrain() -> None:
    act = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.5]])
    ter = np.array([[0.2, 0.1, 0.0], [30.0, 0.0, 0.0]])
    got = build.framed_points(ter, act)
    assert len(got) == 3 and not np.any(got[:, 0] > 2)
    assert np.array_equal(build.framed_points(ter, np.zeros((0, 3))), ter)


def test_the_viewer_does_not_import_the_simulation() -> None:
    # viz sits beside the experiments: it draws files, it never runs a plant
    code = (
        "import sys, footfall.viz.view.page, footfall.viz.view.browser, footfall.cli.view;"
        "print([m for m in sys.modules if m.startswith('footfall.sim')])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
