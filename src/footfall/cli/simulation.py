"""Commands that walk plans: ``simulate`` and ``compare`` (000 sec. 5.5), ``walk`` (MuJoCo bipeds),
``quadruped`` (001) and the ``demo``."""

from __future__ import annotations

import math
import os
from dataclasses import asdict, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from footfall._io import remove_outputs, write_json
from footfall.cli._common import (
    _THREADS_HELP,
    HEADING_WINDOWS_HELP,
    ROBOT_HELP,
    PushDirectionOption,
    PushDurationOption,
    PushDvOption,
    PushOption,
    PushPhaseOption,
    PushStepOption,
    SeedOption,
    _list_arg,
    _threads,
    app,
    console,
    disturbance_of,
    output_folder,
    refuse_inputs_as_outputs,
)
from footfall.cli._progress import ProgressLog
from footfall.errors import InputError

if TYPE_CHECKING:
    pass

_REGION_HELP = (
    "How the MPC keeps the next footstep on the terrain: off (document 000: free; "
    "the MuJoCo walker keeps a uniform margin inside the planned region), planned (in the planned "
    "region inset by the sole, same QP), nearby (or the best region within reach), horizon "
    "(the region that the 3-footstep MIQP from the measured state chooses, re-solved at 50 Hz)."
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
        "wbc",
        help="wbc: joint torques from the whole-body QP that puts the centre of pressure on the "
        "planned ZMP; servo: the document's joint position servos on the planned angles.",
    ),
    robot: str = typer.Option(
        "document",
        "--robot",
        help="The quadruped: document (document 001's 100 kg robot), a built-in (go2, solo12, "
        "anymal_c, from example-robot-data) or a quadruped robot file (.yaml, see footfall robot "
        "inspect). On another robot than the document's, the default gait and the scene's gait "
        "and ground lengths scale with its stance height against 0.6 m, periods with the square "
        "root; options given here are taken as they are.",
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
    from footfall._mjcf import require_mujoco

    require_mujoco()  # before any work: a missing extra is one line, exit 2
    from footfall.experiments.slope_walk import compare_strategies, plan_strategies
    from footfall.sim.quadruped.sim import simulate
    from footfall.sim.quadruped.slip import SLIP_ACTIONS, SlipGuard
    from footfall.sim.replay import REPLAY_FILE, ReplayRecorder, quadruped_traces
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
    from footfall.quadruped.scaling import scale_gait
    from footfall.robots.quadruped import resolve_quadruped
    from footfall.sim.quadruped.mjcf import robot_settings

    quad = resolve_quadruped(robot)
    friction = None
    if scene is not None:
        from footfall.quadruped.scene import resolve_quadruped_scene

        given = [name for name, v in options.items() if v is not None]
        if given:
            raise InputError(given[0], options[given[0]], "no gait option with --scene")
        sc = resolve_quadruped_scene(scene)
        params = scale_gait(quad, sc.params)
        if cycles is not None:
            params = replace(params, cycles=cycles)
        friction = sc.friction
        label = sc.name
    else:
        slope = 15.0 if slope_deg is None else slope_deg
        doc = _slope_params(
            slope,
            default_body_deg(slope) if body_deg is None else body_deg,
            (None, None, cycles, None, None),
            "osp" if strategy is None else strategy,
        )
        # the document's gait scaled to the robot; the options given replace it as they are
        params = _with_given(
            scale_gait(quad, doc), (step, height, None, swing_period, shift_period)
        )
        label = f"{math.degrees(params.slope):g}°/{math.degrees(params.body_pitch):g}°"
    settings = robot_settings(quad, friction)
    if quad.legs is not None:
        label = f"{quad.name}, {label}"
    outputs = ["quadruped.json", "quadruped.mp4", REPLAY_FILE, *WALK_FIGURES]
    refuse_inputs_as_outputs([scene], {"out": [out / name for name in outputs]})
    output_folder(out)
    # this run's files replace the last run's as a set: none of theirs is left beside ours
    remove_outputs(out, *outputs)
    plans, infeasible = plan_strategies(quad, params, compare)
    plan = plans[params.strategy]
    console.print(f"simulating {params.cycles} cycles on {label} ({plan.duration:.1f} s)...")
    replay = ReplayRecorder("quadruped")
    res = simulate(
        plan,
        settings,
        video_path=out / "quadruped.mp4" if video else None,
        controller=controller,
        slip_guard=guard,
        replay=replay,
    )
    replay.write(out / REPLAY_FILE, quadruped_traces(res.trace, replay.times))
    if video and res.video is None:
        console.print(res.video_note)
    payload = res.metrics.to_dict()
    payload["controller"] = {"name": controller, "qp_failures": res.trace.qp_failures}
    payload["robot"] = {
        "name": quad.name,
        "mass_kg": quad.total_mass,
        "stance_height_m": quad.stance_height,
        "gait": {
            "step_m": params.step,
            "swing_height_m": params.swing_height,
            "swing_period_s": params.swing_period,
            "shift_period_s": params.shift_period,
            "lateral_share": params.lateral_share,
        },
    }
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
    figs = save_walk_figures(plan, res.trace, out, label)
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
    console.print(f"wrote {out / 'quadruped.json'} and {REPLAY_FILE}")
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
    params = GaitParams(
        slope=math.radians(slope_deg), body_pitch=math.radians(body_deg), strategy=strat
    )
    return _with_given(params, gait)


def _with_given(
    params: Any, gait: tuple[float | None, float | None, int | None, float | None, float | None]
) -> Any:
    """``params`` with the gait options given (step, swing height, cycles, swing and shift
    periods; None: not given) in their place."""
    step, height, cycles, swing_period, shift_period = gait
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
    push: PushOption = 0.0,
    push_dv: PushDvOption = None,
    seed: SeedOption = 0,
    push_step: PushStepOption = None,
    push_phase: PushPhaseOption = None,
    push_direction: PushDirectionOption = None,
    push_duration: PushDurationOption = 0.1,
    noise_pos: float = typer.Option(0.0, help="CoM position estimate noise (std) [m]."),
    noise_vel: float = typer.Option(0.0, help="CoM velocity estimate noise (std) [m/s]."),
    placement_error: float = typer.Option(0.0, help="Landing error (std per axis) [m]."),
    mass_scale: float = typer.Option(1.0, help="True mass / model mass."),
    com_height_scale: float = typer.Option(1.0, help="True CoM height / model CoM height."),
    rate: float = typer.Option(500.0, help="Control rate [Hz]."),
    engine: str = typer.Option(
        "auto", help="Loop engine: auto, compiled (numba) or python (reference)."
    ),
    region_aware: str = typer.Option("off", "--region-aware", help=_REGION_HELP),
    out: Path = typer.Option(Path("out/simulate"), help="Output folder."),
) -> None:
    """Plan a scene, walk it in closed loop (MPC eq. 5.19 on the ALIP plant), write sim.json + figures."""
    from footfall.planning import PlannerOptions, make_plan
    from footfall.planning.plan import check_planner_name
    from footfall.sim.reduced.closed_loop import SimOptions, run_report
    from footfall.sim.reduced.trial import ReducedPlant
    from footfall.sim.trial import run_trial, trial_pushes
    from footfall.terrain.resolve import resolve_scene
    from footfall.viz.sim_plots import save_sim_figures

    check_planner_name(planner)
    disturbance = disturbance_of(
        push, push_dv, seed, push_step, push_phase, push_direction, push_duration
    )
    plant = ReducedPlant(
        SimOptions(
            control_rate=rate,
            noise_pos=noise_pos,
            noise_vel=noise_vel,
            mass_scale=mass_scale,
            com_height_scale=com_height_scale,
            placement_error=placement_error,
            engine=engine,
            region_aware=region_aware,
        )
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
    pushes = trial_pushes(plant, plan, disturbance)
    res = run_trial(plant, sc, plan, disturbance).detail
    m = res.metrics
    opts = replace(plant.options, pushes=pushes, seed=seed)
    write_json(out / "sim.json", run_report(sc.name, plan, opts, res))
    figs = save_sim_figures(res, out, sc.terrain)
    outcome = f"FELL at {m.fall_time:.2f} s" if m.fell else ("stopped" if m.stopped else "walked")
    typer.echo(
        f"{sc.name} / {planner}: {outcome}; single-support ZMP offset mean "
        f"{1000 * m.zmp_offset_mean:.1f} mm, max {1000 * m.zmp_offset_max:.1f} mm; "
        f"goal error {m.goal_error:.3f} m; wrote {out / 'sim.json'} and {len(figs)} figures"
    )


#: the walker's controller unless --controller says otherwise
DEFAULT_CONTROLLER = "wbc"
_CONTROLLER_HELP = (
    "wbc: whole-body inverse dynamics, every joint torque-driven, the ALIP ankle torque as the "
    "commanded centre of pressure (500 Hz QP); servo: differential IK to joint position servos."
)


def _check_controller(controller: str) -> None:
    from footfall.sim.biped.options import CONTROLLERS

    if controller not in CONTROLLERS:
        raise InputError("controller", controller, f"one of {', '.join(CONTROLLERS)}")


#: help of the walks' ``--heading-segments``
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
    trials: int = typer.Option(50, help="Seeded walks per scene and planner (seeds 0 ... N-1)."),
    push: float = typer.Option(
        3.0,
        help="Push impulse of every walk [N s]; its direction, step and phase are drawn from "
        "the walk's seed (the same push for every planner).",
    ),
    steps: str = typer.Option(
        "smallest",
        help="N of the horizon planners: smallest (each its own smallest N), equal (the reactive "
        "walk's N), or both: smallest,equal.",
    ),
    sim: str = typer.Option(
        "reduced",
        help="reduced: the ALIP closed loop (fast); mujoco: the 30 kg biped in MuJoCo.",
    ),
    controller: str = typer.Option(
        DEFAULT_CONTROLLER, help="--sim mujoco: the walker's controller, " + _CONTROLLER_HELP
    ),
    robot: str = typer.Option("biped", help="--sim mujoco: " + ROBOT_HELP),
    noise_pos: float | None = typer.Option(
        None, help="--sim reduced: CoM position estimate noise (std) [m]. [default: 0.002]"
    ),
    noise_vel: float | None = typer.Option(
        None, help="--sim reduced: CoM velocity estimate noise (std) [m/s]. [default: 0.02]"
    ),
    placement_error: float | None = typer.Option(
        None, help="--sim reduced: landing error (std per axis) [m]. [default: 0.01]"
    ),
    region_aware: str = typer.Option("off", "--region-aware", help=_REGION_HELP),
    time_limit: float = typer.Option(300.0, "--time-limit", help="Planner time limit [s]."),
    workers: int | None = typer.Option(
        None, help="Parallel walks (default: the cores this process may use)."
    ),
    executor: str = typer.Option("local", help="local (process pool) or ray."),
    out: Path = typer.Option(Path("out/compare"), help="Output folder (reruns resume it)."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress lines."),
) -> None:
    """Section 5.5: every planner through the same controller and plant over seeded pushed walks.

    A preset of `footfall study` (one push level, no initial perturbation): the same runner,
    executors, trials.parquet rows, summary.md statistics and figures."""
    from footfall.experiments.study.design import StudyDesign

    # the reduced-order walks are disturbed like section55_reduced's; MuJoCo's are deterministic
    noise = {"noise_pos": noise_pos, "noise_vel": noise_vel, "placement_error": placement_error}
    defaults = {"noise_pos": 0.002, "noise_vel": 0.02, "placement_error": 0.01}
    for name, value in noise.items():
        if value is None:
            noise[name] = defaults[name] if sim == "reduced" else 0.0
    design = StudyDesign(
        name="compare",
        simulator=sim,
        controller=controller if sim == "mujoco" else None,
        scenes=tuple(_list_arg(scenes)),
        planners=tuple(_list_arg(planners)),
        steps=tuple(_list_arg(steps)),
        default_push=push,
        seeds=trials,
        push_levels=(),
        level_seeds=0,
        initial_impulse=0.0,
        time_limit=time_limit,
        region_aware=region_aware,
        robot=robot,
        **noise,  # type: ignore[arg-type]
    )
    from footfall.cli.study import run_design

    run_design(design, out, executor, workers, None, None, quiet)


# --- walk ---
@app.command("walk")
def walk_cmd(
    scene_file: Path | None = typer.Argument(None, help="Scene YAML file (or use --scene)."),
    scene: str | None = typer.Option(None, help="Built-in scene name (see `footfall scenes`)."),
    planner: str = typer.Option("miqcqp", help="miqcqp, kinematic or reactive."),
    steps: int | None = typer.Option(
        None, help="Footsteps N (optimising planners); omitted: the smallest N with a plan."
    ),
    time_limit: float = typer.Option(
        300.0,
        help="Planner time limit per solve [s]. A MIQCQP solve that finds no plan in it is "
        "followed by a search with the headings pinned outside a window of footsteps, for as "
        "long again.",
    ),
    push: PushOption = 0.0,
    push_dv: PushDvOption = None,
    seed: SeedOption = 0,
    push_step: PushStepOption = None,
    push_phase: PushPhaseOption = None,
    push_direction: PushDirectionOption = None,
    push_duration: PushDurationOption = 0.1,
    out: Path = typer.Option(Path("out/walk"), help="Output folder."),
    video: bool = typer.Option(True, "--video/--no-video", help="Write walk.mp4 (offscreen GL)."),
    robot: str = typer.Option("biped", help=ROBOT_HELP),
    robot_aware: bool = typer.Option(
        True,
        "--robot-aware/--document-reach",
        help="Plan miqcqp/kinematic with the options beyond the document (reach in both feet's "
        "frames, swing bound); --document-reach: eq. (5.12f) in the stance foot's frame only.",
    ),
    heading_segments: int | None = typer.Option(None, help=_WALK_SEGMENTS_HELP),
    # PlannerOptions.heading_windows (a test keeps them equal)
    heading_windows: int = typer.Option(2, help=HEADING_WINDOWS_HELP),
    controller: str = typer.Option(DEFAULT_CONTROLLER, help=_CONTROLLER_HELP),
    region_aware: str = typer.Option(
        "horizon",  # WalkOptions.region_aware's default (a test keeps them equal)
        "--region-aware",
        help=_REGION_HELP + " The walker's default is horizon (against planned, over the same "
        "pushed walks on terrain of three robots: 13 walks gained, 2 lost).",
    ),
    leg_momentum: float | None = typer.Option(
        None,
        "--leg-momentum",
        help="Share in [0, 1] of the legs' sagittal momentum about the CoM [kg m^2/s], "
        "forecast over each single support from the last ones, that the MPC's prediction "
        "carries (0: off, the document's point-mass prediction). Default: 0.5 with the wbc "
        "controller, 0 with servo (whose MPC gets the true momentum, legs included).",
    ),
    walk_on: int | None = typer.Option(
        None,
        "--walk-on",
        help="Stopping steps the walker may add, two at a time, when its stopping steps land "
        "more than 0.1 m (the goal tolerance) from their final footholds (a push moved the walk "
        "off its goal); 0: stop where the planned stopping steps end. Default: the walker's, 4.",
    ),
    step_timing: bool = typer.Option(
        True,  # WalkOptions.step_timing's default (a test keeps them equal)
        "--step-timing/--no-step-timing",
        help="The MPC chooses when the swing foot lands as well as where: a single support ends "
        "sooner (in its first half, by at most 30 % of the time it has left) when that lowers "
        "the MPC's cost by 0.5, e.g. after a push. It moves nothing in an unpushed walk.",
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
    offset statistics per step, the push), walk.png, walk.mp4 and plan.json (the plan walked;
    plans are cached in --out/plans and reused while nothing they depend on changes). Exit 1
    when the robot falls or misses the goal. The optimising planners plan for this robot beyond
    the document: each step in the reach set of both feet's frames and every swing no longer than
    the longest the robot has walked, unless --document-reach.
    """
    from footfall.terrain.resolve import resolve_scene_arguments

    if video:
        # headless offscreen rendering; MuJoCo picks its GL backend when it is first imported
        os.environ.setdefault("MUJOCO_GL", "egl")
    from footfall.planning.plan import check_planner_name
    from footfall.results.walk import walk_report
    from footfall.sim.biped.model import planner_params
    from footfall.sim.biped.options import WalkOptions, check_start_soles
    from footfall.sim.biped.plans import plan_for_walk, robot_model
    from footfall.sim.biped.trial import MujocoBipedPlant
    from footfall.sim.replay import REPLAY_FILE, ReplayRecorder, biped_traces
    from footfall.sim.trial import run_trial, trial_pushes
    from footfall.terrain import scene_to_yaml
    from footfall.viz.walk_plot import plot_walk

    check_planner_name(planner)
    _check_controller(controller)
    # the walker's options (region mode, leg-momentum share) are checked before planning, which
    # can take minutes
    options = WalkOptions(
        controller=controller, region_aware=region_aware, leg_momentum=leg_momentum
    )
    if walk_on is not None:
        options = replace(options, walk_on=walk_on)
    options = replace(options, step_timing=step_timing)
    if steps is not None and steps < 1:
        raise InputError("steps", steps, "an integer >= 1")
    disturbance = disturbance_of(
        push, push_dv, seed, push_step, push_phase, push_direction, push_duration
    )
    model = robot_model(robot)
    sc = resolve_scene_arguments(scene_file, scene)
    # before planning: a start the robot cannot stand on is refused now, not after minutes
    check_start_soles(sc, planner_params(model, base=sc.robot))
    files = ("plan.json", "walk.json", "walk.png", "walk.mp4", REPLAY_FILE)
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
            heading_windows=heading_windows,
        )
        log.done(plan)
    write_json(out / "plan.json", plan.to_dict(sc.name))
    if not plan.has_solution:
        console.print(f"{sc.name}: {planner} found no plan ({plan.status.value}). {plan.message}")
        raise typer.Exit(1)
    replay = ReplayRecorder("biped")
    plant = MujocoBipedPlant(
        options,
        robot=model,
        video_path=out / "walk.mp4" if video else None,
        replay=replay,
    )
    pushes = trial_pushes(plant, plan, disturbance)
    with console.status(f"walking {plan.n_steps} steps in MuJoCo ..."):
        res = run_trial(plant, sc, plan, disturbance).detail
    # what `footfall view` replays: joint positions at 30 Hz, the model, the scene, the CoP
    replay.write(out / REPLAY_FILE, biped_traces(res.trace, replay.times), scene_to_yaml(sc))
    # walk.json's "controller" (from the result) names the controller and holds its tally
    report = walk_report(sc.name, planner, robot, plan, disturbance, pushes, res)
    # the walker's options that change a walk, so that walk.json says how it was walked
    report["walker"] = {
        "region_aware": options.region_aware,
        "leg_momentum": options.leg_momentum,
        "walk_on": options.walk_on,
        "step_timing": options.step_timing,
        "capture_stop": options.capture_stop,
        "torque_weight_mass": options.torque_weight_mass,
    }
    write_json(out / "walk.json", report)
    plot_walk(res, sc, out / "walk.png", params=model, title=f"{sc.name}, {planner}, {robot}")
    m = res.metrics
    console.print(
        f"{sc.name} / {planner} / {robot}: {plan.n_steps} steps, fell={m.fell}, "
        f"reached goal={m.reached_goal}, footstep error mean "
        f"{m.footstep_error_m.mean:.3f} m, ZMP offset mean {m.zmp.mean:.3f} m "
        f"max {m.zmp.max:.3f} m"
    )
    if res.video_note:
        console.print(res.video_note)
    console.print(
        f"wrote {out / 'walk.json'}, walk.png, {REPLAY_FILE}" + (", walk.mp4" if res.video else "")
    )
    if m.fell or not m.reached_goal:
        raise typer.Exit(1)
