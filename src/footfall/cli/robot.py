"""``footfall robot``: a humanoid or a quadruped from its URDF or MJCF, inspected and written as a
robot file."""

from __future__ import annotations

from pathlib import Path

import typer

from footfall._io import remove_outputs, write_text
from footfall.cli._common import app, console, output_folder, refuse_inputs_as_outputs

robot_app = typer.Typer(
    help="Robots from their URDF or MJCF: inspect a model, write its robot file.",
    no_args_is_help=True,
    rich_markup_mode=None,
)
app.add_typer(robot_app, name="robot")


@robot_app.command("inspect")
def inspect_command(
    model: Path = typer.Argument(
        ...,
        help="A humanoid's or a quadruped's URDF (or MJCF), or a robot file (.yaml).",
        metavar="MODEL",
    ),
    config: Path | None = typer.Option(
        None,
        help="A robot file whose given values (legs, sole, base, torso, pelvis height, ...) are "
        "kept; every value it leaves out is derived.",
    ),
    name: str | None = typer.Option(
        None, help="The robot's name [default: the model's file name]."
    ),
    out: Path = typer.Option(Path("out/robot"), help="Output folder: robot.yaml and robot.png."),
) -> None:
    """Find the legs (a humanoid: the chains from the floating base to the two lowest links; a
    quadruped: a three-joint leg in each quadrant) and the feet, and derive the mass, posture,
    joint and torque limits (a humanoid: soles, reach [m] and step height [m]; a quadruped: point
    feet, knee bend, stance height [m] and its gait); print them with their units and write the
    completed robot file OUT/robot.yaml (which `--robot OUT/robot.yaml` takes as it is: `walk`,
    `plan` for a humanoid, `quadruped` for a quadruped) and the figure OUT/robot.png."""
    from footfall.robots.inspect import inspect_robot, plot_inspection, robot_file_text
    from footfall.robots.inspect_quadruped import (
        inspect_quadruped,
        looks_quadruped,
        plot_quadruped,
        quadruped_file_text,
    )

    files = ("robot.yaml", "robot.png")
    refuse_inputs_as_outputs([model, config], {"out": [out / f for f in files]})
    output_folder(out)
    path = out / "robot.yaml"
    with console.status(f"inspecting {model} ..."):
        quad = inspect_quadruped(model, config, name) if looks_quadruped(model, config) else None
        ins = inspect_robot(model, config, name) if quad is None else None
    lines = quad.lines() if quad is not None else ins.lines() if ins is not None else []
    for line in lines:
        console.print(line)
    remove_outputs(out, *files)  # this run's files replace the last run's as a set
    if quad is not None:
        write_text(path, quadruped_file_text(quad.file, out))
        fig = plot_quadruped(quad, out / "robot.png")
    else:
        assert ins is not None
        write_text(path, robot_file_text(ins.robot, out))
        fig = plot_inspection(ins, out / "robot.png")
    console.print(f"wrote {path}, {fig}")
