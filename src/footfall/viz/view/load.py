"""Read whatever footfall wrote into plain frozen dataclasses of arrays, one loader per kind.

:func:`load_view` looks at a path and calls the loader of its kind: a scene file (``.yaml``), a
``plan.json`` (``footfall plan``), a walk (``walk.json`` + ``plan.json`` + ``replay.npz`` of
``footfall walk``), a quadruped walk (``quadruped.json`` + ``replay.npz``) or a study folder
(``trials.parquet`` + the ``plans/`` cache of ``footfall study``). Every file is read as data
through footfall's validating loaders (JSON, YAML, ``npz`` without pickle); what a folder lacks
(a walk written before replays were recorded, a scene that is not built in) becomes a note, and
the page shows what there is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.errors import FootfallError, InputError
from footfall.models.biped import Side
from footfall.planning import load_plan
from footfall.planning.plan import FootstepPlan
from footfall.planning.plan_file import read_json_file
from footfall.terrain import builtin_scene, builtin_scene_names, load_scene
from footfall.terrain.scene import Scene
from footfall.viz.view.replay import REPLAY_FORMAT, Replay, RobotMotion, read_replay, robot_motion

__all__ = [
    "REPLAY_FORMAT",
    "PushMark",
    "QuadrupedTrack",
    "StudyTrial",
    "ViewData",
    "WalkTrack",
    "load_view",
]

#: the files footfall's commands write, by what they hold
SCENE_SUFFIXES = (".yaml", ".yml")
PLAN_FILE, WALK_FILE, QUADRUPED_FILE = "plan.json", "walk.json", "quadruped.json"
REPLAY_FILE, TRIALS_FILE, STUDY_FILE = "replay.npz", "trials.parquet", "study.json"
#: a walk.json / quadruped.json larger than this [bytes] is refused
MAX_REPORT_BYTES = 50_000_000


@dataclass(frozen=True)
class PushMark:
    """A push on the robot: it starts at ``start`` [s] for ``duration`` [s] with ``force`` (3,)
    [N]; ``at`` (3,) [m] is where the CoM was then (None: unknown)."""

    start: float
    duration: float
    force: FloatArray
    at: FloatArray | None = None


@dataclass(frozen=True)
class WalkTrack:
    """What a biped walk measured.

    Attributes:
        planned: the plan's footsteps 1..N, shape (N, 3) [m]; landed: where they landed (NaN:
            never), shape (N, 3).
        pushes: the pushes.
        motion: the robot's poses per frame (None: the folder has no replay).
        cop: measured centre of pressure on the stance sole per frame, shape (F, 3) [m] (NaN
            outside single support); zmp: the planned ZMP likewise.
        fell: whether the robot fell; summary: a line of walk.json's numbers.
    """

    planned: FloatArray
    landed: FloatArray
    pushes: tuple[PushMark, ...]
    motion: RobotMotion | None
    cop: FloatArray
    zmp: FloatArray
    fell: bool
    summary: str


@dataclass(frozen=True)
class QuadrupedTrack:
    """What a quadruped walk measured: the robot's poses, the feet (F, 4, 3) [m], the planned
    stance flags (F, 4), the measured CoP and planned ZMP (F, 3) [m] on the ground."""

    motion: RobotMotion | None
    feet: FloatArray
    contact: NDArray[np.bool_]
    cop: FloatArray
    zmp: FloatArray
    summary: str


@dataclass(frozen=True)
class StudyTrial:
    """One row of a study's table, with the plan it walked when the folder's cache has it, and
    what walking it again needs: its ``seed`` (None: the row has none) and push ``impulse``
    [N s]."""

    key: str
    scene: str
    planner: str
    n_steps: int
    push: PushMark | None
    outcome: str
    plan: FootstepPlan | None
    seed: int | None = None
    impulse: float = 0.0


@dataclass(frozen=True)
class ViewData:
    """Everything the page shows of one path.

    Attributes:
        kind: ``scene``, ``plan``, ``walk``, ``quadruped`` or ``study``.
        title: a line naming what is shown.
        scene: the terrain (None: unknown, e.g. a plan of a scene file that was not given).
        plan: the footstep plan.
        walk, quadruped: the measurements of a walk.
        trials: a study's trials; scenes: the study's scenes by name.
        notes: what could not be shown and why.
        folder: the study's folder (a study's trials are walked again from it).
    """

    kind: str
    title: str
    scene: Scene | None = None
    plan: FootstepPlan | None = None
    walk: WalkTrack | None = None
    quadruped: QuadrupedTrack | None = None
    trials: tuple[StudyTrial, ...] = ()
    scenes: tuple[Scene, ...] = ()
    notes: tuple[str, ...] = ()
    folder: Path | None = None


def load_view(path: Path, scene: str | Path | None = None) -> ViewData:
    """What ``path`` holds, for the page: a scene file, a plan, a walk, a quadruped walk or a
    study (a file of one, or the folder it is in). ``scene`` (a built-in name or a scene file)
    is the terrain of a plan or walk whose own files do not hold it.

    Raises:
        InputError: the path does not exist, or is none of the above, or a file is damaged.
    """
    path = Path(path)
    if not path.exists():
        raise InputError("path", str(path), "an existing file or folder that footfall wrote")
    given = _given_scene(scene)
    if path.is_file():
        if path.suffix in SCENE_SUFFIXES:
            sc = load_scene(path)
            return ViewData("scene", f"scene {sc.name}", scene=sc)
        by_name = {
            PLAN_FILE: _load_plan_folder,
            WALK_FILE: _load_walk_folder,
            QUADRUPED_FILE: _load_quadruped_folder,
            REPLAY_FILE: _load_replay_folder,
            TRIALS_FILE: _load_study,
            STUDY_FILE: _load_study,
        }
        if path.name in by_name:
            return by_name[path.name](path.parent, given)
        if path.suffix == ".json":
            return _load_plan_file(path, given)
        raise InputError(
            "path", str(path), "a scene .yaml, plan.json, walk.json, quadruped.json or replay.npz"
        )
    for marker, loader in (
        (WALK_FILE, _load_walk_folder),
        (QUADRUPED_FILE, _load_quadruped_folder),
        (TRIALS_FILE, _load_study),
        (STUDY_FILE, _load_study),
        (PLAN_FILE, _load_plan_folder),
    ):
        if (path / marker).is_file():
            return loader(path, given)
    scenes = sorted(p for s in SCENE_SUFFIXES for p in path.glob(f"*{s}"))
    if len(scenes) == 1:
        sc = load_scene(scenes[0])
        return ViewData("scene", f"scene {sc.name}", scene=sc)
    raise InputError(
        "path",
        str(path),
        "a folder footfall wrote (with walk.json, quadruped.json, trials.parquet, plan.json or "
        "one scene .yaml)",
    )


def _given_scene(scene: str | Path | None) -> Scene | None:
    if scene is None:
        return None
    from footfall.terrain.resolve import resolve_scene

    return resolve_scene(scene)


def _named_scene(name: str, notes: list[str]) -> Scene | None:
    """The built-in scene ``name``, or None with a note (a scene file's name is not a path)."""
    if name in builtin_scene_names():
        return builtin_scene(name)
    if name:
        notes.append(f"scene {name!r} is not built in: pass --scene FILE to see its terrain")
    return None


def _study_scene(folder: Path, name: str, notes: list[str]) -> Scene | None:
    """A study's scene: a generated terrain's scene file in ``folder/terrains`` (its name is a
    family terrain's, so never a path), else :func:`_named_scene`."""
    from footfall.terrain.families import family_of

    path = folder / "terrains" / f"{name}.yaml"
    if family_of(name) is not None and path.is_file():
        return load_scene(path)
    return _named_scene(name, notes)


def _load_plan_file(path: Path, given: Scene | None) -> ViewData:
    notes: list[str] = []
    data = read_json_file(path, "plan file")
    name = data.get("scene", "") if isinstance(data, dict) else ""
    sc = given if given is not None else _named_scene(str(name), notes)
    plan = load_plan(path, sc)
    if not plan.has_solution:
        notes.append(f"the plan has no footsteps ({plan.status.value}): {plan.message}")
    title = f"plan of {name or 'a scene'}: {plan.planner}, N = {plan.n_steps}"
    return ViewData("plan", title, scene=sc, plan=plan, notes=tuple(notes))


def _load_plan_folder(folder: Path, given: Scene | None) -> ViewData:
    return _load_plan_file(folder / PLAN_FILE, given)


def _report(path: Path, what: str) -> dict[str, Any]:
    data = read_json_file(path, what, MAX_REPORT_BYTES)
    if not isinstance(data, dict):
        raise InputError(what, str(path), "a JSON object")
    return data


def _rows(data: dict[str, Any], key: str, path: Path) -> FloatArray:
    """An (N, 3) array of a report (null entries become NaN)."""
    raw = data.get(key) or []
    try:
        arr = np.array([[math.nan if v is None else float(v) for v in row] for row in raw])
    except (TypeError, ValueError):
        raise InputError(f"{path}:{key}", "not numbers", "rows of three numbers [m]") from None
    if arr.size == 0:
        return np.zeros((0, 3))
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"{path}:{key}", arr.shape, "rows of three numbers [m]")
    return arr


