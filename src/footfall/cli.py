"""The ``footfall`` command line.

Every command that computes something writes JSON and a figure into ``--out``. Input errors
(:class:`footfall.errors.FootfallError`) are printed as one clear line and exit with code 2.
"""

from __future__ import annotations

import sys
from pathlib import Path

import typer
from rich.console import Console

from footfall._io import write_json
from footfall.errors import FootfallError, InputError

app = typer.Typer(
    name="footfall",
    help="Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(stderr=True)


@app.callback()
def _root() -> None:
    """Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits)."""


def parse_floats(field: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers, naming ``field`` on error."""
    try:
        return [float(v) for v in text.split(",") if v.strip() != ""]
    except ValueError:
        raise InputError(field, text, "comma-separated numbers, e.g. 0,0.3,0.3") from None


def main() -> None:
    """Entry point of the ``footfall`` console script."""
    try:
        app()
    except FootfallError as exc:
        console.print(f"[bold red]error:[/] {exc}")
        sys.exit(2)


# --- LIP walk (document 004) ---
@app.command()
def lip(
    out: Path = typer.Option(Path("out/lip"), help="Output folder for lip_walk.json and .png."),
    example: str | None = typer.Option(
        None, help="A document example: straight, diagonal, turn or circle (overrides the rest)."
    ),
    zc: float = typer.Option(0.8, help="CoM height z_c [m]."),
    t_sup: float = typer.Option(0.8, help="Support duration T_sup [s]."),
    sx: str = typer.Option("0,0.3,0.3,0.3,0", help="Forward walk parameters per step [m]."),
    sy: str = typer.Option("0.2,0.2,0.2,0.2,0.2", help="Lateral walk parameters per step [m]."),
    theta_deg: str | None = typer.Option(None, help="Heading per step [deg]; default all 0."),
    a: float = typer.Option(10.0, help="Position weight of the foot placement cost."),
    b: float = typer.Option(1.0, help="Velocity weight of the foot placement cost."),
    a_stop: float = typer.Option(1.0, help="Position weight for the stop step."),
    b_stop: float = typer.Option(1.0, help="Velocity weight for the stop step."),
    g: float = typer.Option(9.81, help="Gravity [m/s^2] (the document's code uses 9.8)."),
    dt: float = typer.Option(0.01, help="Sampling period of the CoM trajectory in the JSON [s]."),
) -> None:
    """Kajita LIP walking pattern with foot placement modification (document 004)."""
    import math

    from footfall.planning.lip_examples import example as get_example
    from footfall.planning.lip_io import lip_walk_to_dict
    from footfall.planning.lip_walk import LipWalkParams, lip_walk
    from footfall.viz.lip_plot import plot_lip_walk

    if example is not None:
        params = get_example(example)
        title = f"LIP walk: {example} (document 004)"
    else:
        theta = None
        if theta_deg is not None:
            theta = tuple(math.radians(v) for v in parse_floats("theta_deg", theta_deg))
        params = LipWalkParams(
            z_c=zc,
            t_sup=t_sup,
            sx=tuple(parse_floats("sx", sx)),
            sy=tuple(parse_floats("sy", sy)),
            theta=theta,
            a=a,
            b=b,
            a_stop=a_stop,
            b_stop=b_stop,
            g=g,
        )
        title = "LIP walk"
    walk = lip_walk(params)
    write_json(out / "lip_walk.json", lip_walk_to_dict(walk, dt))
    plot_lip_walk(walk, out / "lip_walk.png", title=title)
    speed = math.hypot(*walk.final_vel)
    typer.echo(
        f"{walk.footholds.shape[0]} support phases, final CoM speed {speed:.4f} m/s; "
        f"wrote {out / 'lip_walk.json'} and {out / 'lip_walk.png'}"
    )


# --- demo ---
@app.command()
def demo(out: Path = typer.Option(Path("out/demo"), help="Output folder.")) -> None:
    """Run the main demo on built-in defaults and write figures and JSON into OUT."""
    from footfall.demo import run_demo

    summary = run_demo(out)
    for line in summary["lines"]:
        typer.echo(line)
    typer.echo(f"wrote {out / 'demo.json'}")


# --- terrain scenes ---
@app.command("scenes")
def scenes_command(
    show: str | None = typer.Option(
        None, "--show", help="Scene to draw: a built-in name or a YAML file path."
    ),
    out: Path = typer.Option(Path("."), "--out", help="Folder for scene.png and scene.yaml."),
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


# --- bench (issue 5) ---
bench_app = typer.Typer(help="Benchmarks.", no_args_is_help=True)
app.add_typer(bench_app, name="bench")


@bench_app.command("plan")
def bench_plan_cmd(
    steps: str = typer.Option("6,10,15", help="Numbers of footsteps N, comma separated."),
    nodes: str = typer.Option("5,10", help="Numbers of ALIP nodes K, comma separated."),
    seeds: str = typer.Option("0,1,2", help="Seeds of the random stepping-stone scenes."),
    regions: int = typer.Option(8, help="Regions per random scene."),
    scenes: str = typer.Option("", help="Built-in scenes to add, comma separated."),
    time_limit_direct: float = typer.Option(60.0, help="Time limit of the direct SCIP model [s]."),
    time_limit_fast: float = typer.Option(60.0, help="Time limit of the fast planner [s]."),
    gap: float = typer.Option(1e-3, help="Relative optimality gap of both."),
    fast_only: bool = typer.Option(False, help="Skip the direct model."),
    fast_threads: int = typer.Option(2, help="Worker processes of the fast planner."),
    out: Path = typer.Option(Path("out/bench"), help="Output folder for bench_plan.json/.md."),
) -> None:
    """Direct SCIP model vs the fast planner on the same instances: a table of times and gaps."""
    from footfall.bench import bench_plan, format_table, rows_to_dict

    def ints(field: str, text: str) -> list[int]:
        vals = parse_floats(field, text)
        if not vals or any(v != int(v) or v < 1 for v in vals):
            raise InputError(field, text, "comma-separated positive integers, e.g. 6,10")
        return [int(v) for v in vals]

    def ints0(field: str, text: str) -> list[int]:
        vals = parse_floats(field, text)
        if not vals or any(v != int(v) or v < 0 for v in vals):
            raise InputError(field, text, "comma-separated integers >= 0, e.g. 0,1,2")
        return [int(v) for v in vals]

    rows = bench_plan(
        n_steps=ints("steps", steps),
        n_nodes=ints("nodes", nodes),
        seeds=ints0("seeds", seeds),
        n_regions=regions,
        scenes=[s for s in scenes.split(",") if s.strip()],
        time_limit_direct=time_limit_direct,
        time_limit_fast=time_limit_fast,
        gap=gap,
        direct=not fast_only,
        fast_threads=fast_threads,
        progress=lambda run: console.print(
            f"{run.instance} N={run.n_steps} K={run.n_nodes} {run.solver}: {run.status} "
            f"{run.time:.2f} s obj {run.objective:.6g}"
        ),
    )
    table = format_table(rows)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "bench_plan.json", {"runs": rows_to_dict(rows)})
    (out / "bench_plan.md").write_text(table + "\n")
    print(table)
