"""One way from what a user typed to a :class:`Scene`: a built-in name or a YAML file."""

from __future__ import annotations

from pathlib import Path

from footfall.errors import InputError
from footfall.terrain.scene import Scene, builtin_scene, load_scene

#: file endings that mark a scene argument as a path even when the file does not exist (so the
#: error says the file is missing instead of "no built-in scene")
SCENE_SUFFIXES = (".yaml", ".yml")


def resolve_scene(source: str | Path | Scene) -> Scene:
    """The scene ``source`` names: a :class:`Scene` as is, a path to a YAML scene file (a
    :class:`Path`, an existing file or a name ending in ``.yaml``/``.yml``), else a built-in name.

    Raises:
        SceneError: the file is invalid, or no built-in scene has that name (the message lists them).
    """
    if isinstance(source, Scene):
        return source
    if isinstance(source, Path):
        return load_scene(source)
    if not isinstance(source, str):
        raise InputError("scene", source, "a built-in scene name or a YAML file path")
    if source.endswith(SCENE_SUFFIXES) or Path(source).is_file():
        return load_scene(Path(source))
    return builtin_scene(source)


def resolve_scene_arguments(scene_file: Path | None, scene: str | None) -> Scene:
    """The scene of a command that takes a ``SCENE.yaml`` argument or a ``--scene`` option: exactly
    one of the two must be given."""
    if (scene_file is None) == (scene is None):
        raise InputError(
            "scene", scene_file or scene, "either a SCENE.yaml argument or --scene NAME"
        )
    return resolve_scene(scene_file if scene_file is not None else str(scene))
