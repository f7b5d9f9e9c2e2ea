"""Commands that walk plans: ``simulate`` and ``compare`` (000 sec. 5.5), ``walk`` (MuJoCo bipeds),
``quadruped`` (001) and the ``demo``."""

from __future__ import annotations

import math
import os
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import typer

from footfall._io import remove_outputs, write_json
from footfall._validate import names_in, non_negative
from footfall.cli._common import (
    _THREADS_HELP,
    _list_arg,
    _positive_int,
    _progress_bar,
    _threads,
    app,
    console,
    output_folder,
    refuse_inputs_as_outputs,
)
from footfall.cli._progress import ProgressLog
from footfall.errors import InputError

_REGION_HELP = (
    "How the MPC keeps the next footstep on the terrain (issue 23): off (document 000: free; "
    "the MuJoCo walker keeps a uniform margin inside the planned region), planned (in the planned "
    "region inset by the sole, same QP), nearby (or the best region within reach)."
)


# --- demo ---
@app.command()
def demo(out: Path = typer.Option(Path("out/demo"), help="Output folder.")) -> None:
    """Run the main demo on built-in defaults and write figures and JSON into OUT."""
    from footfall.experiments.demo import run_demo

    output_folder(out)
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


# --- quadruped (document 001) ---
@app.command("quadruped")
def quadruped_cmd(
    slope_deg: float | None = typer.Option(
        None, help="Slope angle beta_S [deg]; negative walks downhill. [default: 15]"
    ),
    body_deg: float | None = typer.Option(
        None,
        help="Body angle beta_B to the horizontal [deg], between 0 and the slope. [default: two "
        "thirds of the slope, the compromise posture: 10 on 15, -10 on -15]",
    ),
    step: float | None = typer.Option(None, help="Step length S along the slope [m]. [0.4]"),
    height: float | None = typer.Option(None, help="Swing height H normal to the slope [m]. [0.1]"),
    cycles: int | None = typer.Option(None, help="Number of gait cycles. [6]"),
    swing_period: float | None = typer.Option(None, help="Swing period T_w [s]. [0.5]"),
    shift_period: float | None = typer.Option(None, help="Duration of each body shift [s]. [1.5]"),
    strategy: str | None = typer.Option(
        None, help="ZMP placement: osp, incentre or transverse. [osp]"
    ),
    scene: str | None = typer.Option(
        None,
        help="A quadruped scene: a built-in name (slope_15, downhill_20, side_slope, "
        "varying_slope, stairs_10cm) or a YAML file (schema: terrain/SCHEMA.md). Its ground, "
        "gait and friction replace the options above; --cycles may still shorten it.",
    ),
    compare: bool = typer.Option(False, help="Also run the other strategies (body sway table)."),
    out: Path = typer.Option("out/quadruped", help="Output folder."),
    video: bool = typer.Option(True, "--video/--no-video", help="Render an MP4 (offscreen GL)."),
    controller: str = typer.Option(
        "servo",
        help="servo: the document's joint position servos on the planned angles; wbc: joint "
        "torques from the whole-body QP that puts the centre of pressure on the planned ZMP.",
    ),
    on_slip: str = typer.Option(
        "off",
        help="Slip guard: off, or stop (when a foot slides more than --slip-limit in one stance, "
        "land the swinging foot, if any, then hold the four-foot stance).",
    ),
    slip_limit: float = typer.Option(
        0.03, help="Slip guard limit: a foot's sliding in one stance [m]."
    ),
) -> None:
    """Walk gait up a slope (document 001) or over a scene's ground: plan with ZMP/OSP, simulate
    in MuJoCo, measure."""
    if video:
        # must be chosen before MuJoCo is imported; EGL works headless here
        os.environ.setdefault("MUJOCO_GL", "egl")
    from footfall.sim._mjcf import require_mujoco

    require_mujoco()  # before any work: a missing extra is one line, exit 2
    from footfall.experiments.slope_walk import compare_strategies, plan_strategies
    from footfall.quadruped import QuadrupedRobot
    from footfall.sim.quadruped.mjcf import SimSettings
    from footfall.sim.quadruped.sim import simulate
    from footfall.sim.quadruped.slip import SLIP_ACTIONS, SlipGuard
    from footfall.viz.quadruped_plots import WALK_FIGURES, save_walk_figures

    if controller not in ("servo", "wbc"):
        raise InputError("--controller", controller, "servo or wbc")
    if on_slip not in ("off", *SLIP_ACTIONS):
        raise InputError("--on-slip", on_slip, f"one of off, {', '.join(SLIP_ACTIONS)}")
    if not math.isfinite(slip_limit) or slip_limit <= 0.0:
        raise InputError("--slip-limit", slip_limit, "a finite distance > 0 [m]")
    guard = SlipGuard(slip_limit, on_slip) if on_slip != "off" else None
    options = {
        "--slope-deg": slope_deg,
        "--body-deg": body_deg,
        "--step": step,
        "--height": height,
        "--swing-period": swing_period,
        "--shift-period": shift_period,
        "--strategy": strategy,
    }
    settings = None
    if scene is not None:
        from footfall.quadruped.scene import resolve_quadruped_scene

        given = [name for name, v in options.items() if v is not None]
        if given:
            raise InputError(given[0], options[given[0]], "no gait option with --scene")
        sc = resolve_quadruped_scene(scene)
        params = sc.params
        if cycles is not None:
            params = replace(params, cycles=cycles)
        if sc.friction is not None:
            settings = SimSettings(friction=sc.friction)
        label = sc.name
    else:
        slope = 15.0 if slope_deg is None else slope_deg
        params = _slope_params(
            slope,
            default_body_deg(slope) if body_deg is None else body_deg,
            (step, height, cycles, swing_period, shift_period),
            "osp" if strategy is None else strategy,
        )
        label = f"{math.degrees(params.slope):g}°/{math.degrees(params.body_pitch):g}°"
    outputs = ["quadruped.json", "quadruped.mp4", *WALK_FIGURES]
    refuse_inputs_as_outputs([scene], {"out": [out / name for name in outputs]})
    output_folder(out)
    # this run's files replace the last run's as a set: none of theirs is left beside ours
    remove_outputs(out, *outputs)
    plans, infeasible = plan_strategies(QuadrupedRobot(), params, compare)
    plan = plans[params.strategy]
    console.print(f"simulating {params.cycles} cycles on {label} ({plan.duration:.1f} s)...")
    res = simulate(
        plan,
        settings,
        video_path=out / "quadruped.mp4" if video else None,
        controller=controller,
        slip_guard=guard,
    )
    if video and res.video is None:
        console.print(res.video_note)
    payload = res.metrics.to_dict()
    payload["controller"] = {"name": controller, "qp_failures": res.qp_failures}
    payload["slip_guard"] = {
        "on_slip": on_slip,
        "limit_m": slip_limit,
        "stop": asdict(res.slip_stop) if res.slip_stop is not None else None,
    }
    if scene is not None:
        payload["scene"] = scene
    if compare:
        payload["strategy_comparison"] = compare_strategies(plans, res)
        payload["strategy_comparison_infeasible"] = infeasible
    figs = save_walk_figures(plan, res, out, label)
    payload["figures"] = [str(f) for f in figs]
    write_json(out / "quadruped.json", payload)
    m = res.metrics
    margin = (
        f"margin min {m.stability_margin_min_m:.3f} m mean {m.stability_margin_mean_m:.3f} m"
        if m.stability_margin_min_m is not None and m.stability_margin_mean_m is not None
        else "no stance sample with three loaded feet"
    )
    console.print(
        f"distance {m.distance_up_slope_m:.2f} m, speed {m.mean_speed_m_s:.3f} m/s, "
        f"fell {m.fell}, {margin}, {m.realtime_factor:.0f}x real time"
    )
    if m.zmp_error_mean_m is not None and m.zmp_error_max_m is not None:
        console.print(
            f"{controller}: centre of pressure vs planned ZMP: mean "
            f"{100 * m.zmp_error_mean_m:.1f} cm, max {100 * m.zmp_error_max_m:.1f} cm"
        )
    console.print(
        f"slip per stance: max {100 * m.foot_slip_max_m:.1f} cm, mean "
        f"{100 * m.foot_slip_mean_m:.1f} cm over {len(m.stance_slips)} stances"
    )
    if res.slip_stop is not None:
        st = res.slip_stop
        console.print(
            f"slip guard: {st.leg} slid {100 * st.slip_m:.1f} cm at {st.time_s:.2f} s; "
            f"holding four feet from {st.hold_time_s:.2f} s"
        )
    console.print(f"wrote {out / 'quadruped.json'}")
    if m.fell:
        raise typer.Exit(1)