def _replay(folder: Path, kind: str, notes: list[str]) -> Replay | None:
    path = folder / REPLAY_FILE
    if not path.is_file():
        notes.append(
            f"no {REPLAY_FILE}: walked before replays were recorded, the robot is not shown"
        )
        return None
    replay = read_replay(path)
    if replay.kind != kind:
        raise InputError(f"{path}:kind", replay.kind, kind)
    return replay


def _motion(replay: Replay | None, notes: list[str]) -> RobotMotion | None:
    if replay is None:
        return None
    try:
        return robot_motion(replay)
    except InputError as e:
        if e.field != "mujoco":
            raise
        notes.append(f"the robot is not shown: {e.expected}")
        return None


def _load_walk_folder(folder: Path, given: Scene | None) -> ViewData:
    notes: list[str] = []
    report = _report(folder / WALK_FILE, "walk file")
    replay = _replay(folder, "biped", notes)
    name = str(report.get("scene", ""))
    if given is not None:
        sc: Scene | None = given
    elif replay is not None and replay.scene_yaml:
        sc = load_scene(replay.scene_yaml)
    else:
        sc = _named_scene(name, notes)
    plan = load_plan(folder / PLAN_FILE, sc) if (folder / PLAN_FILE).is_file() else None
    if plan is None:
        notes.append(f"no {PLAN_FILE} beside {WALK_FILE}")
    steps = report.get("footsteps") or {}
    if not isinstance(steps, dict):
        raise InputError(f"{folder / WALK_FILE}:footsteps", type(steps).__name__, "an object")
    motion = _motion(replay, notes)
    cop, zmp = _sole_traces(replay, plan)
    pushes = tuple(_push_mark(p, folder / WALK_FILE, replay) for p in report.get("push") or [])
    metrics = report.get("metrics") or {}
    fell = bool(metrics.get("fell", False)) if isinstance(metrics, dict) else False
    walk = WalkTrack(
        planned=_rows(steps, "planned", folder / WALK_FILE),
        landed=_rows(steps, "landed", folder / WALK_FILE),
        pushes=pushes,
        motion=motion,
        cop=cop,
        zmp=zmp,
        fell=fell,
        summary=_walk_summary(report),
    )
    title = f"walk of {name}: {report.get('planner', '?')}, {report.get('robot', '?')}"
    return ViewData("walk", title, scene=sc, plan=plan, walk=walk, notes=tuple(notes))


