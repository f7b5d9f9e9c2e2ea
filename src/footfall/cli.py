"""The ``footfall`` command line.

Every command that computes something writes JSON and a figure into ``--out``. Input errors
(:class:`footfall.errors.FootfallError`) are printed as one clear line and exit with code 2.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import typer
from rich.console import Console
from rich.text import Text

from footfall._io import write_json
from footfall._validate import names_in, non_negative
from footfall.errors import FootfallError, InputError
from footfall.terrain.resolve import resolve_scene, resolve_scene_arguments

app = typer.Typer(
    name="footfall",
    help="Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # help texts are plain text: units like [s] and extras like footfall[robots] must show as typed
    rich_markup_mode=None,
)
#: user-facing messages (scene names, paths, install hints) are printed as typed, never as markup
console = Console(stderr=True, markup=False, highlight=False, soft_wrap=True)


def _say_error(prefix: str, message: str) -> None:
    """Print ``prefix: message`` on stderr, the prefix in bold red, the message as plain text."""
    console.print(Text(f"{prefix}: ", style="bold red") + Text(message))


@app.callback()
def _root() -> None:
    """Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits)."""


_THREADS_HELP = (
    "Worker processes of the bnb backend / solver threads (default: 2, or the cores if fewer; "
    "at most the cores this process may use)."
)


def _threads(threads: int | None) -> int:
    """``--threads``: as given, or the default of two workers where two cores exist."""
    if threads is not None:
        return threads
    from footfall.planning.plan import available_cores

    return min(2, available_cores())


def output_folder(out: Path) -> Path:
    """Create ``out`` (and its parents) and check that it is a writable folder, before any work
    whose result would otherwise be lost."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise InputError("out", str(out), "a folder (a file of that name exists)") from None
    except OSError as e:
        raise InputError("out", str(out), f"a folder that can be created ({e.strerror})") from None
    if not out.is_dir():
        raise InputError("out", str(out), "a folder (a file of that name exists)")
    if not os.access(out, os.W_OK | os.X_OK):
        raise InputError("out", str(out), "a folder this user may write to")
    return out


