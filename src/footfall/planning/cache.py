"""Footstep plans cached on disk as JSON, keyed by the content of everything that determines them.

A MIQCQP plan can take minutes; walks, comparisons and studies ask for the same plan again. The
cache key is a SHA-256 digest of one canonical JSON document holding the scene (regions, start,
goal, its robot: :func:`footfall.terrain.scene_to_dict`), the planner and its revision
(:data:`PLANNER_REVISION`), the step count, the robot
the plan is made for and every planner option (weights, solver, its settings, time limit, gap,
threads, margins): change any of them, or edit a scene file under the same name, and the plan is
made again. The file name is the digest alone (``plan-<digest>.json``), so no name a user gave
reaches a path. A file is the ``plan.json`` of ``footfall plan`` (:meth:`FootstepPlan.to_dict`)
plus its key; it is read back by the validating :meth:`FootstepPlan.from_dict`, so a cache file
is data, never code.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import write_json
from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning.check import check_plan, unexpected_violations
from footfall.planning.plan import FootstepPlan, PlannerOptions
from footfall.planning.run import SearchMonitor, make_plan
from footfall.terrain.scene import Scene, robot_to_dict, scene_to_dict

#: version of the key's layout and of the file format; bumping it makes every old entry a miss
CACHE_VERSION = 2
#: revision of a planner's algorithm, bumped when it makes another plan from the same inputs
#: (reactive 2: it brakes before the goal). A planner not listed is at revision 1, which is left
#: out of the key so that its entries stay valid.
PLANNER_REVISION: dict[str, int] = {"reactive": 2}
#: ``bnb`` settings left out of the key: they change how the search proves its plan optimal (to
#: the same problem and gap), not which plan that is, and were added after plans were cached
#: (the section 5.5 study's plans ship in the repository)
KEY_NEUTRAL_BNB = ("escalate",)
#: a cache file larger than this [bytes] is refused (a plan of 100 steps is ~200 kB)
MAX_CACHE_FILE = 20_000_000


def _plain(value: Any) -> Any:
    """``value`` as plain JSON data with a canonical form (dataclasses, enums, arrays, floats)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, enum.Enum):
        return _plain(value.value)
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in sorted(value.items(), key=lambda kv: str(kv[0]))}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return _plain(value.item())
    if isinstance(value, float):
        # repr round-trips exactly; -0.0 and 0.0 are the same plan input
        return "nan" if math.isnan(value) else repr(value + 0.0)
    return value


def plan_key(
    scene: Scene,
    planner: str,
    n_steps: int | None,
    options: PlannerOptions,
    robot: BipedParams | None = None,
) -> str:
    """The cache key (64 hex digits) of the plan these arguments make (see the module docstring).

    ``options.verbose`` is left out (it changes the log, not the plan), and so are the search
    switches of ``KEY_NEUTRAL_BNB``.
    """
    opts = _plain(options)
    opts.pop("verbose", None)
    if options.heading_windows == PlannerOptions.heading_windows:
        # the default leaves the keys of plans cached before the option existed valid: the
        # search runs only where the solve found no plan, and such a result is never cached
        opts.pop("heading_windows", None)
    for name in KEY_NEUTRAL_BNB:
        opts["bnb"].pop(name, None)
    doc = {
        "version": CACHE_VERSION,
        "scene": _plain(scene_to_dict(scene)),
        "planner": planner,
        "n_steps": n_steps,
        "robot": _plain(robot_to_dict(robot if robot is not None else scene.robot)),
        "options": opts,
    }
    if PLANNER_REVISION.get(planner, 1) != 1:
        doc["revision"] = PLANNER_REVISION[planner]
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


