"""What the page draws, as one JSON document: pure functions from a
:class:`~footfall.viz.view.load.ViewData` to the nodes of :mod:`footfall.viz.view.build`, packed
for the browser's viewer (``static/viewer.js``).

Arrays travel as base64 of little-endian ``float32`` (positions), ``float64`` (times) or
``uint32`` (triangle indices). The document (``data.json``):

- ``title``, ``notes``, ``summaries``: the panel's text; ``camera``: ``position``, ``target``
  (3,) [m] and vertical ``fov`` [rad], fitted to everything shown; ``start``: the time shown first
  [s].
- ``meshes``: ``name``, ``kind`` (``mesh``, ``points``), ``rgb`` (0..255), ``opacity``,
  ``positions`` (V*3) [m], ``indices`` (T*3) of a mesh, ``size`` [m] of a point,
  ``shown`` ([t0, t1] [s]: drawn only then; absent: always).
- ``labels``: ``name``, ``text``, ``position`` (3,) [m], ``shown``.
- ``robot`` (or null): ``bodies`` (B names), ``t`` (F) [s], ``pos`` (F*B*3) [m], ``wxyz``
  (F*B*4), ``meshes`` in their body's frame (``body``: its index), ``markers`` (a point per frame,
  ``positions`` (F*3), NaN where it is not shown, and its ``mesh``), ``support`` (or null: the
  quadruped's support polygon per frame as ``per`` line vertices a frame).
- ``trials``: a study's trial keys; ``outcome``: the first one's (shown); ``rewalk``: whether
  the server can walk a trial again. ``trial/<i>.json``
  holds trial ``i``'s ``meshes``, ``labels`` and ``outcome``; ``trial/<i>/walk.json`` the page
  document of that trial walked again (a MuJoCo study's: its robot's replay).
"""

from __future__ import annotations

import base64
import math
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.results.outcome import Outcome
from footfall.terrain.scene import Scene
from footfall.viz.view import build
from footfall.viz.view.load import PushMark, StudyTrial, ViewData, load_view
from footfall.viz.view.replay import Mesh, RobotMotion

#: a push arrow shows this long [s] before and after the push
PUSH_SHOWN = 0.4
#: half-widths [m] of the plan's heading ticks, its CoM path, a push's shaft
TICK_RADIUS, COM_RADIUS, PUSH_RADIUS = 0.004, 0.005, 0.012
#: CoP / ZMP: the trail's points and the marker's radius [m]
TRAIL_SIZE, MARKER_RADIUS = 0.008, 0.018
#: line vertices per frame of the quadruped's support polygon (four segments)
SUPPORT_PER = 8


def b64(a: Any, dtype: str) -> str:
    """``a`` as base64 of its little-endian ``dtype`` values, row-major."""
    return base64.b64encode(
        np.ascontiguousarray(a, dtype=np.dtype(dtype).newbyteorder("<")).tobytes()
    ).decode()


def _xyz(p: Any) -> list[float]:
    return [float(v) for v in np.asarray(p, dtype=float).reshape(3)]


def mesh_entry(m: Mesh, body: int = -1, shown: tuple[float, float] | None = None) -> dict[str, Any]:
    """A mesh node (in its body's frame when ``body`` >= 0, else in the world)."""
    entry: dict[str, Any] = {
        "name": m.name,
        "kind": "mesh",
        "rgb": list(m.rgb),
        "opacity": float(m.opacity),
        "positions": b64(m.vertices, "f4"),
        "indices": b64(m.faces, "u4"),
    }
    if body >= 0:
        entry["body"] = body
    if shown is not None:
        entry["shown"] = [float(shown[0]), float(shown[1])]
    return entry


@dataclass
class _Drawing:
    """The nodes of one drawing, and the points the camera frames (the terrain's apart)."""

    meshes: list[dict[str, Any]] = field(default_factory=list)
    labels: list[dict[str, Any]] = field(default_factory=list)
    terrain: list[FloatArray] = field(default_factory=list)
    activity: list[FloatArray] = field(default_factory=list)

    def mesh(
        self, m: Mesh, terrain: bool = False, shown: tuple[float, float] | None = None
    ) -> None:
        (self.terrain if terrain else self.activity).append(m.vertices)
        self.meshes.append(mesh_entry(m, shown=shown))

    def label(self, lb: build.Label, shown: tuple[float, float] | None = None) -> None:
        entry: dict[str, Any] = {"name": lb.name, "text": lb.text, "position": _xyz(lb.position)}
        if shown is not None:
            entry["shown"] = [float(shown[0]), float(shown[1])]
        self.labels.append(entry)

    def tube(
        self, ln: build.Lines, radius: float, shown: tuple[float, float] | None = None
    ) -> None:
        if ln.segments.shape[0]:
            self.mesh(build.tube(ln, radius), shown=shown)

    def trail(self, name: str, pts: FloatArray, rgb: tuple[int, int, int]) -> None:
        ok = pts[np.all(np.isfinite(pts), axis=1)] if pts.size else pts
        if ok.shape[0]:
            lifted = ok + np.array([0.0, 0.0, 2 * build.LIFT])
            self.meshes.append(
                {
                    "name": name,
                    "kind": "points",
                    "rgb": list(rgb),
                    "opacity": 1.0,
                    "size": TRAIL_SIZE,
                    "positions": b64(lifted, "f4"),
                }
            )

    def camera(self) -> dict[str, Any]:
        cam = build.fit_camera(build.framed_points(_stack(self.terrain), _stack(self.activity)))
        return {"position": _xyz(cam.position), "target": _xyz(cam.look_at), "fov": cam.fov}


