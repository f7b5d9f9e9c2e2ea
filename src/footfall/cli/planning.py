"""Commands of the planning documents: ``lip`` (004), ``scenes``, ``plan`` and ``check`` (000)."""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Any

import typer
from rich.console import Console

from footfall._io import remove_outputs, write_json, write_text
from footfall.cli._common import (
    _THREADS_HELP,
    HEADING_WINDOWS_HELP,
    ROBOT_HELP,
    _threads,
    app,
    console,
    output_folder,
    parse_floats,
    refuse_inputs_as_outputs,
)
from footfall.cli._progress import ProgressLog
from footfall.errors import InputError


# --- LIP walk (document 004) ---
@app.command()
def lip(
    out: Path = typer.Option(Path("out/lip"), help="Output folder for lip_walk.json and .png."),
    example: str | None = typer.Option(
        None,
        help="A document example: straight, diagonal, turn or circle; the options below that are "
        "given change it.",
    ),
    zc: float | None = typer.Option(None, help="CoM height z_c [m] (default 0.8)."),
    t_sup: float | None = typer.Option(None, help="Support duration T_sup [s] (default 0.8)."),
    sx: str | None = typer.Option(
        None, help="Forward walk parameters per step [m] (default 0,0.3,0.3,0.3,0)."
    ),
    sy: str | None = typer.Option(
        None, help="Lateral walk parameters per step [m] (default 0.2,0.2,0.2,0.2,0.2)."
    ),
    theta_deg: str | None = typer.Option(None, help="Heading per step [deg]; default all 0."),
    a: float | None = typer.Option(
        None, help="Position weight of the foot placement cost (default 10)."
    ),
    b: float | None = typer.Option(
        None, help="Velocity weight of the foot placement cost (default 1)."
    ),
    a_stop: float | None = typer.Option(
        None, help="Position weight for the stop step (default 1)."
    ),
    b_stop: float | None = typer.Option(
        None, help="Velocity weight for the stop step (default 1)."
    ),
    g: float | None = typer.Option(
        None, help="Gravity [m/s^2] (default 9.81; the document's code uses 9.8)."
    ),
    dt: float = typer.Option(0.01, help="Sampling period of the CoM trajectory in the JSON [s]."),
) -> None:
    """Kajita LIP walking pattern with foot placement modification (document 004)."""
    import math

    from footfall.planning.lip_examples import lip_params
    from footfall.planning.lip_io import lip_walk_to_dict
    from footfall.planning.lip_walk import lip_walk
    from footfall.viz.lip_plot import plot_lip_walk

    given = {
        "z_c": zc,
        "t_sup": t_sup,
        "sx": None if sx is None else tuple(parse_floats("sx", sx)),
        "sy": None if sy is None else tuple(parse_floats("sy", sy)),
        "theta": None
        if theta_deg is None
        else tuple(math.radians(v) for v in parse_floats("theta_deg", theta_deg)),
        "a": a,
        "b": b,
        "a_stop": a_stop,
        "b_stop": b_stop,
        "g": g,
    }
    output_folder(out)
    params = lip_params(example, **{k: v for k, v in given.items() if v is not None})
    title = "LIP walk" if example is None else f"LIP walk: {example} (document 004)"
    walk = lip_walk(params)
    remove_outputs(out, "lip_walk.json", "lip_walk.png")  # no file of another run beside ours
    write_json(out / "lip_walk.json", lip_walk_to_dict(walk, dt))
    plot_lip_walk(walk, out / "lip_walk.png", title=title)
    speed = math.hypot(*walk.final_vel)
    typer.echo(
        f"{walk.footholds.shape[0]} support phases, final CoM speed {speed:.4f} m/s; "
        f"wrote {out / 'lip_walk.json'} and {out / 'lip_walk.png'}"
    )


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

    from footfall.terrain import builtin_scene, builtin_scene_names, scene_to_yaml
    from footfall.terrain.resolve import resolve_scene

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

    from footfall.viz.terrain_plot import plot_scene

    scene = resolve_scene(show)
    refuse_inputs_as_outputs([show], {"out": [out / "scene.yaml", out / "scene.png"]})
    output_folder(out)
    remove_outputs(out, "scene.yaml", "scene.png")  # no file of another run beside ours
    write_text(out / "scene.yaml", scene_to_yaml(scene))
    plot_scene(scene, out / "scene.png")
    console.print(f"wrote {out / 'scene.png'} and {out / 'scene.yaml'}")