def default_body_deg(slope_deg: float) -> float:
    """The body angle [deg] that follows a slope of ``slope_deg`` [deg] when none is given: the
    compromise posture (``BODY_RATIO`` of the slope, so downhill is negative too)."""
    from footfall.quadruped.gait import BODY_RATIO

    return BODY_RATIO * slope_deg if math.isfinite(slope_deg) else slope_deg


def _slope_params(
    slope_deg: float,
    body_deg: float,
    gait: tuple[float | None, float | None, int | None, float | None, float | None],
    strategy: str,
) -> Any:
    """GaitParams of the document's slope from the CLI options (errors name the option)."""
    from footfall.quadruped import GaitParams, ZmpStrategy

    if not math.isfinite(slope_deg) or not -60.0 <= slope_deg <= 60.0:
        raise InputError("--slope-deg", slope_deg, "a slope in [-60, 60] deg (negative: downhill)")
    lo, hi = min(0.0, slope_deg), max(0.0, slope_deg)
    if not math.isfinite(body_deg) or not lo <= body_deg <= hi:
        raise InputError(
            "--body-deg", body_deg, f"a body angle between 0 and --slope-deg = {slope_deg:g} deg"
        )
    try:
        strat = ZmpStrategy(strategy)
    except ValueError:
        raise InputError("--strategy", strategy, "one of osp, incentre, transverse") from None
    step, height, cycles, swing_period, shift_period = gait
    params = GaitParams(
        slope=math.radians(slope_deg), body_pitch=math.radians(body_deg), strategy=strat
    )
    given: dict[str, Any] = {
        "step": step,
        "swing_height": height,
        "cycles": cycles,
        "swing_period": swing_period,
        "shift_period": shift_period,
    }
    return replace(params, **{k: v for k, v in given.items() if v is not None})


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
    region_aware: str = typer.Option("off", "--region-aware", help=_REGION_HELP),
    out: Path = typer.Option(Path("out/simulate"), help="Output folder."),
) -> None:
    """Plan a scene, walk it in closed loop (MPC eq. 5.19 on the ALIP plant), write sim.json + figures."""
    import math

    from footfall.planning import PlannerOptions, make_plan
    from footfall.planning.plan import check_planner_name
    from footfall.sim import Push, SimOptions, simulate
    from footfall.sim.reduced.closed_loop import run_report
    from footfall.terrain.resolve import resolve_scene
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
        region_aware=region_aware,
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
    res = simulate(plan, opts, goal=sc.goal.position, regions=sc.terrain.regions)
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
#: the walker's controller unless --controller says otherwise
DEFAULT_CONTROLLER = "wbc"
_CONTROLLER_HELP = (
    "wbc: whole-body inverse dynamics, every joint torque-driven, the ALIP ankle torque as the "
    "commanded centre of pressure (500 Hz QP); servo: differential IK to joint position servos."
)