def _stack(arrays: list[FloatArray]) -> FloatArray:
    """The rows of ``arrays`` (each (..., 3)) as one (P, 3) array."""
    return np.vstack([a.reshape(-1, 3) for a in arrays]) if arrays else np.zeros((0, 3))


def _static(d: _Drawing, data: ViewData) -> None:
    """Terrain, plan, landed footsteps, CoP / ZMP traces and pushes."""
    if data.scene is not None:
        for m in build.region_meshes(data.scene):
            d.mesh(m, terrain=True)
        for lb in build.start_goal(data.scene):
            d.label(lb)
    plan = data.plan
    if plan is not None and plan.has_solution:
        soles, labels, ticks = build.footstep_nodes(plan, data.scene)
        for m in soles:
            d.mesh(m)
        for lb in labels:
            d.label(lb)
        d.tube(ticks, TICK_RADIUS)
        if plan.states.size:
            d.tube(build.com_path(plan), COM_RADIUS)
    if data.walk is not None:
        w = data.walk
        landed = build.landed_soles(plan, w.landed) if plan is not None else None
        if landed is not None:
            d.mesh(landed)
        d.trail("/walk/cop_trail", w.cop, build.COP_RGB)
        d.trail("/walk/zmp_trail", w.zmp, build.ZMP_RGB)
        _pushes(d, w.pushes)
    if data.quadruped is not None:
        q = data.quadruped
        d.trail("/quadruped/cop_trail", q.cop, build.COP_RGB)
        d.trail("/quadruped/zmp_trail", q.zmp, build.ZMP_RGB)
        d.activity.append(q.feet.reshape(-1, 3))


def _pushes(d: _Drawing, pushes: tuple[PushMark, ...]) -> None:
    """Each push as an arrow (a shaft ending in a ball at the CoM) and a label, shown around the
    push's time only."""
    for k, p in enumerate(pushes):
        if p.at is None:
            continue
        shown = (p.start - PUSH_SHOWN, p.start + p.duration + PUSH_SHOWN)
        seg = build.push_arrow(p.at, p.force)
        d.tube(build.Lines(f"/walk/push/{k}/shaft", seg, build.PUSH_RGB), PUSH_RADIUS, shown)
        head = build.sphere(f"/walk/push/{k}/head", 0.03, build.PUSH_RGB)
        d.mesh(Mesh(head.name, head.vertices + p.at, head.faces, head.rgb), shown=shown)
        text = f"push {np.linalg.norm(p.force):.0f} N at {p.start:.2f} s"
        d.label(build.Label(f"/walk/push/{k}/label", text, seg[0, 0]), shown)


def _marker(name: str, pts: FloatArray, frames: int, rgb: tuple[int, int, int]) -> dict[str, Any]:
    """A ball at ``pts[f]`` at frame ``f`` (hidden where NaN or missing)."""
    at = np.full((frames, 3), np.nan)
    n = min(frames, pts.shape[0])
    at[:n] = pts[:n] + np.array([0.0, 0.0, 2 * build.LIFT])
    return {
        "name": name,
        "positions": b64(at, "f4"),
        "mesh": mesh_entry(build.sphere(name, MARKER_RADIUS, rgb)),
    }


