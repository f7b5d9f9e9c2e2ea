"""The ``footfall`` command line.

Every command that computes something writes JSON and a figure into ``--out``. Input errors
(:class:`footfall.errors.FootfallError`) are printed as one clear line and exit with code 2.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import typer
from rich.console import Console

from footfall.errors import FootfallError, InputError

app = typer.Typer(
    name="footfall",
    help="Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(stderr=True)


def parse_floats(field: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers, naming ``field`` on error."""
    try:
        return [float(v) for v in text.split(",") if v.strip() != ""]
    except ValueError:
        raise InputError(field, text, "comma-separated numbers, e.g. 0,0.3,0.3") from None


def write_json(path: Path, payload: dict[str, Any]) -> None:
    """Write ``payload`` as indented JSON, creating parent folders."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(payload, indent=2) + "\n")


def main() -> None:
    """Entry point of the ``footfall`` console script."""
    try:
        app()
    except FootfallError as exc:
        console.print(f"[bold red]error:[/] {exc}")
        sys.exit(2)


# --- terrain scenes ---
@app.command("scenes")
def scenes_command(
    show: str | None = typer.Option(
        None, "--show", help="Scene to draw: a built-in name or a YAML file path."
    ),
    out: Path = typer.Option(  # noqa: B008 - typer's documented default style
        Path("."), "--out", help="Folder for scene.png and scene.yaml."
    ),
) -> None:
    """List the built-in scenes, or draw one (top and side view) and write it as YAML."""
    import math

    from rich.table import Table

    from footfall.terrain import builtin_scene, builtin_scene_names, load_scene, scene_to_yaml

    if show is None:
        table = Table(title="Built-in scenes")
        for col in ("name", "regions", "goal: x, y, z (m), heading (deg)", "description"):
            table.add_column(col)
        for name in builtin_scene_names():
            sc = builtin_scene(name)
            g = sc.goal
            goal = f"({g.position[0]:.2f}, {g.position[1]:.2f}, {g.position[2]:.2f}), "
            goal += f"{math.degrees(g.heading):.0f}"
            table.add_row(name, str(len(sc.terrain)), goal, sc.description)
        Console().print(table)
        return

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from footfall.viz.terrain_plot import plot_terrain, plot_terrain_side

    is_file = show.endswith((".yaml", ".yml")) or Path(show).is_file()
    scene = load_scene(Path(show)) if is_file else builtin_scene(show)
    out.mkdir(parents=True, exist_ok=True)
    (out / "scene.yaml").write_text(scene_to_yaml(scene))
    fig, (ax_top, ax_side) = plt.subplots(
        2, 1, figsize=(9, 8), gridspec_kw={"height_ratios": [3, 1]}, constrained_layout=True
    )
    sm = plot_terrain(ax_top, scene.terrain)
    plot_terrain_side(ax_side, scene.terrain)
    for foot, mark in ((scene.start.left, "^"), (scene.start.right, "v")):
        ax_top.plot(foot[0], foot[1], mark, color="tab:red", ms=8)
        ax_side.plot(foot[0], foot[2], mark, color="tab:red", ms=8)
    g = scene.goal
    ax_top.plot(g.position[0], g.position[1], "*", color="gold", mec="k", ms=14)
    ax_top.arrow(
        g.position[0],
        g.position[1],
        0.2 * math.cos(g.heading),
        0.2 * math.sin(g.heading),
        width=0.01,
        color="k",
    )
    ax_side.plot(g.position[0], g.position[2], "*", color="gold", mec="k", ms=14)
    ax_top.set_title(f"{scene.name}: {scene.description}", fontsize=9)
    fig.colorbar(sm, ax=ax_top, label="z [m]", shrink=0.8)
    fig.savefig(out / "scene.png", dpi=120)
    plt.close(fig)
    console.print(f"wrote {out / 'scene.png'} and {out / 'scene.yaml'}")