def _check_region_aware(region_aware: str) -> None:
    """Refuse an unknown ``--region-aware`` before any planning."""
    from footfall.control.adjusters import REGION_MODES

    if region_aware not in REGION_MODES:
        raise InputError("region_aware", region_aware, f"one of {', '.join(REGION_MODES)}")


def _check_controller(controller: str) -> None:
    from footfall.sim.biped.options import CONTROLLERS

    if controller not in CONTROLLERS:
        raise InputError("controller", controller, f"one of {', '.join(CONTROLLERS)}")


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
    region_aware: str = typer.Option(
        "off", "--region-aware", help="--sim reduced: " + _REGION_HELP
    ),
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
    controller: str = typer.Option(
        DEFAULT_CONTROLLER, help="--sim mujoco: the walker's controller, " + _CONTROLLER_HELP
    ),
) -> None:
    """Section 5.5: every planner through the same MPC and plant over seeded disturbed trials."""
    from footfall.terrain.resolve import resolve_scene

    if sim not in ("reduced", "mujoco"):
        raise InputError("sim", sim, "reduced or mujoco")
    _check_controller(controller)
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
            controller,
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
        region_aware=region_aware,
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
    controller: str = DEFAULT_CONTROLLER,
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
            controller=controller,
            # plain lines (printed above the status line; a second live display is refused)
            monitor_for=lambda title: ProgressLog(title, terminal=False),
        )
    table = compare_table(rows)
    header = describe(trials, force, PUSH_DURATION) + f" Controller: {controller}."
    paths = write_mujoco_outputs(out, rows, table, header)
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
    controller: str | None = typer.Option(
        None, help=_CONTROLLER_HELP + " Default: the robot's (biped: wbc, g1: servo)."
    ),
    region_aware: str = typer.Option(
        "planned",
        "--region-aware",
        help=_REGION_HELP + " The walker's default is planned (issue 23: 90/90 pushed walks "
        "over the built-in scenes reached the goal, 70/90 with off).",
    ),
    quiet: bool = typer.Option(
        False, "--quiet", help="No planning progress lines or status line (results still print)."
    ),
    log_json: Path | None = typer.Option(
        None,
        "--log-json",
        help="Write the planning progress as JSON lines to this file (as `footfall plan`).",
    ),
) -> None:
    """Walk a footstep plan with the MuJoCo biped (document 000, section 5.5).

    Writes walk.json (fell or not, time to goal, footstep tracking error, single-support ZMP
    offset statistics per step), walk.png, walk.mp4 and plan.json (the plan walked; plans are
    cached in --out/plans and reused while nothing they depend on changes). Exit 1 when the robot falls or misses the goal.
    The optimising planners plan for this robot beyond the document: each step in the reach set
    of both feet's frames and every swing at most ``SWING_MAX`` (``plan_for_walk``), unless
    ``--document-reach``.
    """
    from footfall.terrain.resolve import resolve_scene_arguments

    if video:
        # headless offscreen rendering; MuJoCo picks its GL backend when it is first imported
        os.environ.setdefault("MUJOCO_GL", "egl")
    from footfall.planning.plan import check_planner_name
    from footfall.sim.biped.options import WalkOptions
    from footfall.sim.biped.plans import ROBOT_CONTROLLERS, plan_for_walk, random_push, robot_model
    from footfall.sim.biped.result import walk_report
    from footfall.sim.biped.walk import walk
    from footfall.viz.walk_plot import plot_walk

    check_planner_name(planner)
    if controller is None:
        controller = ROBOT_CONTROLLERS.get(robot, DEFAULT_CONTROLLER)
    _check_controller(controller)
    _check_region_aware(region_aware)
    if steps is not None and steps < 1:
        raise InputError("steps", steps, "an integer >= 1")
    push = non_negative("push", push)
    model = robot_model(robot)
    sc = resolve_scene_arguments(scene_file, scene)
    files = ("plan.json", "walk.json", "walk.png", "walk.mp4")
    logs = [log_json] if log_json else []
    refuse_inputs_as_outputs(
        [scene_file, scene], {"out": [out / f for f in files], "log_json": logs}
    )
    output_folder(out)
    remove_outputs(out, *files)  # no file of an earlier run beside this run's
    with ProgressLog(f"{sc.name} with {planner} for the {robot}", quiet, log_json) as log:
        plan = plan_for_walk(
            sc,
            planner,
            steps,
            time_limit,
            out / "plans",
            model=model,
            robot_aware=robot_aware,
            heading_segments=heading_segments,
            monitor=log,
        )
        log.done(plan)
    write_json(out / "plan.json", plan.to_dict(sc.name))
    if not plan.has_solution:
        console.print(f"{sc.name}: {planner} found no plan ({plan.status.value}). {plan.message}")
        raise typer.Exit(1)
    opts = WalkOptions(controller=controller, region_aware=region_aware)
    pushes = (random_push(seed, push, plan, opts),) if push > 0 else ()
    opts = WalkOptions(controller=controller, pushes=pushes, region_aware=region_aware)
    with console.status(f"walking {plan.n_steps} steps in MuJoCo ..."):
        res = walk(
            sc, plan, opts, model_params=model, video_path=out / "walk.mp4" if video else None
        )
    # walk.json's "controller" (from the result) names the controller and holds its tally
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
