"""``footfall robot``: a humanoid from its URDF or MJCF, inspected and written as a robot file."""

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
        ..., help="A humanoid's URDF (or MJCF), or a robot file (.yaml).", metavar="MODEL"
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
    """Find the legs (the chains from the floating base to the two lowest links), the feet and
    their soles, and derive the mass, CoM height, nominal posture, joint and torque limits, reach
    [m] and step height [m]; print them with their units and write the completed robot file
    OUT/robot.yaml (which `--robot OUT/robot.yaml` takes as it is) and the figure OUT/robot.png."""
    from footfall.robots.inspect import inspect_robot, plot_inspection, robot_file_text

    files = ("robot.yaml", "robot.png")
    refuse_inputs_as_outputs([model, config], {"out": [out / f for f in files]})
    output_folder(out)
    with console.status(f"inspecting {model} ..."):
        ins = inspect_robot(model, config, name)
    for line in ins.lines():
        console.print(line)
    path = out / "robot.yaml"
    remove_outputs(out, *files)  # this run's files replace the last run's as a set
    write_text(path, robot_file_text(ins.robot, out))
    fig = plot_inspection(ins, out / "robot.png")
    console.print(f"wrote {path}, {fig}")