def _support(feet: FloatArray, contact: Any) -> dict[str, Any]:
    """The support polygon per frame, padded to four segments (zero-length at the first foot)."""
    frames = feet.shape[0]
    out = np.zeros((frames, SUPPORT_PER // 2, 2, 3))
    for f in range(frames):
        seg = build.support_polygon(feet[f], contact[f])
        out[f, :] = feet[f, 0]
        out[f, : seg.shape[0]] = seg[: SUPPORT_PER // 2]
    return {"name": "/quadruped/support", "rgb": [30, 30, 30], "per": SUPPORT_PER,
            "positions": b64(out + np.array([0.0, 0.0, 2 * build.LIFT]), "f4")}  # fmt: skip


def _robot(d: _Drawing, data: ViewData) -> dict[str, Any] | None:
    """The robot's bodies, meshes and motion, and the markers that move with time."""
    track = data.walk if data.walk is not None else data.quadruped
    motion: RobotMotion | None = track.motion if track is not None else None
    if motion is None:
        return None
    world = data.scene is None or data.quadruped is not None
    meshes = []
    for body, mesh in build.robot_meshes(motion, world):
        if body < 0:  # the model's fixed geoms (the quadruped's ground): terrain
            d.mesh(mesh, terrain=True)
        else:
            meshes.append(mesh_entry(mesh, body=body))
    d.activity.append(build.body_extents(motion))
    frames = len(motion.t)
    prefix = "/walk" if data.walk is not None else "/quadruped"
    assert track is not None
    markers = [
        _marker(f"{prefix}/cop", track.cop, frames, build.COP_RGB),
        _marker(f"{prefix}/zmp", track.zmp, frames, build.ZMP_RGB),
    ]
    q = data.quadruped
    return {
        "bodies": list(motion.bodies),
        "t": b64(motion.t, "f8"),
        "pos": b64(motion.pos, "f4"),
        "wxyz": b64(motion.wxyz, "f4"),
        "meshes": meshes,
        "markers": markers,
        "support": _support(q.feet[:frames], q.contact[:frames]) if q is not None else None,
    }


def page_payload(data: ViewData, start: float = 0.0) -> dict[str, Any]:
    """The page's document for ``data``, the recorded motion shown at ``start`` [s] first."""
    if not (math.isfinite(start) and start >= 0.0):
        raise InputError("time", start, "a finite time >= 0 [s]")
    d = _Drawing()
    outcome = ""
    if data.trials:
        outcome = _trial(d, data, 0)
    else:
        _static(d, data)
    robot = _robot(d, data)
    summaries = [
        s for s in (data.walk and data.walk.summary, data.quadruped and data.quadruped.summary) if s
    ]
    return {
        "title": data.title,
        "notes": list(data.notes),
        "summaries": summaries,
        "camera": d.camera(),
        "start": float(start),
        "meshes": d.meshes,
        "labels": d.labels,
        "robot": robot,
        "trials": [t.key for t in data.trials],
        "outcome": outcome,
    }


def _trial_at(data: ViewData, index: int) -> tuple[StudyTrial, Scene | None]:
    """Study trial ``index`` and its scene (None: the study's scenes do not hold it)."""
    if not 0 <= index < len(data.trials):
        raise InputError("trial", index, f"a trial index in 0..{len(data.trials) - 1}")
    trial = data.trials[index]
    return trial, next((s for s in data.scenes if s.name == trial.scene), None)


def _trial(d: _Drawing, data: ViewData, index: int) -> str:
    """Draw study trial ``index`` (its scene, the plan it walked, its push) into ``d``; its
    outcome."""
    trial, scene = _trial_at(data, index)
    _static(d, ViewData("plan", trial.key, scene=scene, plan=trial.plan))
    if trial.push is not None and trial.plan is not None:
        at = _com_at(trial.plan, trial.push.start)
        _pushes(d, (PushMark(trial.push.start, trial.push.duration, trial.push.force, at),))
    return trial.outcome + ("" if trial.plan else " (no plan in the cache)")


def trial_payload(data: ViewData, index: int) -> dict[str, Any]:
    """A study trial's nodes and outcome (``trial/<index>.json``)."""
    d = _Drawing()
    outcome = _trial(d, data, index)
    return {"meshes": d.meshes, "labels": d.labels, "outcome": outcome}


#: walks a study trial again into a folder (scene, plan, trial, folder -> its outcome): the
#: study's own walker, handed in by the command (the page does not import the studies)
TrialWalker = Callable[[Path, StudyTrial, Scene, Path], Outcome]


def trial_walk_payload(data: ViewData, index: int, walker: TrialWalker) -> dict[str, Any]:
    """A study trial walked again with its replay recorded (``trial/<index>/walk.json``): the
    page document of that walk (:func:`page_payload`), its summary the walk's outcome."""
    trial, scene = _trial_at(data, index)
    if data.folder is None or trial.plan is None or scene is None or trial.seed is None:
        missing = (
            "folder" if data.folder is None else "plan" if trial.plan is None
            else "scene" if scene is None else "seed"
        )  # fmt: skip
        raise InputError("trial", trial.key, f"a trial whose {missing} the study holds")
    with tempfile.TemporaryDirectory(prefix="footfall-trial-") as tmp:
        outcome = walker(data.folder, trial, scene, Path(tmp))
        walked = load_view(Path(tmp))  # the scene: the one its replay.npz holds
    assert walked.walk is not None
    summary = (
        f"walked again: success {outcome.success}, fell {outcome.fell}, goal error "
        f"{outcome.goal_error:.4g} m, ZMP offset mean {outcome.zmp_offset_mean:.4g} m"
    )
    shown = replace(walked, title=f"{trial.key}, walked again", notes=())
    return page_payload(replace(shown, walk=replace(walked.walk, summary=summary)))


def _com_at(plan: Any, t: float) -> FloatArray:
    """Roughly where the planned CoM is at ``t`` [s] of the walk: above the stance footstep of
    the step under way (the studies' push times count from the walk's start)."""
    i = int(
        np.clip(math.floor(t / (plan.robot.t_ss + plan.robot.t_ds)), 0, len(plan.footsteps) - 1)
    )
    return np.asarray(plan.footsteps[i]) + np.array([0.0, 0.0, plan.robot.com_height])