# --- footstep planning (document 000, section 5.3) ---
def _walker_params(robot: str, base: Any) -> Any:
    """The planner's robot parameters measured on the named MuJoCo walker model."""
    from footfall.sim.biped.model import planner_params
    from footfall.sim.biped.plans import robot_model

    return planner_params(robot_model(robot), base=base)


@app.command()
def plan(
    scene_file: Path | None = typer.Argument(None, help="Scene YAML file (or use --scene)."),
    scene: str | None = typer.Option(None, help="Built-in scene name (see `footfall scenes`)."),
    steps: int | None = typer.Option(
        None, help="Footsteps N to plan; omitted: the smallest N with a plan (like --min-steps)."
    ),
    min_steps: bool = typer.Option(False, help="Search the smallest feasible N."),
    planner: str = typer.Option("miqcqp", help="miqcqp, kinematic or reactive."),
    time_limit: float = typer.Option(
        60.0,
        help="Time limit of the solve [s]; in the smallest-N search, of each N tried (its checks "
        "before the solve included). A MIQCQP solve that finds no plan in it is followed by a "
        "search with the headings pinned outside a window of footsteps, for as long again.",
    ),
    gap: float = typer.Option(1e-4, help="Relative optimality gap at which to stop."),
    solver: str = typer.Option(
        "bnb", help="Backend: bnb (fast exact, default), scip (direct model) or gurobi."
    ),
    threads: int | None = typer.Option(None, help=_THREADS_HELP),
    region_margin: float = typer.Option(
        0.0, help="Keep footsteps this far inside their region [m] (0: point footholds)."
    ),
    reach_both_frames: bool = typer.Option(
        False,
        help="Beyond the document: each step also in the reach set of the landing foot's frame "
        "(no trailing foot beside or across the new stance foot when headings differ).",
    ),
    robot: str | None = typer.Option(
        None, help=ROBOT_HELP + " Omitted: the scene's robot (the document's parameters)."
    ),
    swing_max: float | None = typer.Option(
        None,
        help="Beyond the document: bound each foot's horizontal swing (consecutive footholds of "
        "the same foot) to this length [m]; omitted: no bound.",
    ),
    heading_segments: int = typer.Option(
        16,
        help="Heading segments L of the linear reach model (eq. 5.12f-h): more segments make it "
        "less conservative (longer steps allowed) and the problem larger.",
    ),
    heading_windows: int = typer.Option(
        2,  # PlannerOptions.heading_windows (a test keeps them equal)
        help=HEADING_WINDOWS_HELP,
    ),
    out: Path = typer.Option(Path("out/plan"), help="Output folder for plan.json and plan.png."),
    quiet: bool = typer.Option(
        False, "--quiet", help="No progress lines or status line (the result is still printed)."
    ),
    log_json: Path | None = typer.Option(
        None,
        "--log-json",
        help="Write the progress as JSON lines to this file (one object per N tried or skipped, "
        "and while a solve runs, at most one every 5 s), with or without a terminal.",
    ),
) -> None:
    """Plan footsteps over a scene; writes plan.json and plan.png. Exit 1 when no plan exists or
    the independent checker rejects the plan.

    Progress: a status line in a terminal; without one, a plain line on stderr per N tried and at
    most every 5 s while a solve runs."""
    from footfall.planning import PlannerOptions, check_plan, make_plan, plan_min_steps
    from footfall.planning.check import unexpected_violations
    from footfall.planning.plan import check_planner_name
    from footfall.terrain.resolve import resolve_scene_arguments
    from footfall.viz.plan_plot import plot_plan

    check_planner_name(planner)
    sc = resolve_scene_arguments(scene_file, scene)
    outputs = {
        "out": [out / "plan.json", out / "plan.png"],
        "log_json": [log_json] if log_json else [],
    }
    refuse_inputs_as_outputs([scene_file, scene], outputs)
    output_folder(out)
    if steps is not None and min_steps:
        raise InputError("steps", steps, "no --steps with --min-steps (which searches N)")
    options = PlannerOptions(
        time_limit=time_limit,
        gap=gap,
        solver=solver,
        threads=_threads(threads),
        region_margin=region_margin,
        reach_both_frames=reach_both_frames,
        swing_max=swing_max,
        heading_segments=heading_segments,
        heading_windows=heading_windows,
    )
    robot_params = None if robot is None else _walker_params(robot, sc.robot)
    with ProgressLog(f"{sc.name} with {planner}", quiet, log_json) as log:
        if planner != "reactive" and (min_steps or steps is None):
            result = plan_min_steps(sc, planner, options, robot=robot_params, monitor=log)
        else:
            hook = partial(log.solving, steps, model=planner)
            result = make_plan(sc, planner, steps, options, robot_params, solve_progress=hook)
        log.done(result)
    payload = result.to_dict(sc.name)
    unexpected: list[Any] = []
    if result.has_solution:
        report = check_plan(result, sc)
        # a kinematic plan over U_max is what that planner makes; anything else is a failure
        unexpected = unexpected_violations(report, result)
        payload["check"] = {"ok": report.ok, "violations": report.summary().splitlines()}
    remove_outputs(out, "plan.json", "plan.png")  # no file of an earlier run beside ours
    write_json(out / "plan.json", payload)
    if result.has_solution:
        plot_plan(result, sc, out / "plan.png")
    console.print(
        f"{sc.name}: {planner} -> {result.status.value}, {result.n_steps} steps, "
        f"objective {result.objective:.4g}, {result.solve_time:.2f} s. {result.message}"
    )
    console.print(f"wrote {out / 'plan.json'}" + (" and plan.png" if result.has_solution else ""))
    if unexpected:
        # a plan the independent checker rejects is not a plan to walk: a failed run
        console.print(
            f"the plan violates the checker's constraints: {unexpected[0].describe()}"
            + (f" and {len(unexpected) - 1} more" if len(unexpected) > 1 else "")
            + " (see plan.json 'check')"
        )
        raise typer.Exit(1)
    if not result.reaches_goal:
        raise typer.Exit(1)