def _walk_summary(report: dict[str, Any]) -> str:
    m = report.get("metrics") or {}
    if not isinstance(m, dict):
        return ""
    return f"fell: {m.get('fell')}, reached goal: {m.get('reached_goal')}"


def _push_mark(p: Any, path: Path, replay: Replay | None) -> PushMark:
    try:
        start, duration = float(p["start_s"]), float(p["duration_s"])
        force = np.array([float(v) for v in p["force_N"]])
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{path}:push", p, "start_s, duration_s and force_N [N]") from None
    at = None
    if replay is not None and "com" in replay.traces:
        k = int(np.clip(np.searchsorted(replay.t, start), 0, len(replay.t) - 1))
        at = np.asarray(replay.traces["com"][k], dtype=float)
    return PushMark(start, duration, force, at)


def sole_points(
    offset: FloatArray, phase: NDArray[np.int_], feet: FloatArray, plan: FootstepPlan
) -> FloatArray:
    """World points (F, 3) [m] of offsets (F, 2) [m] in the stance sole's frame: in single
    support ``phase[f] = i`` the stance foot is the plan's footstep ``i`` (its side and heading),
    standing at the measured sole centre ``feet[f, side]``; NaN outside single support."""
    out = np.full((offset.shape[0], 3), np.nan)
    n = len(plan.sides)
    for f, i in enumerate(phase):
        if i < 0 or i >= n or not np.all(np.isfinite(offset[f])):
            continue
        side = 0 if plan.sides[i] is Side.LEFT else 1
        c, s = math.cos(plan.headings[i]), math.sin(plan.headings[i])
        dx, dy = offset[f]
        out[f] = feet[f, side] + np.array([c * dx - s * dy, s * dx + c * dy, 0.0])
    return out


