"""The robots footfall knows by name, and robot files by path.

``biped`` is footfall's own 30 kg biped (its MJCF generated from
:class:`~footfall.robots.biped.BipedModel`, its planner parameters the document's); every other
built-in is a robot file in ``footfall/robots/builtin/`` naming a model of ``example-robot-data``
(``pip install 'footfall[robots]'``), exactly like a user's robot file.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from footfall.errors import InputError
from footfall.robots.file import RobotFile, load_robot_file, parse_robot_file

#: footfall's own biped (generated model)
OWN_BIPED = "biped"
#: file endings of a robot file argument
ROBOT_FILE_SUFFIXES = (".yaml", ".yml")


def builtin_robot_names() -> list[str]:
    """``biped`` and the names of the robot files shipped in ``footfall/robots/builtin/``."""
    folder = resources.files("footfall.robots").joinpath("builtin")
    files = sorted(p.name[: -len(".yaml")] for p in folder.iterdir() if p.name.endswith(".yaml"))
    return [OWN_BIPED, *files]


def builtin_robot_file(name: str) -> RobotFile:
    """The shipped robot file ``name`` (not ``biped``, which has none)."""
    names = builtin_robot_names()
    if name not in names or name == OWN_BIPED:
        raise InputError("robot", name, f"one of {', '.join(names)} or a robot file (.yaml)")
    text = resources.files("footfall.robots").joinpath("builtin", f"{name}.yaml").read_text()
    return parse_robot_file(text, f"{name}.yaml", None)


def resolve_robot_file(source: str | Path) -> RobotFile | None:
    """The robot file ``source`` names: a path to a robot file (YAML), else a built-in name;
    None for footfall's own biped."""
    if isinstance(source, Path) or str(source).endswith(ROBOT_FILE_SUFFIXES):
        path = Path(source)
        if not path.is_file():
            raise InputError("robot", str(source), "an existing robot file (.yaml)")
        from footfall.robots.quadruped import is_quadruped_file

        if is_quadruped_file(path):
            raise InputError(
                "robot",
                str(source),
                "a humanoid's robot file (this one is a quadruped's, kind: quadruped: "
                "footfall quadruped --robot takes it)",
            )
        return load_robot_file(path)
    if not isinstance(source, str):
        raise InputError("robot", source, "a robot name or a robot file (.yaml)")
    if source == OWN_BIPED:
        return None
    return builtin_robot_file(source)
