"""The declared design of a section 5.5 study: scenes x planners x step counts x push levels x seeds.

A study file is YAML (read with the safe loader, so it is data, never code) validated into the frozen
:class:`StudyDesign`; every bad value names its field. Two studies ship with footfall
(:func:`builtin_study`): ``section55`` (the final study, MuJoCo biped with the whole-body
controller) and ``quick`` (a tiny reduced-order study that checks a setup in about a minute).

Paired design: trial ``seed`` draws its :class:`~footfall.sim.disturbance.Disturbance` (which step
and when in its single support the push comes, its direction, the direction of the initial
perturbation) from the seed alone (:meth:`~footfall.sim.disturbance.Disturbance.of_seed`), so every
planner, step count and push level of that seed gets the same disturbance and only its impulse
varies between levels (common random numbers).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from footfall._io import read_bounded
from footfall._validate import non_negative, positive
from footfall._yaml import safe_load
from footfall.errors import InputError
from footfall.planning.plan import PLANNERS
from footfall.terrain.scene import builtin_scene_names

#: the simulators a study can walk its plans in
SIMULATORS = ("reduced", "mujoco")
#: how a horizon planner's footstep count N is chosen: its own smallest feasible N, or the N of the
#: reactive planner's walk on the same scene (equal N)
STEP_MODES = ("smallest", "equal")
#: controllers of the MuJoCo walker (``WalkOptions.controller``)
CONTROLLERS = ("wbc", "servo")
#: the studies that ship with footfall (``footfall study --builtin NAME``)
BUILTIN_STUDIES = ("section55", "section55_reduced", "section55_terrain", "quick")
#: largest study file accepted [bytes]
MAX_STUDY_BYTES = 100_000
#: most trials one study may declare (a typo like ``seeds: 2000000`` is refused, not queued)
MAX_TRIALS = 200_000


@dataclass(frozen=True)
class StudyDesign:
    """A study: which walks to run and how to disturb them.

    Attributes:
        name: label of the study (free text, shown in the report).
        simulator: ``reduced`` (the ALIP closed loop of :mod:`footfall.sim.reduced`) or ``mujoco``
            (the MuJoCo biped of :mod:`footfall.sim.biped`).
        controller: the MuJoCo walker's controller (``wbc`` or ``servo``); None with ``reduced``.
        scenes: built-in scene names or scene YAML files (a file's path relative to the study
            file's folder when the study was read from a file).
        planners: planner names (``miqcqp``, ``kinematic``, ``reactive``).
        steps: step-count modes of the horizon planners (``smallest``, ``equal``); the reactive
            planner walks to the goal in both.
        default_push: the push impulse of the main comparison [N s].
        seeds: trials per cell at ``default_push`` (seeds ``seed_start`` ... + seeds - 1).
        push_levels: impulses of the fragility curves [N s].
        level_seeds: trials per cell at each push level (the first seeds of the same range).
        level_steps: the step modes walked at the push levels other than the default (default:
            every mode of ``steps``); e.g. ``[smallest]`` draws the fragility curves at the
            smallest N only and compares equal N at the default push.
        push_duration: length of every push pulse [s].
        initial_impulse: impulse of the initial perturbation [N s] (0: none), a push at the
            start of the walk (reduced) or while the walker stands before its first step (mujoco).
        seed_start: first seed.
        time_limit: planner time limit per solve [s].
        noise_pos: reduced only: CoM position estimate noise [m].
        noise_vel: reduced only: CoM velocity estimate noise [m/s].
        placement_error: reduced only: landing error per axis [m].
        region_aware: how the walkers' MPC keeps the next footstep on the terrain
            (``WalkOptions.region_aware`` / ``SimOptions.region_aware``): ``off`` (document 000's
            free footstep, the default), ``planned`` (in the planned region inset by the sole) or
            ``nearby`` (or the best region within reach).
        robot: the walker (``mujoco``): ``biped`` (footfall's), a built-in robot file's name
            (``g1``, ``talos``) or a robot file (a ``.yaml`` path, relative to the study file).
        families: terrain families (:mod:`footfall.terrain.families`) whose terrains the study
            walks besides ``scenes`` (which may then be empty): terrain is a random factor.
        terrains: terrains per family (family seeds ``terrain_start`` ... + terrains - 1).
        terrain_start: first family seed.
    """

    name: str
    simulator: str = "mujoco"
    controller: str | None = "wbc"
    scenes: tuple[str, ...] = ("discrete_steps", "stairs_slope_gap")
    planners: tuple[str, ...] = ("miqcqp", "kinematic", "reactive")
    steps: tuple[str, ...] = ("smallest", "equal")
    default_push: float = 3.0
    seeds: int = 200
    push_levels: tuple[float, ...] = (0.0, 2.0, 4.0, 6.0, 8.0)
    level_seeds: int = 50
    level_steps: tuple[str, ...] | None = None
    push_duration: float = 0.1
    initial_impulse: float = 0.5
    seed_start: int = 0
    time_limit: float = 300.0
    noise_pos: float = 0.0
    noise_vel: float = 0.0
    placement_error: float = 0.0
    region_aware: str = "off"
    robot: str = "biped"
    families: tuple[str, ...] = ()
    terrains: int = 0
    terrain_start: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError("name", self.name, "a non-empty text")
        if self.simulator not in SIMULATORS:
            raise InputError("simulator", self.simulator, f"one of {', '.join(SIMULATORS)}")
        if self.simulator == "mujoco" and self.controller not in CONTROLLERS:
            raise InputError("controller", self.controller, f"one of {', '.join(CONTROLLERS)}")
        if self.simulator == "reduced" and self.controller is not None:
            raise InputError(
                "controller",
                self.controller,
                "no controller with simulator reduced (it is MuJoCo's)",
            )
        for name in ("noise_pos", "noise_vel", "placement_error"):
            v = non_negative(name, getattr(self, name))
            if self.simulator == "mujoco" and v != 0.0:
                raise InputError(name, v, "0 with simulator mujoco (a reduced-order option)")
            object.__setattr__(self, name, v)
        from footfall.terrain.families import MAX_SEED, family_names

        fam = self.families
        if isinstance(fam, str) or not isinstance(fam, list | tuple):
            raise InputError("families", fam, f"a list of: {', '.join(family_names())}")
        object.__setattr__(self, "families", _names("families", fam, family_names()) if fam else ())
        for name, lo in (("terrains", 1 if fam else 0), ("terrain_start", 0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < lo:
                raise InputError(name, v, f"an integer >= {lo}")
            object.__setattr__(self, name, int(v))
        if not fam and self.terrains:
            raise InputError("terrains", self.terrains, "0 without families (or name families)")
        if self.terrain_start + self.terrains - 1 > MAX_SEED:
            raise InputError("terrain_start", self.terrain_start, f"family seeds <= {MAX_SEED}")
        object.__setattr__(self, "scenes", _scenes(self.scenes, allow_empty=bool(fam)))
        object.__setattr__(self, "planners", _names("planners", self.planners, PLANNERS))
        object.__setattr__(self, "steps", _names("steps", self.steps, STEP_MODES))
        if self.level_steps is None:
            object.__setattr__(self, "level_steps", self.steps)
        else:
            object.__setattr__(
                self, "level_steps", _names("level_steps", self.level_steps, self.steps)
            )
        object.__setattr__(self, "default_push", non_negative("default_push", self.default_push))
        levels = self.push_levels
        if isinstance(levels, str) or not isinstance(levels, list | tuple):
            raise InputError("push_levels", levels, "a list of impulses [N s] (may be empty)")
        lv = tuple(non_negative(f"push_levels[{i}]", x) for i, x in enumerate(levels))
        if len(set(lv)) != len(lv):
            raise InputError("push_levels", list(levels), "distinct impulses")
        object.__setattr__(self, "push_levels", lv)
        for name, lo in (("seeds", 1), ("level_seeds", 0 if not lv else 1), ("seed_start", 0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < lo:
                raise InputError(name, v, f"an integer >= {lo}")
            object.__setattr__(self, name, int(v))
        object.__setattr__(self, "push_duration", positive("push_duration", self.push_duration))
        object.__setattr__(
            self, "initial_impulse", non_negative("initial_impulse", self.initial_impulse)
        )
        object.__setattr__(self, "time_limit", positive("time_limit", self.time_limit))
        from footfall.control.adjusters import check_region_mode

        check_region_mode(self.region_aware)
        from footfall.robots.registry import ROBOT_FILE_SUFFIXES, builtin_robot_names

        names = builtin_robot_names()
        if not isinstance(self.robot, str) or not (
            self.robot in names
            or (self.robot.endswith(ROBOT_FILE_SUFFIXES) and Path(self.robot).is_file())
        ):
            raise InputError(
                "robot", self.robot, f"one of {', '.join(names)} or a robot file (.yaml)"
            )
        if self.robot != "biped" and self.simulator != "mujoco":
            raise InputError("robot", self.robot, "biped with simulator reduced (its plans' robot)")
        n = self.max_trials()
        if n > MAX_TRIALS:
            raise InputError("seeds", self.seeds, f"a study of at most {MAX_TRIALS} walks ({n})")

    def impulses(self) -> tuple[float, ...]:
        """Every push impulse of the study [N s]: the default first, then the other levels."""
        return (self.default_push, *(x for x in self.push_levels if x != self.default_push))

    def seeds_at(self, impulse: float, mode: str = "smallest") -> range:
        """The seeds walked at ``impulse`` in step mode ``mode``: ``seeds`` at the default push
        (or ``level_seeds`` if more), ``level_seeds`` at the other levels (none when ``mode`` is
        not in ``level_steps``). The reactive planner's walks (mode ``goal``) are in every mode."""
        n = 0
        if impulse == self.default_push:
            n = self.seeds
        levels = self.level_steps or self.steps
        if impulse in self.push_levels and (mode == "goal" or mode in levels):
            n = max(n, self.level_seeds)
        return range(self.seed_start, self.seed_start + n)

    def max_trials(self) -> int:
        """Walks the study runs at most (before identical walks are merged)."""
        horizon = sum(p != "reactive" for p in self.planners)
        per_scene = sum(
            horizon * len(self.seeds_at(i, m)) for i in self.impulses() for m in self.steps
        )
        if "reactive" in self.planners:
            per_scene += sum(len(self.seeds_at(i, "goal")) for i in self.impulses())
        return (len(self.scenes) + len(self.families) * self.terrains) * per_scene

    def terrain_seeds(self) -> range:
        """The family seeds of the study's terrains (the same in every family)."""
        return range(self.terrain_start, self.terrain_start + self.terrains)

    def fingerprint(self) -> dict[str, Any]:
        """The fields that change what a trial computes (a folder's trials are reused only by a
        study with the same fingerprint; scenes, planners, steps, pushes and seeds may grow)."""
        keys = (
            "simulator",
            "controller",
            "push_duration",
            "initial_impulse",
            "time_limit",
            "noise_pos",
            "noise_vel",
            "placement_error",
        )
        out = {k: getattr(self, k) for k in keys}
        if self.region_aware != "off":  # absent when off: folders from before the field stay valid
            out["region_aware"] = self.region_aware
        if self.robot != "biped":  # likewise
            out["robot"] = self.robot
        return out

    def to_dict(self) -> dict[str, Any]:
        """Plain data (the YAML schema)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = list(v) if isinstance(v, tuple) else v
        return out


def _scenes(value: object, allow_empty: bool = False) -> tuple[str, ...]:
    """Scene entries: built-in names or paths of existing files, each once (none only with
    ``allow_empty``: a study of terrain families)."""
    builtin = builtin_scene_names()
    if (
        isinstance(value, str)
        or not isinstance(value, list | tuple)
        or (not value and not allow_empty)
    ):
        raise InputError(
            "scenes", value, f"a non-empty list of: {', '.join(builtin)} or files (or families)"
        )
    out: list[str] = []
    for i, v in enumerate(value):
        if not isinstance(v, str) or not (v in builtin or Path(v).is_file()):
            raise InputError(
                f"scenes[{i}]", v, f"a built-in scene ({', '.join(builtin)}) or a scene file"
            )
        if v in out:
            raise InputError(f"scenes[{i}]", v, "each scene once")
        out.append(v)
    return tuple(out)


def _names(field: str, value: object, valid: tuple[str, ...] | list[str]) -> tuple[str, ...]:
    if isinstance(value, str) or not isinstance(value, list | tuple) or not value:
        raise InputError(field, value, f"a non-empty list of: {', '.join(valid)}")
    out = []
    for i, v in enumerate(value):
        if not isinstance(v, str) or v not in valid:
            raise InputError(f"{field}[{i}]", v, f"one of {', '.join(valid)}")
        if v in out:
            raise InputError(f"{field}[{i}]", v, "each name once")
        out.append(v)
    return tuple(out)


_FIELDS = {f.name for f in fields(StudyDesign)}


def study_from_dict(data: object, source: str = "study", base: Path | None = None) -> StudyDesign:
    """Validate plain data (a parsed study file) into a :class:`StudyDesign`; ``base``: the
    folder that relative scene file paths are relative to (the study file's)."""
    if not isinstance(data, dict):
        raise InputError(source, type(data).__name__, "a mapping of study fields")
    unknown = sorted((k for k in data if k not in _FIELDS), key=str)
    if unknown:
        raise InputError(
            f"{source}: {unknown[0]}",
            data[unknown[0]],
            f"one of the fields {', '.join(sorted(_FIELDS))}",
        )
    if "name" not in data:
        raise InputError(f"{source}: name", None, "a name for the study")
    if data.get("simulator", "mujoco") == "reduced" and "controller" not in data:
        data = {**data, "controller": None}
    scenes = data.get("scenes")
    if base is not None and isinstance(scenes, list):
        builtin = builtin_scene_names()
        data = {
            **data,
            "scenes": [
                str(base / v) if isinstance(v, str) and v not in builtin else v for v in scenes
            ],
        }
    robot = data.get("robot")
    if base is not None and isinstance(robot, str) and robot.endswith((".yaml", ".yml")):
        data = {**data, "robot": str(base / robot)}
    return StudyDesign(**{str(k): v for k, v in data.items()})


def load_study(path: Path) -> StudyDesign:
    """Read and validate a study YAML file (a regular file of at most ``MAX_STUDY_BYTES``)."""
    path = Path(path)
    text = read_bounded(path, "study file", MAX_STUDY_BYTES, "YAML file")
    return parse_study(text, str(path), base=path.parent)


def parse_study(text: str | bytes, source: str = "study", base: Path | None = None) -> StudyDesign:
    """Validate study YAML text (safe loader: tags that build Python objects are refused);
    ``base``: the folder of relative scene file paths."""
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError(source, "undecodable bytes", "UTF-8 YAML text") from None
    try:
        data = safe_load(text)  # footfall's loader: a repeated key is an error
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark else ""
        raise InputError(
            f"{source}{where}", None, f"valid YAML ({getattr(e, 'problem', e)})"
        ) from None
    return study_from_dict(data, source, base)


def builtin_study(name: str) -> StudyDesign:
    """One of the studies that ship with footfall (``BUILTIN_STUDIES``)."""
    if name not in BUILTIN_STUDIES:
        raise InputError("study", name, f"one of {', '.join(BUILTIN_STUDIES)}")
    text = resources.files("footfall.experiments.study").joinpath(f"{name}.yaml").read_text()
    return parse_study(text, f"{name}.yaml")
