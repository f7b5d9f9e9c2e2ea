"""Footstep plans cached as JSON next to a walk's outputs, so a slow MIQCQP plan is solved once.

The file is the ``plan.json`` format of ``footfall plan`` (:func:`plan_to_dict`) plus a ``cache_key``
naming the scene (with a digest of its contents, :func:`scene_fingerprint`), planner, step count,
robot parameters and the planner options beyond the document; :func:`load_plan` rebuilds the
:class:`FootstepPlan` for the given robot and refuses a file whose key differs.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import write_json
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.planning.plan_io import plan_to_dict
from footfall.solvers.base import SolveStatus
from footfall.terrain.scene import Scene, scene_to_yaml


def scene_fingerprint(scene: Scene) -> str:
    """``<name>#<digest>``: the scene's name and a digest of everything in it (regions, start, goal,
    robot), so an edited scene under the same name does not reuse a plan made for the old one."""
    digest = hashlib.sha256(scene_to_yaml(scene).encode()).hexdigest()[:16]
    return f"{scene.name}#{digest}"


def cache_key(
    scene: str,
    planner: str,
    n_steps: int | None,
    robot: BipedParams,
    margin: float = 0.0,
    both_frames: bool = False,
    swing_max: float | None = None,
    heading_segments: int = 16,
) -> str:
    """A string that changes whenever anything the plan depends on changes (``both_frames``,
    ``swing_max`` [m] and ``heading_segments`` are the planner options ``reach_both_frames``,
    ``swing_max`` and ``heading_segments``)."""
    r = robot
    swing = "none" if swing_max is None else f"{swing_max:.6g}"
    return (
        f"{scene}|{planner}|N={n_steps}|margin={margin:.6g}|m={r.mass:.6g}|zH={r.com_height:.6g}|tss={r.t_ss:.6g}|"
        f"tds={r.t_ds:.6g}|K={r.n_nodes}|umax={r.u_max:.6g}|w={r.stance_width:.6g}|"
        f"reach={np.round(r.reach.vertices, 6).tolist()}|both_frames={bool(both_frames)}|"
        f"swing={swing}|L={int(heading_segments)}"
    )


def save_plan(path: Path, plan: FootstepPlan, scene: str, key: str) -> Path:
    """Write ``plan`` as JSON with its cache key."""
    payload = plan_to_dict(plan, scene)
    payload["cache_key"] = key
    return write_json(path, payload)


def _nan(v: Any) -> float:
    return math.nan if v is None else float(v)


def load_plan(
    path: Path, robot: BipedParams, key: str, region_margin: float = 0.0
) -> FootstepPlan | None:
    """The cached plan at ``path`` if it exists and its key equals ``key``, else None.

    ``region_margin`` is the margin the plan was made with (part of ``key``; the walker keeps its
    footsteps at least that far inside their regions).
    """
    if not path.is_file():
        return None
    try:
        d = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    if d.get("cache_key") != key:
        return None
    steps = d["footsteps"]
    alip = d["alip"]
    n = len(steps) - 1
    k = robot.n_nodes
    states = np.asarray(alip["states"], dtype=float).reshape(n, k, 4)
    torques = np.asarray(alip["torques"], dtype=float).reshape(n, k - 1, 2)
    try:
        status = SolveStatus(d["status"])
    except ValueError:
        raise InputError("plan cache status", d["status"], "a SolveStatus value") from None
    return FootstepPlan(
        planner=d["planner"],
        status=status,
        robot=robot,
        footsteps=np.asarray([s["position"] for s in steps], dtype=float),
        headings=np.asarray([s["heading"] for s in steps], dtype=float),
        sides=tuple(Side(s["side"]) for s in steps),
        regions=tuple(s["region"] for s in steps),
        states=states,
        torques=torques,
        final_state=np.asarray([_nan(v) for v in alip["final_state"]], dtype=float),
        objective=_nan(d.get("objective")),
        bound=_nan(d.get("bound")),
        gap=_nan(d.get("gap")) if d.get("gap") is not None else math.inf,
        solve_time=float(d.get("solve_time_s", 0.0)),
        solver=d.get("solver", "none"),
        message=d.get("message", "") + " (loaded from cache)",
        region_margin=region_margin,
        reach_both_frames=bool(d.get("reach_both_frames", False)),
        swing_max=None if d.get("swing_max") is None else float(d["swing_max"]),
        heading_segments=None if d.get("heading_segments") is None else int(d["heading_segments"]),
    )