@app.command("check")
def check_command(
    plan_file: Path = typer.Argument(..., help="A plan.json written by `footfall plan`."),
    scene_file: Path | None = typer.Argument(None, help="Scene YAML file (or use --scene)."),
    scene: str | None = typer.Option(None, help="Built-in scene name (see `footfall scenes`)."),
    out: Path | None = typer.Option(
        None, help="Output folder for check.json (omitted: print only)."
    ),
) -> None:
    """Check a saved plan against a scene with the independent checker, for the robot the plan
    was made for. Exit 0: valid; 1: a constraint is violated (each printed with its footstep and
    amount); 2: bad input."""
    from footfall.planning import check_plan, load_plan
    from footfall.terrain.resolve import resolve_scene_arguments

    sc = resolve_scene_arguments(scene_file, scene)
    if out is not None:
        refuse_inputs_as_outputs([plan_file, scene_file, scene], {"out": [out / "check.json"]})
        output_folder(out)
    result = load_plan(plan_file, sc)
    report = check_plan(result, sc)
    if out is not None:
        lines = [] if report.ok else report.summary().splitlines()
        payload = {"plan": str(plan_file), "scene": sc.name, "ok": report.ok, "violations": lines}
        write_json(out / "check.json", {**payload, "checked": list(report.checked)})
    if report.ok:
        console.print(
            f"{plan_file}: valid on {sc.name} ({result.n_steps} steps; checked "
            f"{', '.join(report.checked)})"
        )
        return
    console.print(f"{plan_file}: {len(report.violations)} violated constraint(s) on {sc.name}")
    for v in report.violations:
        console.print(f"  {v.describe()}")
    raise typer.Exit(1)