@dataclasses.dataclass(frozen=True)
class PlanCache:
    """A folder of cached plans.

    Attributes:
        folder: where the ``plan-<digest>.json`` files live (created on the first save).
    """

    folder: Path

    def path(self, key: str) -> Path:
        """The file of ``key``."""
        if len(key) != 64 or any(c not in "0123456789abcdef" for c in key):
            raise InputError("cache key", key, "64 lowercase hex digits (plan_key)")
        return Path(self.folder) / f"plan-{key[:32]}.json"

    def load(self, key: str, robot: BipedParams) -> FootstepPlan | None:
        """The cached plan of ``key`` for ``robot``, or None when there is none.

        Raises:
            InputError: the file exists but is not a regular file, is too large, is not JSON, or
                does not hold a valid plan (it names the file and the field).
        """
        path = self.path(key)
        if not path.exists():
            return None
        if not path.is_file():
            raise InputError("plan cache file", str(path), "a regular file")
        if path.stat().st_size > MAX_CACHE_FILE:
            raise InputError(
                "plan cache file", str(path), f"at most {MAX_CACHE_FILE} bytes; delete it"
            )
        try:
            data = json.loads(path.read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise InputError(
                "plan cache file", str(path), f"a JSON plan ({exc}); delete it to plan again"
            ) from None
        if not isinstance(data, dict) or data.get("cache_key") != key:
            return None  # another plan whose digest shares the first 32 digits: a miss
        plan = FootstepPlan.from_dict(data, robot, source=str(path))
        return dataclasses.replace(plan, message=plan.message + " (loaded from cache)")

    def check_writable(self, key: str) -> None:
        """Refuse, before any planning, a cache whose file of ``key`` could not be written: the
        folder is a file, or the file's path is a folder (or another non-file)."""
        folder, path = Path(self.folder), self.path(key)
        if folder.exists() and not folder.is_dir():
            raise InputError(
                "plan cache folder", str(folder), "a folder (a file of that name exists)"
            )
        if path.exists() and not path.is_file():
            raise InputError("plan cache file", str(path), "a regular file or nothing (remove it)")

    def save(self, key: str, plan: FootstepPlan, scene_name: str = "") -> Path:
        """Write ``plan`` under ``key`` (atomically); returns the path."""
        payload = plan.to_dict(scene_name)
        payload["cache_key"] = key
        return write_json(self.path(key), payload)


def cached_plan(
    scene: Scene,
    planner: str = "miqcqp",
    n_steps: int | None = None,
    options: PlannerOptions | None = None,
    robot: BipedParams | None = None,
    cache: PlanCache | None = None,
    monitor: SearchMonitor | None = None,
) -> FootstepPlan:
    """:func:`footfall.planning.make_plan`, served from ``cache`` when it holds the plan
    (``monitor`` hears of a smallest-N search that runs, :func:`~footfall.planning.run.plan_min_steps`).

    Only plans with footsteps that pass their re-check are stored: a failed search is made
    again next time (it may have hit a time limit). A cached plan is re-checked in full before
    use (:func:`cache_mismatch`): one that an edited or damaged file broke (or that is no longer
    a valid plan file at all) is discarded, planned again (the file is overwritten) and the new
    plan's message says so.
    """
    options = options or PlannerOptions()
    robot = robot if robot is not None else scene.robot
    key = plan_key(scene, planner, n_steps, options, robot)
    discarded = ""
    if cache is not None:
        cache.check_writable(key)  # before the planning, whose plan would be lost
        try:
            hit = cache.load(key, robot)
        except InputError as exc:  # a damaged file is a miss: plan again and overwrite it
            hit, discarded = None, f" (cached plan {cache.path(key).name} discarded: {exc})"
        if hit is not None:
            problem = cache_mismatch(hit, scene, n_steps)
            if not problem:
                return hit
            discarded = f" (cached plan {cache.path(key).name} discarded: {problem}; planned again)"
    plan = make_plan(scene, planner, n_steps, options, robot, monitor=monitor)
    if cache is not None and plan.has_solution:
        # a plan its own re-check would refuse is not stored: it would be discarded every time
        problem = cache_mismatch(plan, scene, n_steps)
        if not problem:
            try:
                cache.save(key, plan, scene.name)
            except OSError as e:  # a full disk: the plan is still returned, uncached
                problem = f"{cache.path(key)}: {e.strerror}"
        if problem:
            discarded += f" (not cached: {problem})"
    if discarded:
        plan = dataclasses.replace(plan, message=plan.message + discarded)
    return plan


def cache_mismatch(plan: FootstepPlan, scene: Scene, n_steps: int | None) -> str:
    """Why a cached ``plan`` cannot be the one asked for on ``scene`` ("" when it can).

    It must have footsteps (only those are stored), ``n_steps`` of them when N was asked for,
    and pass every check of the independent checker (:func:`footfall.planning.check_plan`:
    start, regions, reach, step height, swing, heading rate, torque, the re-simulated ALIP
    dynamics, goal) but those its planner makes by design
    (:func:`~footfall.planning.check.unexpected_violations`): any other violation means the file
    was altered (or the plan was never valid).
    """
    if not plan.has_solution:
        return "no footsteps"
    if n_steps is not None and plan.n_steps != n_steps:
        return f"{plan.n_steps} footsteps where N = {n_steps} was asked for"
    bad = unexpected_violations(check_plan(plan, scene), plan)
    if not bad:
        return ""
    more = f" (and {len(bad) - 1} more violation(s))" if len(bad) > 1 else ""
    return bad[0].describe() + more
