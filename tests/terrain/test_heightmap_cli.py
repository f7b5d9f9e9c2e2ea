"""``footfall terrain from-heightmap``: a map file in, a scene the loader accepts and a figure out;
bad input exits 2 with one line naming the field."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from footfall.terrain import builtin_scene, load_scene
from footfall.terrain.heightmap import rasterize_scene


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", "terrain", "from-heightmap", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_a_png_map_becomes_a_scene_with_start_and_goal_on_the_blocks(tmp_path: Path) -> None:
    from PIL import Image

    hm = rasterize_scene(builtin_scene("discrete_steps"), 0.02)
    scale, offset = 0.0005, -0.1  # 0.5 mm per count; count 0 marks unknown cells
    counts = np.where(np.isnan(hm.heights), 0, np.round((hm.heights - offset) / scale))
    Image.fromarray(counts.astype(np.uint16)).save(tmp_path / "map.png")
    x0, y0 = hm.origin
    out = tmp_path / "out" / "steps.yaml"
    r = _run(str(tmp_path / "map.png"), "--resolution", "0.02", "--origin", f"{x0},{y0}",
             "--height-scale", str(scale), "--height-offset", str(offset), "--nodata", "0",
             "--start", "0,0,0", "--goal", "3.2,0,90", "--out", str(out))  # fmt: skip
    assert r.returncode == 0, r.stderr
    scene = load_scene(out)
    assert len(scene.terrain) == len(builtin_scene("discrete_steps").terrain)
    assert scene.goal.heading == pytest.approx(np.pi / 2)
    block2 = scene.terrain.locate(np.array([1.0, 0.0, 0.25]), 2e-3)
    assert block2, "block2 (0.25 m high) is a region of the scene"
    assert out.with_suffix(".png").stat().st_size > 0


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (["--resolution", "0.02"], "heights"),  # the all-NaN map below
        (["--resolution", "-1"], "resolution"),
        (["--resolution", "0.02", "--start", "1,x"], "start"),
        (["--resolution", "0.02", "--window", "4"], "window"),
    ],
)
def test_bad_input_exits_2_with_one_line_naming_the_field(
    tmp_path: Path, args: list[str], field: str
) -> None:
    np.save(tmp_path / "nan.npy", np.full((10, 10), np.nan))
    r = _run(str(tmp_path / "nan.npy"), *args, "--out", str(tmp_path / "s.yaml"))
    assert r.returncode == 2, r.stderr
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    assert f"{field}:" in lines[0], lines[0]
    assert not (tmp_path / "s.yaml").exists()
