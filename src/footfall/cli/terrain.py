"""``footfall terrain``: terrain tools; ``from-heightmap`` turns an elevation map into a scene."""

from __future__ import annotations

import math
import time
from pathlib import Path

import typer

from footfall._io import remove_outputs, write_text
from footfall.cli._common import (
    app,
    console,
    output_folder,
    parse_floats,
    refuse_inputs_as_outputs,
)
from footfall.errors import InputError

terrain_app = typer.Typer(
    help="Terrain tools: build a scene from a robot's height map.",
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode=None,
)
app.add_typer(terrain_app, name="terrain")


def _pose(field: str, text: str | None) -> tuple[float, ...] | None:
    """``X,Y[,YAW]`` with YAW in degrees as ``(x, y[, yaw_rad])``."""
    if text is None:
        return None
    v = parse_floats(field, text)
    if len(v) not in (2, 3) or not all(math.isfinite(c) for c in v):
        raise InputError(field, text, "X,Y or X,Y,YAW: finite numbers [m, m, deg]")
    return (v[0], v[1]) if len(v) == 2 else (v[0], v[1], math.radians(v[2]))


def _origin(text: str) -> tuple[float, float]:
    v = parse_floats("origin", text)
    if len(v) != 2 or not all(math.isfinite(c) for c in v):
        raise InputError("origin", text, "X,Y: two finite numbers [m]")
    return (v[0], v[1])


@terrain_app.command("from-heightmap")
def from_heightmap(
    map_file: Path = typer.Argument(
        ..., metavar="MAP", help="Height map: .npy, .npz, .png (16-bit) or .csv."
    ),
    resolution: float = typer.Option(..., help="Cell size [m]."),
    out: Path = typer.Option(
        Path("scene.yaml"), help="Scene YAML to write; the figure goes beside it (.png)."
    ),
    origin: str = typer.Option("0,0", help="X,Y of the centre of the first cell [m]."),
    start: str | None = typer.Option(
        None,
        help="X,Y[,YAW]: midpoint of the start feet [m] and heading [deg]; default: inside the largest region.",
    ),
    goal: str | None = typer.Option(
        None, help="X,Y[,YAW]: goal [m] and heading [deg]; default: the start."
    ),
    height_scale: float | None = typer.Option(None, help="PNG only, required: metres per count."),
    height_offset: float = typer.Option(0.0, help="PNG only: height of count 0 [m]."),
    nodata: int | None = typer.Option(None, help="PNG only: the count of unknown cells."),
    key: str | None = typer.Option(None, help=".npz only: the array to read."),
    max_slope: float = typer.Option(30.0, help="Steepest traversable plane [deg]."),
    roughness: float = typer.Option(
        0.02, help="Largest RMS residual of a cell's local plane fit [m]."
    ),
    tolerance: float = typer.Option(0.03, help="Largest distance of a cell from its plane [m]."),
    window: int = typer.Option(5, help="Local plane fit window [cells], odd."),
    margin: float = typer.Option(0.0, help="Erode every segment by this foot margin [m]."),
    min_area: float = typer.Option(0.005, help="Smallest region kept [m^2]."),
    min_width: float = typer.Option(0.04, help="Thinnest region kept (2 area / perimeter) [m]."),
    max_spikes: float = typer.Option(
        0.01, help="Most spike cells (fraction of known cells) accepted."
    ),
    name: str = typer.Option("heightmap", help="Scene name."),
) -> None:
    """Convex planar regions from a height map, written as a scene (the YAML schema of
    `footfall scenes`) and a figure of the regions over the map.

    Cell [i, j] of the map is at x = X0 + j R, y = Y0 + i R (rows along y, for every format);
    unknown cells are NaN (empty in a CSV, --nodata in a PNG)."""
    from footfall.terrain import load_scene, scene_to_yaml
    from footfall.terrain.heightmap import HeightmapOptions, load_heightmap, scene_from_heightmap
    from footfall.viz.heightmap_plot import plot_heightmap_regions

    if out.exists() and out.is_dir():
        raise InputError(
            "out", str(out), "a file path for the scene YAML (a folder of that name exists)"
        )
    if out.suffix.lower() == ".png":
        raise InputError("out", str(out), "a .yaml path (the figure goes beside it as .png)")
    refuse_inputs_as_outputs([map_file], {"out": [out, out.with_suffix(".png")]})
    output_folder(out.parent if str(out.parent) else Path("."))
    options = HeightmapOptions(
        max_slope_deg=max_slope,
        roughness=roughness,
        plane_tolerance=tolerance,
        window=window,
        margin=margin,
        min_area=min_area,
        min_width=min_width,
        max_spike_fraction=max_spikes,
    )
    start_pose, goal_pose = _pose("start", start), _pose("goal", goal)
    t0 = time.perf_counter()
    hm = load_heightmap(
        map_file,
        resolution,
        _origin(origin),
        key=key,
        height_scale=height_scale,
        height_offset=height_offset,
        nodata=nodata,
    )
    scene, result = scene_from_heightmap(hm, options, start=start_pose, goal=goal_pose, name=name)
    elapsed = time.perf_counter() - t0
    text = scene_to_yaml(scene)
    load_scene(text)  # the file must pass the scene loader's own validation
    remove_outputs(out.parent, out.name, out.with_suffix(".png").name)  # no mixed runs
    write_text(out, text)
    figure = plot_heightmap_regions(result, out.with_suffix(".png"), scene)
    h, w = hm.shape
    spikes = int(result.spikes.sum())
    console.print(
        f"{len(scene.terrain)} regions on {int(result.labels.max())} planar segments from a "
        f"{h} x {w} map in {elapsed:.2f} s" + (f" ({spikes} spike cells ignored)" if spikes else "")
    )
    console.print(f"wrote {out} and {figure}")


@terrain_app.command("generate")
def generate(
    family: str = typer.Option(
        ..., help="Terrain family: discrete_steps or stairs_slope_gap (document 000's two)."
    ),
    seed: int = typer.Option(0, help="First family seed (each seed is one terrain)."),
    count: int = typer.Option(1, help="Number of terrains (seeds SEED ... SEED + COUNT - 1)."),
    out: Path = typer.Option(Path("terrains"), help="Folder for the scene files (NAME.yaml)."),
) -> None:
    """Terrains drawn from a seeded family shaped like one of document 000's study scenes, each
    written as a scene file (walk it with `footfall walk FILE`). The same family and seed give
    the same terrain; the family's ranges (lengths in m, angles in deg) are printed."""
    from footfall.terrain import load_scene, scene_to_yaml
    from footfall.terrain.families import MAX_SEED, family_terrain, ranges_dict

    ranges = ranges_dict(family)  # checks the family's name first
    if count < 1 or count > 10_000:
        raise InputError("count", count, "an integer in [1, 10000]")
    if seed < 0 or seed + count - 1 > MAX_SEED:
        raise InputError("seed", seed, f"an integer >= 0 with SEED + COUNT - 1 <= {MAX_SEED}")
    output_folder(out)
    paths = []
    for s in range(seed, seed + count):
        scene = family_terrain(family, s)
        text = scene_to_yaml(scene)
        load_scene(text)  # the file must pass the scene loader's own validation
        paths.append(write_text(out / f"{scene.name}.yaml", text))
    console.print(f"{family} ranges: " + ", ".join(f"{k} {v}" for k, v in ranges.items()))
    shown = ", ".join(p.name for p in paths[:3]) + (", ..." if len(paths) > 3 else "")
    console.print(f"wrote {len(paths)} scene file(s) to {out}: {shown}")