def parse_floats(field: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers, naming ``field`` on error."""
    try:
        return [float(v) for v in text.split(",") if v.strip() != ""]
    except ValueError:
        raise InputError(field, text, "comma-separated numbers, e.g. 0,0.3,0.3") from None


class _Stopped(BaseException):
    """SIGINT or SIGTERM arrived: unwinds the command like Ctrl-C (not caught by click)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _end_children() -> None:
    """Terminate this process's worker processes (solver workers, trial pools), then kill what
    is still alive a second later: no worker outlives an interrupted command."""
    import multiprocessing as mp

    children = mp.active_children()
    for child in children:
        child.terminate()
    deadline = time.monotonic() + 1.0
    for child in children:
        child.join(max(0.0, deadline - time.monotonic()))
        if child.is_alive():
            child.kill()


#: pid of the process that installed the handlers (forked workers inherit them)
_MAIN_PID = 0


def _on_signal(signum: int, frame: object) -> None:
    if os.getpid() != _MAIN_PID:  # a forked worker: leave at once, quietly
        os._exit(128 + signum)
    signal.signal(signum, signal.SIG_IGN)  # a second signal must not interrupt the clean-up
    _end_children()
    raise _Stopped(signum)


def main() -> None:
    """Entry point of the ``footfall`` console script.

    Exit codes: 0 success, 1 a run that failed (no plan, a solver error, a fall reported as a
    failure), 2 bad input (:class:`footfall.errors.InputError`), 128 + the signal number when
    stopped by SIGINT (130) or SIGTERM (143), after ending every worker process. Errors footfall
    raises are printed as one line, never as a traceback.
    """
    global _MAIN_PID
    _MAIN_PID = os.getpid()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _on_signal)
    try:
        app()
    except InputError as exc:
        _say_error("error", str(exc))
        sys.exit(2)
    except FootfallError as exc:
        _say_error("failed", str(exc))
        sys.exit(1)
    except _Stopped as exc:
        _say_error("stopped", f"by {signal.Signals(exc.signum).name}")
        sys.exit(128 + exc.signum)


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
    from footfall.experiments.demo import run_demo

    labels = {
        "lip": "LIP walks (document 004)",
        "plans": "footstep plans (document 000)",
        "closed_loop": "MPC closed loop (document 000 eq. 5.19)",
        "quadruped": "quadruped on a slope in MuJoCo (document 001)",
    }
    with console.status("footfall demo") as status:
        summary = run_demo(out, progress=lambda key: status.update(f"demo: {labels[key]} ..."))
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

    from footfall.terrain import builtin_scene, builtin_scene_names, scene_to_yaml

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
    output_folder(out)
    (out / "scene.yaml").write_text(scene_to_yaml(scene))
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
    time_limit: float = typer.Option(60.0, help="Solver time limit per solve [s]."),
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
        None,
        help="Plan for a MuJoCo walker model: biped or g1 (mass, CoM height, stance width and "
        "foot size measured on the model, the rest from the scene); omitted: the scene's robot.",
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
    out: Path = typer.Option(Path("out/plan"), help="Output folder for plan.json and plan.png."),
) -> None:
    """Plan footsteps over a scene; writes plan.json and plan.png. Exit 1 when no plan exists."""
    from footfall.planning import PlannerOptions, check_plan, make_plan, plan_min_steps
    from footfall.planning.plan import check_planner_name
    from footfall.viz.plan_plot import plot_plan

    check_planner_name(planner)
    sc = resolve_scene_arguments(scene_file, scene)
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
    )
    robot_params = None if robot is None else _walker_params(robot, sc.robot)
    with console.status(f"planning {sc.name} with {planner} ...") as status:

        def progress(n: int, result: Any) -> None:
            status.update(f"planning {sc.name} with {planner}: N = {n} -> {result.status.value}")

        if planner != "reactive" and (min_steps or steps is None):
            result = plan_min_steps(sc, planner, options, progress=progress, robot=robot_params)
        else:
            result = make_plan(sc, planner, steps, options, robot_params)
    payload = result.to_dict(sc.name)
    checked = True
    if result.has_solution:
        report = check_plan(result, sc)
        checked = report.ok
        payload["check"] = {"ok": report.ok, "violations": report.summary().splitlines()}
    write_json(out / "plan.json", payload)
    if result.has_solution:
        plot_plan(result, sc, out / "plan.png")
    else:  # no figure of an earlier run beside this run's plan.json
        (out / "plan.png").unlink(missing_ok=True)
    console.print(
        f"{sc.name}: {planner} -> {result.status.value}, {result.n_steps} steps, "
        f"objective {result.objective:.4g}, {result.solve_time:.2f} s. {result.message}"
    )
    console.print(f"wrote {out / 'plan.json'}" + (" and plan.png" if result.has_solution else ""))
    if not checked:
        console.print("the plan violates the checker's constraints (see plan.json 'check')")
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

    sc = resolve_scene_arguments(scene_file, scene)
    if out is not None:
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