def _sole_traces(replay: Replay | None, plan: FootstepPlan | None) -> tuple[FloatArray, FloatArray]:
    n = 0 if replay is None else replay.t.shape[0]
    need = ("phase", "feet", "cop_offset", "zmp_offset")
    if replay is None or plan is None or any(k not in replay.traces for k in need):
        return np.full((n, 3), np.nan), np.full((n, 3), np.nan)
    tr = replay.traces
    phase = np.asarray(tr["phase"], dtype=int)
    feet = np.asarray(tr["feet"], dtype=float)
    if feet.shape != (n, 2, 3):
        raise InputError("replay trace/feet", feet.shape, f"({n}, 2, 3) sole centres [m]")
    cop = sole_points(np.asarray(tr["cop_offset"], dtype=float).reshape(n, 2), phase, feet, plan)
    zmp = sole_points(np.asarray(tr["zmp_offset"], dtype=float).reshape(n, 2), phase, feet, plan)
    return cop, zmp


def _load_quadruped_folder(folder: Path, given: Scene | None) -> ViewData:
    notes: list[str] = []
    report = _report(folder / QUADRUPED_FILE, "quadruped file")
    replay = _replay(folder, "quadruped", notes)
    motion = _motion(replay, notes)
    n = 0 if replay is None else replay.t.shape[0]
    tr = replay.traces if replay is not None else {}
    feet = np.asarray(tr.get("feet", np.full((n, 4, 3), np.nan)), dtype=float)
    contact = np.asarray(tr.get("contact", np.zeros((n, 4), dtype=bool)), dtype=bool)
    if feet.shape != (n, 4, 3) or contact.shape != (n, 4):
        raise InputError("replay traces", (feet.shape, contact.shape), f"({n}, 4, 3) and ({n}, 4)")
    # the CoP and ZMP are on the plane of the stance feet: drawn at their mean height
    z = np.array(
        [np.mean(feet[f, contact[f], 2]) if contact[f].any() else np.nan for f in range(n)]
    )
    cop, zmp = (
        np.column_stack([np.asarray(tr[k], dtype=float).reshape(n, 2), z])
        if k in tr
        else np.full((n, 3), np.nan)
        for k in ("cop", "zmp")
    )
    m = report.get("metrics", report)
    summary = ""
    if isinstance(m, dict):
        d = m.get("distance_up_slope_m")
        shown = f"{d:.2f}" if isinstance(d, int | float) else str(d)
        summary = f"distance up the slope {shown} m, fell {m.get('fell')}"
    track = QuadrupedTrack(motion, feet, contact, cop, zmp, summary)
    robot = report.get("robot")
    name = robot.get("name") if isinstance(robot, dict) else None
    title = (
        f"quadruped walk{' of ' + str(name) if name else ''}"
        f"{' on ' + str(report['scene']) if report.get('scene') else ''}"
    )
    return ViewData("quadruped", title, quadruped=track, notes=tuple(notes))


