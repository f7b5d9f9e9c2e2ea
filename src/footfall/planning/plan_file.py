"""Reading a saved plan (the ``plan.json`` of ``footfall plan``) back into a :class:`FootstepPlan`.

The file is data, never code: it is read as bounded UTF-8 JSON and every field is checked by the
validating :meth:`FootstepPlan.from_dict`. The robot is the one the plan was made for, rebuilt from
the file's ``robot`` object (which may be a MuJoCo walker's, not the scene's).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import regular_file
from footfall.errors import InputError
from footfall.models.biped import BipedParams, ReachTrapezoid
from footfall.planning.plan import FootstepPlan
from footfall.terrain.scene import Scene

#: a plan file larger than this [bytes] is refused (a plan of 200 steps of K = 50 is ~2 MB)
MAX_PLAN_BYTES = 20_000_000

#: the robot fields a plan file may hold (:func:`footfall.terrain.scene.robot_to_dict`)
_ROBOT_FIELDS = tuple(f.name for f in dataclasses.fields(BipedParams))


def read_json_file(path: Path, what: str, max_bytes: int = MAX_PLAN_BYTES) -> Any:
    """The JSON data of ``path``: a regular file (not a folder, device or pipe) of at most
    ``max_bytes`` bytes of UTF-8 JSON; anything else raises :class:`InputError` naming ``what``
    and the file."""
    regular_file(path, what, max_bytes)
    try:
        with path.open("rb") as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as e:
        raise InputError(what, str(path), f"a readable JSON file ({e.strerror})") from None
    try:
        return json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise InputError(what, str(path), f"UTF-8 text ({e.reason} at byte {e.start})") from None
    except json.JSONDecodeError as e:
        raise InputError(
            what, str(path), f"valid JSON ({e.msg} at line {e.lineno} column {e.colno})"
        ) from None
    except RecursionError:
        raise InputError(what, str(path), "JSON nested less deeply") from None


def robot_from_dict(data: object, base: BipedParams, source: str = "robot") -> BipedParams:
    """``base`` with the fields ``data`` (a plan file's ``robot`` object) holds.

    Unknown keys are refused; missing ones (files written before every field was saved) keep
    ``base``'s value. Raises :class:`InputError` naming ``source`` and the field.
    """
    if not isinstance(data, dict):
        raise InputError(source, data, "an object of robot parameters")
    unknown = sorted(str(k) for k in data if k not in _ROBOT_FIELDS)
    if unknown:
        raise InputError(f"{source}.{unknown[0]}", data[unknown[0]], "a known robot field")
    kw: dict[str, Any] = dict(data)
    try:
        if "reach" in kw:
            try:
                kw["reach"] = ReachTrapezoid(np.array(kw["reach"], dtype=float))
            except (TypeError, ValueError):
                raise InputError("reach", kw["reach"], "4 vertices [[x, y], ...] [m]") from None
        return dataclasses.replace(base, **kw)
    except InputError as e:
        raise InputError(f"{source}.{e.field}", e.value, e.expected) from None


def load_plan(path: str | Path, scene: Scene | BipedParams | None = None) -> FootstepPlan:
    """The plan saved in ``path`` by ``footfall plan`` (:meth:`FootstepPlan.to_dict`).

    Args:
        path: a ``plan.json`` file (at most :data:`MAX_PLAN_BYTES` bytes).
        scene: a scene or a robot whose parameters fill the robot fields the file does not hold
            (files written before every field was saved); None: :class:`BipedParams` defaults.
            The file's own ``robot`` always wins: a plan is checked for the robot it was made for.

    Raises:
        InputError: ``path`` is not a regular file, is too large, is not JSON, or does not hold
            a valid plan (the message names the file and the field).
    """
    if not isinstance(path, str | Path):
        raise InputError("path", path, "a plan.json file path")
    if scene is not None and not isinstance(scene, Scene | BipedParams):
        raise InputError("scene", scene, "a Scene, a BipedParams or None")
    p = Path(path)
    data = read_json_file(p, "plan file")
    if not isinstance(data, dict):
        raise InputError(str(p), type(data).__name__, "a JSON object (a plan.json)")
    if isinstance(scene, Scene):
        base = scene.robot
    else:
        base = scene if scene is not None else BipedParams()
    robot = robot_from_dict(data["robot"], base, f"{p}.robot") if "robot" in data else base
    return FootstepPlan.from_dict(data, robot, source=str(p))