# --- quadruped (document 001) ---
@app.command("quadruped")
def quadruped_cmd(
    slope_deg: float = typer.Option(15.0, help="Slope angle beta_S [deg]."),
    body_deg: float = typer.Option(
        10.0, help="Body angle beta_B to the horizontal [deg], in [0, slope]."
    ),
    step: float = typer.Option(0.4, help="Step length S along the slope [m]."),
    height: float = typer.Option(0.1, help="Swing height H normal to the slope [m]."),
    cycles: int = typer.Option(6, help="Number of gait cycles."),
    swing_period: float = typer.Option(0.5, help="Swing period T_w [s]."),
    shift_period: float = typer.Option(1.5, help="Duration of each body shift [s]."),
    strategy: str = typer.Option("osp", help="ZMP placement: osp, incentre or transverse."),
    compare: bool = typer.Option(False, help="Also run the other strategies (body sway table)."),
    out: Path = typer.Option("out/quadruped", help="Output folder."),
    video: bool = typer.Option(True, "--video/--no-video", help="Render an MP4 (offscreen GL)."),
) -> None:
    """Walk gait up a slope (document 001): plan with ZMP/OSP, simulate in MuJoCo, measure."""
    import math
    import os

    if video:
        # must be chosen before MuJoCo is imported; EGL works headless here
        os.environ.setdefault("MUJOCO_GL", "egl")
    from footfall.experiments.slope_walk import compare_strategies, plan_strategies
    from footfall.quadruped import GaitParams, QuadrupedRobot, ZmpStrategy
    from footfall.sim.quadruped.sim import simulate
    from footfall.viz.quadruped_plots import save_walk_figures

    if not math.isfinite(slope_deg) or not 0.0 <= slope_deg <= 60.0:
        raise InputError("--slope-deg", slope_deg, "a slope in [0, 60] deg")
    if not math.isfinite(body_deg) or not 0.0 <= body_deg <= slope_deg:
        raise InputError(
            "--body-deg", body_deg, f"a body angle within [0, --slope-deg] = [0, {slope_deg:g}] deg"
        )
    try:
        strat = ZmpStrategy(strategy)
    except ValueError:
        raise InputError("--strategy", strategy, "one of osp, incentre, transverse") from None
    params = GaitParams(
        slope=math.radians(slope_deg),
        body_pitch=math.radians(body_deg),
        step=step,
        swing_height=height,
        swing_period=swing_period,
        shift_period=shift_period,
        cycles=cycles,
        strategy=strat,
    )
    output_folder(out)
    plans, infeasible = plan_strategies(QuadrupedRobot(), params, compare)
    plan = plans[strat]
    console.print(f"simulating {cycles} cycles on {slope_deg:g} deg ({plan.duration:.1f} s)...")
    res = simulate(plan, video_path=out / "quadruped.mp4" if video else None)
    if video and res.video is None:
        console.print(res.video_note)
    payload = res.metrics.to_dict()
    if compare:
        payload["strategy_comparison"] = compare_strategies(plans, res)
        payload["strategy_comparison_infeasible"] = infeasible
    figs = save_walk_figures(plan, res, out, f"{slope_deg:g}°/{body_deg:g}°")
    payload["figures"] = [str(f) for f in figs]
    write_json(out / "quadruped.json", payload)
    m = res.metrics
    console.print(
        f"distance {m.distance_up_slope_m:.2f} m, speed {m.mean_speed_m_s:.3f} m/s, "
        f"fell {m.fell}, margin min {m.stability_margin_min_m:.3f} m "
        f"mean {m.stability_margin_mean_m:.3f} m, {m.realtime_factor:.0f}x real time"
    )
    console.print(f"wrote {out / 'quadruped.json'}")


