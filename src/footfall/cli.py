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
    out: Path = typer.Option("out/quadruped", help="Output folder."),  # noqa: B008 - typer reads its options from the defaults
    video: bool = typer.Option(True, "--video/--no-video", help="Render an MP4 (offscreen GL)."),
) -> None:
    """Walk gait up a slope (document 001): plan with ZMP/OSP, simulate in MuJoCo, measure."""
    import math
    import os

    if video:
        # must be chosen before MuJoCo is imported; EGL works headless here
        os.environ.setdefault("MUJOCO_GL", "egl")
    from footfall.quadruped import GaitParams, QuadrupedRobot, ZmpStrategy, plan_gait
    from footfall.sim.quadruped_sim import simulate
    from footfall.viz import quadruped_plots as qp

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
    robot = QuadrupedRobot()

    def params(s: ZmpStrategy) -> GaitParams:
        return GaitParams(
            slope=math.radians(slope_deg),
            body_pitch=math.radians(body_deg),
            step=step,
            swing_height=height,
            swing_period=swing_period,
            shift_period=shift_period,
            cycles=cycles,
            strategy=s,
        )

    # every plan is built (and validated) before any simulation starts
    plans = {strat: plan_gait(robot, params(strat))}
    comparison_errors: dict[str, str] = {}
    if compare:
        for other in ZmpStrategy:
            if other is not strat:
                try:
                    plans[other] = plan_gait(robot, params(other))
                except InputError as exc:
                    comparison_errors[other.value] = str(exc)
    out.mkdir(parents=True, exist_ok=True)
    plan = plans[strat]
    console.print(f"simulating {cycles} cycles on {slope_deg:g} deg ({plan.duration:.1f} s)...")
    res = simulate(plan, video_path=out / "quadruped.mp4" if video else None)
    if video and res.video is None:
        console.print(f"[yellow]{res.video_note}[/]")
    payload: dict[str, Any] = dict(res.metrics)
    if compare:
        table = {}
        for s, p in plans.items():
            r = res if s is strat else simulate(p)
            table[s.value] = {
                "shifts_per_cycle": r.metrics["body_sway_planned"]["shifts_per_cycle"],
                "planned_path_per_cycle_m": r.metrics["body_sway_planned"]["path_per_cycle_m"],
                "measured_path_per_cycle_m": r.metrics["body_sway_measured"]["path_per_cycle_m"],
                "measured_lateral_path_per_cycle_m": r.metrics["body_sway_measured"][
                    "lateral_path_per_cycle_m"
                ],
                "measured_excess_path_per_cycle_m": r.metrics["body_sway_measured"][
                    "excess_path_per_cycle_m"
                ],
                "stability_margin_min_m": r.metrics["stability_margin_min_m"],
                "mean_speed_m_s": r.metrics["mean_speed_m_s"],
                "fell": r.metrics["fell"],
            }
        payload["strategy_comparison"] = table
        payload["strategy_comparison_infeasible"] = comparison_errors
    figs = [
        qp.plot_swing_frames(plan, out / "fig8_swing_frames.png"),
        qp.plot_foot_path(plan, res, out / "fig10_lf_foot_path.png"),
        qp.plot_body_height(
            [
                (
                    f"{slope_deg:g}°/{body_deg:g}°",
                    res.t,
                    res.trunk_pos[:, 2],
                    res.planned.body_pos[:, 2],
                )
            ],
            out / "fig11_body_z.png",
        ),
        qp.plot_stability(plan, res, out / "stability.png"),
    ]
    payload["figures"] = [str(f) for f in figs]
    write_json(out / "quadruped.json", payload)
    m = res.metrics
    console.print(
        f"distance {m['distance_up_slope_m']:.2f} m, speed {m['mean_speed_m_s']:.3f} m/s, "
        f"fell {m['fell']}, margin min {m['stability_margin_min_m']:.3f} m "
        f"mean {m['stability_margin_mean_m']:.3f} m, {m['realtime_factor']:.0f}x real time"
    )
    console.print(f"wrote {out / 'quadruped.json'}")
