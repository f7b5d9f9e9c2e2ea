"""``footfall bench``: timings as ratios against a baseline measured in the same run."""

from __future__ import annotations

from pathlib import Path

import typer

from footfall._io import remove_outputs, write_json, write_text
from footfall.cli._common import (
    ROBOT_HELP,
    _threads,
    app,
    console,
    output_folder,
    parse_floats,
    refuse_inputs_as_outputs,
)
from footfall.errors import InputError

# --- bench ---
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
    horizon: int = typer.Option(
        0,
        help="Short-horizon mode: plan H footsteps per control tick from the measured ALIP "
        "state (footfall.planning.HorizonPlanner) along each scene's walk and report the "
        "latency distribution; 0: the full-horizon table.",
    ),
    ticks: int = typer.Option(20, help="Short-horizon mode: solves per single support."),
    push: float = typer.Option(
        0.3,
        help="Short-horizon mode: largest velocity change [m/s] given to the CoM at the start "
        "of each step (random direction, seeded by --seeds).",
    ),
    suite: Path | None = typer.Option(
        None,
        help="Instance-suite mode: solve every instance of the suite folder (its suite.json, "
        "e.g. benchmarks/suite) with --solver and compare with its certified optimum.",
    ),
    solver: str = typer.Option("bnb", help="Instance-suite mode: the backend (bnb, scip, gurobi)."),
    instances: str = typer.Option(
        "", help="Instance-suite mode: instance names to solve, comma separated (default all)."
    ),
    out: Path = typer.Option(
        Path("out/bench"),
        help="Output folder for bench_plan.json/.md (bench_horizon.json/.md, bench_suite.json/.md).",
    ),
) -> None:
    """Direct SCIP model vs the fast planner on the same instances: a table of times and gaps.

    With --horizon H: the short-horizon MIQP's latency per tick (warm-started, cold, and SCIP on
    the same problem at the first tick of every step) along each scene's walk. With --suite DIR:
    every instance of the suite solved by --solver at the suite's own gap, each result compared
    with its certificate (exit 1 when one disagrees)."""
    from footfall.experiments.bench import bench_plan, format_table, rows_to_dict

    if suite is not None and horizon:
        raise InputError("suite", str(suite), "either --suite or --horizon, not both")
    if suite is not None:
        _bench_suite(suite, solver, instances, time_limit_fast, fast_threads, out)
        return
    if horizon:
        _bench_horizon(horizon, ticks, push, scenes, seeds, gap, fast_only, time_limit_direct, out)
        return

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

    output_folder(out)
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
    remove_outputs(out, "bench_plan.json", "bench_plan.md")  # no file of another run beside ours
    write_json(out / "bench_plan.json", {"runs": rows_to_dict(rows)})
    write_text(out / "bench_plan.md", table + "\n")
    print(table)


def _bench_suite(
    folder: Path, solver: str, instances: str, time_limit: float, threads: int, out: Path
) -> None:
    from footfall.experiments.suite import (
        format_suite_table,
        load_suite,
        run_suite,
        suite_runs_to_dict,
    )
    from footfall.solvers import KNOWN_BACKENDS

    if solver not in KNOWN_BACKENDS:
        raise InputError("solver", solver, f"one of {', '.join(KNOWN_BACKENDS)}")
    if not time_limit > 0.0:
        raise InputError("time_limit_fast", time_limit, "a time > 0 [s]")
    refuse_inputs_as_outputs(
        [folder / "suite.json"], {"out": [out / "bench_suite.json", out / "bench_suite.md"]}
    )
    gap, known = load_suite(folder)  # a bad suite is refused before anything is written
    names = [n.strip() for n in instances.split(",") if n.strip()]
    known_names = {i.name for i in known}
    for n in names:
        if n not in known_names:
            raise InputError("instances", n, "names of the suite's instances")
    output_folder(out)
    runs = run_suite(
        folder,
        solver=solver,
        time_limit=time_limit,
        threads=_threads(threads),
        names=names,
        progress=lambda r: console.print(
            f"{r.name} {r.solver}: {r.status} {r.time:.2f} s "
            f"({'agrees' if r.agrees else 'DISAGREES'} with the certificate)"
        ),
    )
    table = format_suite_table(runs)
    remove_outputs(out, "bench_suite.json", "bench_suite.md")
    write_json(
        out / "bench_suite.json",
        {"suite": str(folder), "gap": gap, "runs": suite_runs_to_dict(runs)},
    )
    write_text(out / "bench_suite.md", table + "\n")
    print(table)
    if not all(r.agrees for r in runs):
        raise typer.Exit(1)