def _load_replay_folder(folder: Path, given: Scene | None) -> ViewData:
    if (folder / QUADRUPED_FILE).is_file():
        return _load_quadruped_folder(folder, given)
    if (folder / WALK_FILE).is_file():
        return _load_walk_folder(folder, given)
    raise InputError("path", str(folder / REPLAY_FILE), f"a replay beside its {WALK_FILE}")


def _load_study(folder: Path, given: Scene | None) -> ViewData:
    rows = _study_rows(folder)
    duration = _push_duration(folder)
    notes: list[str] = []
    plans = _cached_plans(folder / "plans")
    scenes: dict[str, Scene] = {}
    trials = []
    for row in rows:
        name = str(row.get("scene") or "")
        if name not in scenes:
            sc = given if given is not None else _study_scene(folder, name, notes)
            if sc is not None:
                scenes[name] = sc
        n = int(row.get("n_steps") or 0)
        push = None
        if row.get("push_time") is not None and row.get("push_impulse"):
            direction = float(row.get("push_direction") or 0.0)  # [rad] (Disturbance)
            f = float(row["push_impulse"]) / duration
            push = PushMark(
                float(row["push_time"]),
                duration,
                np.array([f * math.cos(direction), f * math.sin(direction), 0.0]),
            )
        outcome = (
            f"error: {row['error']}"
            if row.get("error")
            else f"success {row.get('success')}, fell {row.get('fell')}, "
            f"goal error {row.get('goal_error')}"
        )
        plan = plans.get((name, str(row.get("planner")), n))
        seed = row.get("seed")
        trials.append(
            StudyTrial(
                str(row.get("key")),
                name,
                str(row.get("planner")),
                n,
                push,
                outcome,
                plan,
                int(seed) if isinstance(seed, int) else None,
                float(row.get("push_impulse") or 0.0),
            )
        )
    if not trials:
        notes.append("the study has no finished trials yet")
    missing = sum(t.plan is None for t in trials)
    if missing:
        notes.append(f"{missing} trials have no plan in {folder / 'plans'}")
    return ViewData(
        "study",
        f"study {folder.name}: {len(trials)} trials",
        trials=tuple(trials),
        scenes=tuple(scenes.values()),
        notes=tuple(dict.fromkeys(notes)),
        folder=folder,
    )


def _push_duration(folder: Path) -> float:
    """The study's push pulse [s] from its ``study.json`` (the design's fingerprint); the
    designs' default, 0.1 s, when the file does not say."""
    path = folder / STUDY_FILE
    data = _report(path, "study file") if path.is_file() else {}
    fp = data.get("fingerprint")
    value = fp.get("push_duration") if isinstance(fp, dict) else None
    if isinstance(value, int | float) and math.isfinite(value) and value > 0:
        return float(value)
    return 0.1


def _study_rows(folder: Path) -> list[dict[str, Any]]:
    path = folder / TRIALS_FILE
    if not path.is_file():
        return []
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise InputError("pyarrow", "not installed", "pip install 'footfall[study]'") from None
    try:
        rows: list[dict[str, Any]] = pq.read_table(path).to_pylist()
    except Exception as e:  # pyarrow's errors have no common base outside pyarrow
        raise InputError("trials file", str(path), f"a readable Parquet table ({e})") from None
    return rows


def _cached_plans(cache: Path) -> dict[tuple[str, str, int], FootstepPlan]:
    """The plans of a study's cache by (scene, planner, N); a file that is not a plan is left
    out (the cache is footfall's own, written atomically)."""
    plans: dict[tuple[str, str, int], FootstepPlan] = {}
    for path in sorted(cache.glob("plan-*.json")) if cache.is_dir() else []:
        try:
            data = read_json_file(path, "cached plan", 20_000_000)
            name = str(data.get("scene", "")) if isinstance(data, dict) else ""
            plan = load_plan(path)
        except FootfallError:
            continue
        if plan.has_solution:
            plans.setdefault((name, plan.planner, plan.n_steps), plan)
    return plans