# --- simulate (issue 4) ---
@contextmanager
def _progress_bar() -> Iterator[Callable[[str, int, int], None]]:
    """A console progress bar; yields ``progress(what, done, total)`` (total 0: unknown)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn())
    with Progress(*columns, TimeElapsedColumn(), console=console) as bar:
        task = bar.add_task("planning", total=None)

        def progress(what: str, done: int, total: int) -> None:
            bar.update(task, description=what, completed=done, total=total or None)

        yield progress


def _list_arg(text: str) -> list[str]:
    """The non-empty items of a comma-separated option."""
    return [item.strip() for item in text.split(",") if item.strip()]


def _positive_int(field: str, value: int) -> int:
    if value < 1:
        raise InputError(field, value, "an integer >= 1")
    return value


@app.command("simulate")
def simulate_command(
    scene: str = typer.Option("flat", "--scene", help="Built-in scene name or YAML file."),
    planner: str = typer.Option("miqcqp", help="Planner: miqcqp, kinematic or reactive."),
    steps: int | None = typer.Option(
        None, help="Footsteps N of miqcqp/kinematic (default: the smallest N with a miqcqp plan)."
    ),
    time_limit: float = typer.Option(60.0, "--time-limit", help="Planner time limit [s]."),
    threads: int | None = typer.Option(None, help=_THREADS_HELP),
    push: float = typer.Option(0.0, help="Push impulse [N s]; 0 for none."),
    push_time: float = typer.Option(1.0, help="Push start time [s]."),
    push_direction: float = typer.Option(90.0, help="Push direction [deg] (0 = +x, 90 = +y)."),
    push_duration: float = typer.Option(0.1, help="Push pulse length [s]."),
    noise_pos: float = typer.Option(0.0, help="CoM position estimate noise (std) [m]."),
    noise_vel: float = typer.Option(0.0, help="CoM velocity estimate noise (std) [m/s]."),
    placement_error: float = typer.Option(0.0, help="Landing error (std per axis) [m]."),
    mass_scale: float = typer.Option(1.0, help="True mass / model mass."),
    com_height_scale: float = typer.Option(1.0, help="True CoM height / model CoM height."),
    rate: float = typer.Option(500.0, help="Control rate [Hz]."),
    seed: int = typer.Option(0, help="Random seed."),
    engine: str = typer.Option(
        "auto", help="Loop engine: auto, compiled (numba) or python (reference)."
    ),
    out: Path = typer.Option(Path("out/simulate"), help="Output folder."),
) -> None:
    """Plan a scene, walk it in closed loop (MPC eq. 5.19 on the ALIP plant), write sim.json + figures."""
    import math

    from footfall.planning import PlannerOptions, make_plan
    from footfall.planning.plan import check_planner_name
    from footfall.sim import Push, SimOptions, simulate
    from footfall.sim.reduced.closed_loop import run_report
    from footfall.viz.sim_plots import save_sim_figures

    check_planner_name(planner)
    opts = SimOptions(
        control_rate=rate,
        noise_pos=noise_pos,
        noise_vel=noise_vel,
        mass_scale=mass_scale,
        com_height_scale=com_height_scale,
        pushes=(Push.horizontal(push_time, push, math.radians(push_direction), push_duration),)
        if push != 0
        else (),
        placement_error=placement_error,
        seed=seed,
        engine=engine,
    )
    sc = resolve_scene(scene)
    output_folder(out)
    # the reactive planner walks until the goal: --steps is for the horizon planners
    n = None if planner == "reactive" else steps
    plan = make_plan(
        sc, planner, n, PlannerOptions(time_limit=time_limit, threads=_threads(threads))
    )
    if not plan.has_solution:
        from footfall.errors import InfeasibleError

        raise InfeasibleError(f"{planner} found no plan for {sc.name}: {plan.message}")
    res = simulate(plan, opts, goal=sc.goal.position)
    m = res.metrics
    write_json(out / "sim.json", run_report(sc.name, plan, opts, res))
    figs = save_sim_figures(res, out, sc.terrain)
    outcome = f"FELL at {m.fall_time:.2f} s" if m.fell else ("stopped" if m.stopped else "walked")
    typer.echo(
        f"{sc.name} / {planner}: {outcome}; single-support ZMP offset mean "
        f"{1000 * m.zmp_offset_mean:.1f} mm, max {1000 * m.zmp_offset_max:.1f} mm; "
        f"goal error {m.goal_error:.3f} m; wrote {out / 'sim.json'} and {len(figs)} figures"
    )


# --- compare (issue 4) ---
#: help of the walks' ``--heading-segments`` (``walk``, ``compare --sim mujoco``)
_WALK_SEGMENTS_HELP = (
    "Heading segments L of the miqcqp / kinematic plans (eq. 5.12g-h); default: 64 for the "
    "robot-aware plans (with 16, straight plans step wide at theta = 0, a breakpoint of the 16; "
    "see plan_for_walk), the document's 16 with --document-reach."
)


@app.command("compare")
def compare_command(
    scenes: str = typer.Option(
        "discrete_steps,stairs_slope_gap", help="Comma-separated scene names or YAML files."
    ),
    planners: str = typer.Option("miqcqp,kinematic,reactive", help="Comma-separated planners."),
    trials: int = typer.Option(50, help="Seeded trials per scene and planner."),
    workers: int = typer.Option(2, help="Worker processes."),
    steps: str | None = typer.Option(
        None,
        help="Footsteps N of miqcqp/kinematic: one number, or per scene 'name=N,name=N' "
        "(default: the smallest N with a miqcqp plan).",
    ),
    time_limit: float = typer.Option(60.0, "--time-limit", help="Planner time limit [s]."),
    threads: int | None = typer.Option(None, help=_THREADS_HELP),
    push_max: float = typer.Option(15.0, help="Push impulses uniform in [0, push_max] [N s]."),
    noise_pos: float = typer.Option(0.002, help="CoM position estimate noise (std) [m]."),
    noise_vel: float = typer.Option(0.02, help="CoM velocity estimate noise (std) [m/s]."),
    placement_error: float = typer.Option(0.01, help="Landing error (std per axis) [m]."),
    mismatch: float = typer.Option(0.0, help="Mass/CoM-height mismatch fraction (uniform +-)."),
    rate: float = typer.Option(500.0, help="Control rate [Hz]."),
    out: Path = typer.Option(Path("out/compare"), help="Output folder (plans cached in plans/)."),
    sim: str = typer.Option(
        "reduced",
        help="reduced: the ALIP plant (fast, --trials disturbed trials); mujoco: the 30 kg biped "
        "in MuJoCo (--trials seeded walks, each with one push of push_max N s over 0.1 s).",
    ),
    robot_aware: bool = typer.Option(
        True,
        "--robot-aware/--document-reach",
        help="--sim mujoco: plan miqcqp/kinematic with the options beyond the document (as "
        "`walk`); --document-reach: the document's problem (the reduced simulation always is).",
    ),
    heading_segments: int | None = typer.Option(None, help="--sim mujoco: " + _WALK_SEGMENTS_HELP),
) -> None:
    """Section 5.5: every planner through the same MPC and plant over seeded disturbed trials."""
    import os

    if sim not in ("reduced", "mujoco"):
        raise InputError("sim", sim, "reduced or mujoco")
    n_steps = _steps_arg(steps)
    if sim == "mujoco":
        _compare_mujoco(
            scenes,
            planners,
            trials,
            push_max,
            time_limit,
            out,
            n_steps,
            robot_aware,
            heading_segments,
        )
        return

    from footfall.experiments.compare import (
        TrialSpec,
        describe,
        run_compare,
        summary_lines,
        write_outputs,
    )
    from footfall.planning.plan import PLANNERS, PlannerOptions

    _positive_int("trials", trials)
    _positive_int("workers", workers)
    names = names_in("planners", planners.split(","), PLANNERS)
    spec = TrialSpec(
        push_max=push_max,
        noise_pos=noise_pos,
        noise_vel=noise_vel,
        placement_error=placement_error,
        mismatch=mismatch,
        control_rate=rate,
    )
    scene_objs = {sc.name: sc for sc in map(resolve_scene, _list_arg(scenes))}
    output_folder(out)
    if not scene_objs:
        raise InputError("scenes", scenes, "one or more scene names or YAML files")
    # The MPC's small matrices run fastest single-threaded; spawned workers read this.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    with _progress_bar() as progress:
        options = PlannerOptions(time_limit=time_limit, threads=_threads(threads))
        rows, table, plans = run_compare(
            scene_objs, names, trials, out, spec, workers, n_steps, options, progress
        )
    paths = write_outputs(out, rows, table, describe(spec, trials, time_limit, plans))
    for line in summary_lines(table):
        console.print(line)
    console.print(f"wrote {', '.join(str(p) for p in paths)}")


def _steps_arg(steps: str | None) -> int | dict[str, int] | None:
    """``--steps`` of ``compare``: one N for every scene, or ``scene=N,scene=N``."""
    if steps is None:
        return None
    out: int | dict[str, int]
    try:
        if "=" in steps:
            out = {k.strip(): int(v) for k, v in (kv.split("=") for kv in steps.split(","))}
        else:
            out = int(steps)
    except ValueError:
        raise InputError("steps", steps, "an integer or 'scene=N,scene=N'") from None
    values = out.values() if isinstance(out, dict) else [out]
    if any(v < 1 for v in values):
        raise InputError("steps", steps, "step counts >= 1")
    return out


def _compare_mujoco(
    scenes: str,
    planners: str,
    trials: int,
    push_max: float,
    time_limit: float,
    out: Path,
    n_steps: int | dict[str, int] | None = None,
    robot_aware: bool = True,
    heading_segments: int | None = None,
) -> None:
    """``compare --sim mujoco``: the section 5.5 table from MuJoCo walks (issue 7)."""
    from footfall.experiments.compare_mujoco import (
        compare_mujoco,
        compare_table,
        describe,
        steps_per_pair,
        summary_lines,
        write_mujoco_outputs,
    )
    from footfall.planning.plan import PLANNERS
    from footfall.sim.biped.plans import PUSH_DURATION
    from footfall.terrain.scene import builtin_scene_names

    _positive_int("trials", trials)
    output_folder(out)
    push_max = non_negative("push_max", push_max)
    names = names_in("planners", planners.split(","), PLANNERS)
    scene_names = names_in("scenes", _list_arg(scenes), builtin_scene_names())
    force = push_max / PUSH_DURATION
    per_pair = steps_per_pair(scene_names, names, n_steps)
    with console.status("walking in MuJoCo ...") as status:
        rows = compare_mujoco(
            scene_names,
            names,
            seeds=tuple(range(trials)),
            push=force,
            n_steps=per_pair,
            time_limit=time_limit,
            cache_dir=out / "plans",
            progress=lambda line: status.update(line),
            robot_aware=robot_aware,
            heading_segments=heading_segments,
        )
    table = compare_table(rows)
    paths = write_mujoco_outputs(out, rows, table, describe(trials, force, PUSH_DURATION))
    for line in summary_lines(table):
        console.print(line)
    console.print(f"wrote {', '.join(str(p) for p in paths)}")


# --- walk (issue 7) ---
@app.command("walk")
def walk_cmd(
    scene_file: Path | None = typer.Argument(None, help="Scene YAML file (or use --scene)."),
    scene: str | None = typer.Option(None, help="Built-in scene name (see `footfall scenes`)."),
    planner: str = typer.Option("miqcqp", help="miqcqp, kinematic or reactive."),
    steps: int | None = typer.Option(
        None, help="Footsteps N (optimising planners); omitted: the smallest N with a plan."
    ),
    time_limit: float = typer.Option(300.0, help="Planner time limit per solve [s]."),
    push: float = typer.Option(0.0, help="Magnitude of one seeded horizontal push [N] (0: none)."),
    seed: int = typer.Option(0, help="Seed of the push direction and timing."),
    out: Path = typer.Option(Path("out/walk"), help="Output folder."),
    video: bool = typer.Option(True, "--video/--no-video", help="Write walk.mp4 (offscreen GL)."),
    robot: str = typer.Option(
        "biped",
        help="biped (ours) or g1 (Unitree G1 from example-robot-data: pip install "
        "'footfall[robots]'); the plan is made for its measured mass, CoM height and feet.",
    ),
    robot_aware: bool = typer.Option(
        True,
        "--robot-aware/--document-reach",
        help="Plan miqcqp/kinematic with the options beyond the document (reach in both feet's "
        "frames, swing bound); --document-reach: eq. (5.12f) in the stance foot's frame only.",
    ),
    heading_segments: int | None = typer.Option(None, help=_WALK_SEGMENTS_HELP),
) -> None:
    """Walk a footstep plan with the MuJoCo biped (document 000, section 5.5).

    Writes walk.json (fell or not, time to goal, footstep tracking error, single-support ZMP
    offset statistics per step), walk.png, walk.mp4 and plan.json (the plan walked; plans are
    cached in --out/plans and reused while nothing they depend on changes). Exit 1 when the robot falls or misses the goal.
    The optimising planners plan for this robot beyond the document: each step in the reach set
    of both feet's frames and every swing at most ``SWING_MAX`` (``plan_for_walk``), unless
    ``--document-reach``.
    """
    import os

    if video:
        # headless offscreen rendering; MuJoCo picks its GL backend when it is first imported
        os.environ.setdefault("MUJOCO_GL", "egl")
    from footfall.planning.plan import check_planner_name
    from footfall.sim.biped.options import WalkOptions
    from footfall.sim.biped.plans import plan_for_walk, random_push, robot_model
    from footfall.sim.biped.result import walk_report
    from footfall.sim.biped.walk import walk
    from footfall.viz.walk_plot import plot_walk

    check_planner_name(planner)
    if steps is not None and steps < 1:
        raise InputError("steps", steps, "an integer >= 1")
    push = non_negative("push", push)
    model = robot_model(robot)
    sc = resolve_scene_arguments(scene_file, scene)
    output_folder(out)
    with console.status(f"planning {sc.name} with {planner} for the {robot} ..."):
        plan = plan_for_walk(
            sc,
            planner,
            steps,
            time_limit,
            out / "plans",
            model=model,
            robot_aware=robot_aware,
            heading_segments=heading_segments,
        )
    write_json(out / "plan.json", plan.to_dict(sc.name))
    if not plan.has_solution:
        console.print(f"{sc.name}: {planner} found no plan ({plan.status.value}). {plan.message}")
        raise typer.Exit(1)
    pushes = (random_push(seed, push, plan, WalkOptions()),) if push > 0 else ()
    opts = WalkOptions(pushes=pushes)
    with console.status(f"walking {plan.n_steps} steps in MuJoCo ..."):
        res = walk(
            sc, plan, opts, model_params=model, video_path=out / "walk.mp4" if video else None
        )
    write_json(out / "walk.json", walk_report(sc.name, planner, robot, plan, pushes, res))
    plot_walk(res, sc, out / "walk.png", title=f"{sc.name}, {planner}, {robot}")
    m = res.metrics
    console.print(
        f"{sc.name} / {planner} / {robot}: {plan.n_steps} steps, fell={m.fell}, "
        f"reached goal={m.reached_goal}, footstep error mean "
        f"{m.footstep_error_m.mean:.3f} m, ZMP offset mean {m.zmp.mean:.3f} m "
        f"max {m.zmp.max:.3f} m"
    )
    if res.video_note:
        console.print(res.video_note)
    console.print(f"wrote {out / 'walk.json'}, walk.png" + (", walk.mp4" if res.video else ""))
    if m.fell or not m.reached_goal:
        raise typer.Exit(1)


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
    from footfall.experiments.bench import bench_plan, format_table, rows_to_dict

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


@bench_app.command("sim")
def bench_sim_cmd(
    scene: str = typer.Option("flat", "--scene", help="Built-in scene name or YAML file."),
    planner: str = typer.Option(
        "reactive", help="Planner of the walk: miqcqp, kinematic, reactive."
    ),
    nodes: str = typer.Option(
        "plan,10", help="MPC nodes K, comma separated ('plan': the plan robot's K)."
    ),
    runs: int = typer.Option(5, help="Timed runs per engine and K."),
    rate: float = typer.Option(500.0, help="Control rate [Hz]."),
    out: Path = typer.Option(Path("out/bench"), help="Output folder for bench_sim.json/.md."),
) -> None:
    """Reduced-order closed loop (issue 4): x real time of the python and compiled engines.

    The walk has estimate noise and two pushes; the engines run alternately in the same run.
    """
    from footfall.experiments.bench import (
        bench_sim,
        bench_sim_options,
        format_sim_table,
        sim_speed_to_dict,
    )
    from footfall.planning import PlannerOptions, make_plan
    from footfall.planning.plan import check_planner_name

    check_planner_name(planner)
    k_list: list[int | None] = []
    for item in (s.strip() for s in nodes.split(",")):
        if item == "plan":
            k_list.append(None)
        elif item.isdigit() and int(item) >= 2:
            k_list.append(int(item))
        else:
            raise InputError(
                "nodes", nodes, "comma-separated integers >= 2 or 'plan', e.g. plan,10"
            )
    sc = resolve_scene(scene)
    plan = make_plan(sc, planner, None, PlannerOptions(threads=_threads(None)))
    if not plan.has_solution:
        from footfall.errors import InfeasibleError

        raise InfeasibleError(f"{planner} found no plan for {sc.name}: {plan.message}")
    rows = bench_sim(plan, k_list, runs=runs, options=bench_sim_options(rate))
    table = format_sim_table(rows)
    out.mkdir(parents=True, exist_ok=True)
    write_json(
        out / "bench_sim.json",
        {"scene": sc.name, "planner": planner, "rows": sim_speed_to_dict(rows)},
    )
    (out / "bench_sim.md").write_text(table + "\n")
    print(table)


@bench_app.command("quadruped")
def bench_quadruped_cmd(
    slope_deg: float = typer.Option(15.0, help="Slope angle [deg]."),
    body_deg: float = typer.Option(10.0, help="Body angle [deg]."),
    out: Path = typer.Option(Path("out/bench"), help="Output folder for bench_quadruped.json."),
) -> None:
    """Quadruped slope walk: simulated s per wall s vs bare mj_step, and gait-plan time."""
    from footfall.experiments.bench import benchmark_quadruped

    result = benchmark_quadruped(slope_deg=slope_deg, body_deg=body_deg)
    write_json(out / "bench_quadruped.json", result)
    for key, value in result.items():
        console.print(f"{key}: {value}")


if __name__ == "__main__":  # `python -m footfall.cli` as well as `python -m footfall`
    main()