def _bench_horizon(
    horizon: int,
    ticks: int,
    push: float,
    scenes: str,
    seeds: str,
    gap: float,
    fast_only: bool,
    scip_limit: float,
    out: Path,
) -> None:
    from footfall.experiments.bench_horizon import (
        DEFAULT_SCENES,
        bench_horizon,
        bench_to_dict,
        check_bench_args,
        format_horizon_table,
    )

    if not 1 <= horizon <= 10:
        raise InputError("horizon", horizon, "a number of footsteps in 1..10 (0: off)")
    seed_vals = parse_floats("seeds", seeds)
    if not seed_vals or any(v != int(v) or v < 0 for v in seed_vals):
        raise InputError("seeds", seeds, "comma-separated integers >= 0, e.g. 0,1,2")
    if not scip_limit > 0.0:
        raise InputError("time_limit_direct", scip_limit, "a time > 0 [s]")
    names = [s.strip() for s in scenes.split(",") if s.strip()] or list(DEFAULT_SCENES)
    check_bench_args(names, horizon, ticks, push, gap)
    output_folder(out)
    bench = bench_horizon(
        scenes=names,
        seeds=[int(v) for v in seed_vals],
        horizon=horizon,
        ticks=ticks,
        push=push,
        gap=gap,
        scip=not fast_only,
        scip_time_limit=scip_limit,
    )
    table = format_horizon_table(bench)
    remove_outputs(out, "bench_horizon.json", "bench_horizon.md")
    write_json(out / "bench_horizon.json", bench_to_dict(bench))
    write_text(out / "bench_horizon.md", table + "\n")
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
    """Reduced-order closed loop: x real time of the python and compiled engines.

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
    from footfall.terrain.resolve import resolve_scene

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
    refuse_inputs_as_outputs([scene], {"out": [out / "bench_sim.json", out / "bench_sim.md"]})
    output_folder(out)
    plan = make_plan(sc, planner, None, PlannerOptions(threads=_threads(None)))
    if not plan.has_solution:
        from footfall.errors import InfeasibleError

        raise InfeasibleError(f"{planner} found no plan for {sc.name}: {plan.message}")
    rows = bench_sim(plan, k_list, runs=runs, options=bench_sim_options(rate))
    table = format_sim_table(rows)
    remove_outputs(out, "bench_sim.json", "bench_sim.md")  # no file of another run beside ours
    write_json(
        out / "bench_sim.json",
        {"scene": sc.name, "planner": planner, "rows": sim_speed_to_dict(rows)},
    )
    write_text(out / "bench_sim.md", table + "\n")
    print(table)


@bench_app.command("quadruped")
def bench_quadruped_cmd(
    slope_deg: float = typer.Option(15.0, help="Slope angle [deg]."),
    body_deg: float | None = typer.Option(
        None, help="Body angle [deg]; default: two thirds of the slope (10 on 15)."
    ),
    out: Path = typer.Option(Path("out/bench"), help="Output folder for bench_quadruped.json."),
) -> None:
    """Quadruped slope walk: simulated s per wall s vs bare mj_step, and gait-plan time."""
    from footfall.cli.simulation import default_body_deg
    from footfall.experiments.bench import benchmark_quadruped

    output_folder(out)
    body = default_body_deg(slope_deg) if body_deg is None else body_deg
    result = benchmark_quadruped(slope_deg=slope_deg, body_deg=body)
    write_json(out / "bench_quadruped.json", result)
    for key, value in result.items():
        console.print(f"{key}: {value}")


_DV_HELP = (
    "Velocity changes [m/s], comma separated, each > 0: the push as a velocity change; the impulse "
    "is the robot's mass x dv [N s]."
)


@bench_app.command("pushes")
def bench_pushes_cmd(
    protocol: bool = typer.Option(
        False,
        "--protocol",
        help="The field's push-recovery protocol (required: the command's only mode).",
    ),
    robot: str = typer.Option("biped", help=ROBOT_HELP),
    scene: str = typer.Option("flat_long", "--scene", help="Built-in scene name or YAML file."),
    steps: int | None = typer.Option(
        None, help="Footsteps N of the plan; omitted: the planner's smallest N."
    ),
    planner: str = typer.Option("miqcqp", help="miqcqp, kinematic or reactive."),
    controller: str = typer.Option("wbc", help="The walker's controller: wbc or servo."),
    region_aware: str = typer.Option(
        "horizon",  # WalkOptions.region_aware's default (a test keeps them equal)
        "--region-aware",
        help="How the walker's MPC keeps the next footstep on the terrain: off, planned, nearby "
        "or horizon (the region the 3-footstep MIQP chooses from the measured state; the "
        "walker's default).",
    ),
    leg_momentum: float | None = typer.Option(
        None,
        "--leg-momentum",
        help="Share in [0, 1] of the legs' forecast sagittal momentum [kg m^2/s] that the "
        "walker's MPC carries (0: off; default 0.5 with wbc, 0 with servo; see footfall walk "
        "--leg-momentum).",
    ),
    walk_on: int | None = typer.Option(
        None,
        "--walk-on",
        help="Stopping steps the walker may add, two at a time, to reach the goal after a push "
        "(0: never; default: the walker's, 4; see footfall walk --walk-on).",
    ),
    step_timing: bool | None = typer.Option(
        None,
        "--step-timing/--no-step-timing",
        help="Whether the walker's MPC may end a single support sooner when that saves cost "
        "(default: the walker's, on; see footfall walk --step-timing).",
    ),
    dv: str = typer.Option("0.1,0.2,0.3", "--dv", help=_DV_HELP),
    phases: str = typer.Option(
        "0.2,0.45,0.7",
        help="When the push starts, as shares of the pushed single support in [0, 1], comma "
        "separated.",
    ),
    directions: str = typer.Option(
        "forward,backward,inward,outward",
        help="Push directions relative to the stance foot at the push, comma separated: forward "
        "(along its heading), backward, inward (toward the stance foot's side), outward (toward "
        "the swing foot's side).",
    ),
    step: int | None = typer.Option(
        None, help="The pushed single support (0-based). [default: the middle one, N // 2]"
    ),
    duration: float = typer.Option(0.05, help="Push length [s]."),
    time_limit: float = typer.Option(300.0, help="Planner time limit per solve [s]."),
    workers: int = typer.Option(1, help="Walks at once (worker processes)."),
    out: Path = typer.Option(
        Path("out/bench"), help="Output folder for protocol.csv/.md/.png (plans cached in plans/)."
    ),
) -> None:
    """Push recovery as the field measures it: one push of --duration (0.05 s) in the middle
    single support of a walk, at each phase and in each direction, per velocity change. A level
    passes when every case reaches the goal without a fall; the summary names the largest.

    Writes protocol.csv (one row per walk), protocol.md (direction x phase per level) and
    protocol.png; exit 0 when every walk ran (a fall is a result, not an error).
    """
    from footfall.experiments.protocol import (
        PushProtocol,
        format_markdown,
        format_summary,
        plot_protocol,
        rows_csv,
        run_protocol,
    )

    if not protocol:
        raise InputError(
            "protocol",
            "not given",
            "--protocol (the only mode of bench pushes; seeded push sweeps: footfall study)",
        )
    dv_values = parse_floats("dv", dv)
    if not dv_values or any(not v > 0 or v != v for v in dv_values):
        raise InputError("dv", dv, "comma-separated velocity changes > 0 [m/s], e.g. 0.1,0.2")
    phase_values = parse_floats("phases", phases)
    if not phase_values or any(not 0.0 <= v <= 1.0 for v in phase_values):
        raise InputError("phases", phases, "comma-separated shares in [0, 1], e.g. 0.2,0.45,0.7")
    if workers < 1:
        raise InputError("workers", workers, "an integer >= 1")
    files = ("protocol.csv", "protocol.md", "protocol.png")
    refuse_inputs_as_outputs([scene, robot], {"out": [out / f for f in files]})
    proto = PushProtocol(
        dv=tuple(dv_values),
        phases=tuple(phase_values),
        directions=tuple(d.strip() for d in directions.split(",") if d.strip()),
        duration=duration,
        step=step,
        robot=robot,
        scene=scene,
        steps=steps,
        planner=planner,
        controller=controller,
        region_aware=region_aware,
        leg_momentum=leg_momentum,
        walk_on=walk_on,
        step_timing=step_timing,
    )
    from footfall.robots.registry import resolve_robot_file
    from footfall.terrain.resolve import resolve_scene

    resolve_robot_file(robot)  # an unknown robot or scene is refused before any output
    resolve_scene(scene)
    output_folder(out)
    remove_outputs(out, *files)  # no file of another run beside ours

    def progress(row: dict[str, object]) -> None:
        verdict = "pass" if row["success"] else ("fell" if row["fell"] else "missed the goal")
        console.print(f"dv {row['dv_m_s']:g} m/s {row['direction']}@{row['phase']:g}: {verdict}")

    result = run_protocol(proto, out / "plans", workers, time_limit, progress)
    write_text(out / "protocol.csv", rows_csv(result.rows))
    write_text(out / "protocol.md", format_markdown(result))
    plot_protocol(result, out / "protocol.png")
    print(format_summary(result))
    console.print(f"wrote {out / 'protocol.csv'}, protocol.md, protocol.png")


@bench_app.command("quadruped-pushes")
def bench_quadruped_pushes_cmd(
    robot: str = typer.Option(
        "go2", help="A quadruped: document, go2, solo12, anymal_c or a quadruped robot file."
    ),
    slope_deg: float = typer.Option(15.0, help="Slope angle [deg] (the body at two thirds)."),
    dv: str = typer.Option(
        "0.1,0.2,0.3,0.4",
        "--dv",
        help="Lateral velocity changes [m/s], comma separated; each push's impulse is the "
        "robot's mass times it [N s].",
    ),
    seeds: int = typer.Option(10, help="Seeds per level (0..seeds-1): push start and side."),
    duration: float = typer.Option(0.05, help="Push length [s]."),
    cycles: int = typer.Option(4, help="Gait cycles per walk."),
    out: Path = typer.Option(Path("out/bench"), help="Output folder: quadruped_pushes.csv/.md."),
) -> None:
    """Lateral pushes on a quadruped walking up a slope with the whole-body controller: one push
    per walk, sideways (left or right), at a seeded time in the middle half of the walk, the same
    seeds at every level (paired). Prints and writes each level's successes (no fall, trunk
    within 25 % of the planned distance of the plan's end) with a 95 % Wilson interval, and the
    largest level every seed survived; exit 0 when every walk ran (a fall is a result)."""
    from footfall.experiments.quadruped_pushes import (
        QuadrupedPushRow,
        check_push_inputs,
        push_walk_plan,
        rows_csv,
        run_quadruped_pushes,
        summary_lines,
    )

    dv_values = parse_floats("dv", dv)
    if not dv_values or any(not v >= 0 or v != v for v in dv_values):
        raise InputError("dv", dv, "comma-separated velocity changes >= 0 [m/s], e.g. 0.1,0.2")
    if seeds < 1:
        raise InputError("seeds", seeds, "an integer >= 1")
    files = ("quadruped_pushes.csv", "quadruped_pushes.md")
    refuse_inputs_as_outputs([robot], {"out": [out / f for f in files]})
    # every input checked (robot, slope, cycles: the walk planned) before any output is touched
    check_push_inputs(tuple(dv_values), tuple(range(seeds)), duration)
    plan = push_walk_plan(robot, slope_deg, cycles)
    output_folder(out)
    remove_outputs(out, *files)

    def progress(r: QuadrupedPushRow) -> None:
        verdict = "ok" if r.success else ("fell" if r.fell else "drifted")
        console.print(f"dv {r.dv_m_s:g} m/s seed {r.seed} {r.side}: {verdict}")

    rows = run_quadruped_pushes(
        robot, slope_deg, tuple(dv_values), tuple(range(seeds)), duration, cycles, progress, plan
    )
    lines = summary_lines(rows)
    write_text(out / "quadruped_pushes.csv", rows_csv(rows))
    write_text(out / "quadruped_pushes.md", "\n".join(lines) + "\n")
    print("\n".join(lines))
    console.print(f"wrote {out / 'quadruped_pushes.csv'}, quadruped_pushes.md")
