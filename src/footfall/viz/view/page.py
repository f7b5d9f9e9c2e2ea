"""The thin viser layer: serve a :class:`~footfall.viz.view.load.ViewData` as a 3-D page.

:class:`ViewPage` puts the nodes of :mod:`footfall.viz.view.build` into a viser scene, adds the
controls (a time slider, play/pause, a study's trial picker) and moves the robot and the
per-frame markers when the time changes. The camera starts fitted to everything shown.
"""

from __future__ import annotations

import math
import threading
import time
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.viz.view import build
from footfall.viz.view.load import PushMark, StudyTrial, ViewData
from footfall.viz.view.replay import RobotMotion
from footfall.viz.view.serve import READY_NODE, start_server, stop_server

#: frames a second of the replay's playback (the rate walks record at)
PLAY_FPS = 30.0
#: a push arrow shows this long [s] before and after the push
PUSH_SHOWN = 0.4


class ViewPage:
    """A page served at ``http://host:port`` (port 0: any free port). The server starts at
    once, so a browser can load the page while :meth:`show` puts ``data`` into it (given here,
    it is shown at once, the recorded motion at ``start`` [s])."""

    def __init__(
        self,
        data: ViewData | None = None,
        host: str = "127.0.0.1",
        port: int = 8080,
        start: float = 0.0,
        server: Any = None,
    ) -> None:
        # a server already started (:func:`~footfall.viz.view.serve.start_server`) is adopted
        self.server = server = server if server is not None else start_server(host, port)
        self.port = int(server.get_port())
        self.url = f"http://{host}:{self.port}/"
        self.data = ViewData("none", "")
        self.motion: RobotMotion | None = None
        self.t: FloatArray = np.zeros(0)
        self.frame = 0
        self.camera = build.fit_camera(np.zeros((1, 3)))
        self._bodies: list[Any] = []
        self._markers: dict[str, Any] = {}
        self._pushes: list[tuple[PushMark, Any]] = []
        self._playing = threading.Event()
        self._stop = threading.Event()
        self._from_player = False
        self._points: list[FloatArray] = []
        self._terrain: list[FloatArray] = []
        self._handles: list[Any] = []
        self._player = threading.Thread(target=self._play_loop, daemon=True)
        self._player.start()
        if data is not None:
            self.show(data, start)

    def show(self, data: ViewData, start: float = 0.0) -> None:
        """Put ``data`` into the page (once), the motion at ``start`` [s], the camera fitted to
        it; the page holds everything when it holds :data:`READY_NODE`."""
        if self.data.kind != "none":
            raise InputError("show", data.title, "one call per page")
        self.data = data
        server = self.server
        with server.atomic():
            self._draw(data)
            self._controls(data)
            if len(self.t) > 1 and start > 0.0:
                self.set_frame(self.frame_at(start))
                self._from_player = True  # the slider follows; no second update
                self.slider.value = round(float(self.t[self.frame]), 3)
                self._from_player = False
        self.camera = build.fit_camera(
            build.framed_points(_stack(self._terrain), _stack(self._points))
        )
        position, look_at = tuple(self.camera.position), tuple(self.camera.look_at)
        server.initial_camera.position = position
        server.initial_camera.look_at = look_at
        server.initial_camera.up = (0.0, 0.0, 1.0)
        server.initial_camera.fov = self.camera.fov
        for client in server.get_clients().values():  # pages that opened before the data came
            client.camera.fov = self.camera.fov
            client.camera.position = position
            client.camera.look_at = look_at
        # the last node: a page that has it has everything before it (messages arrive in order)
        server.scene.add_frame(READY_NODE, show_axes=False, visible=False)

    # ------------------------------------------------------------------ static scene
    def _mesh(self, m: build.Mesh, terrain: bool = False) -> Any:
        (self._terrain if terrain else self._points).append(m.vertices)
        return self._keep(
            self.server.scene.add_mesh_simple(
                m.name,
                m.vertices,
                m.faces,
                color=m.rgb,
                opacity=None if m.opacity >= 1.0 else m.opacity,
                flat_shading=True,
                cast_shadow=False,
                receive_shadow=False,
            )
        )

    def _keep(self, handle: Any) -> Any:
        """Remember a node of the shown item (a study's trial picker replaces them)."""
        self._handles.append(handle)
        return handle

    def _lines(self, ln: build.Lines, thickness: float = 0.01) -> None:
        if ln.segments.shape[0]:
            self._points.append(ln.segments.reshape(-1, 3))
            self._keep(
                self.server.scene.add_line_segments(
                    ln.name, ln.segments, ln.rgb, thickness=thickness
                )
            )

    def _label(self, lb: build.Label) -> None:
        self._keep(
            self.server.scene.add_label(
                lb.name, lb.text, position=tuple(lb.position), anchor="bottom-center"
            )
        )

    def _draw(self, data: ViewData) -> None:
        """The static part of the page: terrain, plan, landed footsteps, traces."""
        if data.scene is not None:
            for m in build.region_meshes(data.scene):
                self._mesh(m, terrain=True)
            for lb in build.start_goal(data.scene):
                self._label(lb)
        if data.plan is not None and data.plan.has_solution:
            self._draw_plan(data)
        if data.walk is not None:
            w = data.walk
            landed = build.landed_soles(data.plan, w.landed) if data.plan is not None else None
            if landed is not None:
                self._mesh(landed)
            self._robot(w.motion, world=data.scene is None)
            self._trail("/walk/cop_trail", w.cop, build.COP_RGB)
            self._trail("/walk/zmp_trail", w.zmp, build.ZMP_RGB)
            self._marker("/walk/cop", build.COP_RGB)
            self._marker("/walk/zmp", build.ZMP_RGB)
            self._push_arrows(w.pushes)
        if data.quadruped is not None:
            q = data.quadruped
            self._robot(q.motion, world=True)
            self._trail("/quadruped/cop_trail", q.cop, build.COP_RGB)
            self._trail("/quadruped/zmp_trail", q.zmp, build.ZMP_RGB)
            self._marker("/quadruped/cop", build.COP_RGB)
            self._marker("/quadruped/zmp", build.ZMP_RGB)
            self._points.append(q.feet.reshape(-1, 3))

    def _draw_plan(self, data: ViewData) -> None:
        assert data.plan is not None
        soles, labels, ticks = build.footstep_nodes(data.plan, data.scene)
        for m in soles:
            self._mesh(m)
        for lb in labels:
            self._label(lb)
        self._lines(ticks, 0.006)
        if data.plan.states.size:
            self._lines(build.com_path(data.plan), 0.008)

    def _trail(self, name: str, pts: FloatArray, rgb: tuple[int, int, int]) -> None:
        ok = pts[np.all(np.isfinite(pts), axis=1)] if pts.size else pts
        if ok.shape[0]:
            self._keep(
                self.server.scene.add_point_cloud(
                    name,
                    ok + np.array([0.0, 0.0, 2 * build.LIFT]),
                    rgb,
                    point_size=0.008,
                    point_shape="circle",
                )
            )

    def _marker(self, name: str, rgb: tuple[int, int, int]) -> None:
        self._markers[name] = self.server.scene.add_icosphere(
            name, radius=0.018, color=rgb, subdivisions=2, cast_shadow=False, visible=False
        )

    def _push_arrows(self, pushes: tuple[PushMark, ...]) -> None:
        for k, p in enumerate(pushes):
            if p.at is None:
                continue
            seg = build.push_arrow(p.at, p.force)
            # the arrow is a group: shown around the push's time only
            handle = self._keep(self.server.scene.add_frame(f"/walk/push/{k}", show_axes=False))
            scene = self.server.scene
            scene.add_line_segments(f"/walk/push/{k}/shaft", seg, build.PUSH_RGB, thickness=0.02)
            scene.add_icosphere(
                f"/walk/push/{k}/head", radius=0.03, color=build.PUSH_RGB, position=tuple(p.at)
            )
            scene.add_label(
                f"/walk/push/{k}/label",
                f"push {np.linalg.norm(p.force):.0f} N at {p.start:.2f} s",
                position=tuple(seg[0, 0]),
            )
            self._pushes.append((p, handle))

    def _robot(self, motion: RobotMotion | None, world: bool) -> None:
        """The robot's bodies as frames carrying their geoms' meshes (and, with ``world``, the
        model's fixed geoms: the quadruped's ground)."""
        if motion is None:
            return
        self.motion, self.t = motion, motion.t
        scene = self.server.scene
        self._bodies = [
            scene.add_frame(
                f"/robot/{b}",
                show_axes=False,
                position=tuple(motion.pos[0, i]),
                wxyz=tuple(motion.wxyz[0, i]),
            )
            for i, b in enumerate(motion.bodies)
        ]
        for body, mesh in build.robot_meshes(motion, world):
            scene.add_mesh_simple(
                mesh.name,
                mesh.vertices,
                mesh.faces,
                color=mesh.rgb,
                opacity=None if mesh.opacity >= 1.0 else mesh.opacity,
                side="double",
                cast_shadow=False,
                receive_shadow=False,
            )
            if body < 0:
                self._terrain.append(mesh.vertices)
        self._points.append(build.body_extents(motion))

    # ---------------------------------------------------------------------- controls
    def _controls(self, data: ViewData) -> None:
        gui = self.server.gui
        gui.add_markdown(f"**{data.title}**")
        for note in data.notes:
            gui.add_markdown(f"_{note}_")
        if data.walk is not None and data.walk.summary:
            gui.add_markdown(data.walk.summary)
        if data.quadruped is not None and data.quadruped.summary:
            gui.add_markdown(data.quadruped.summary)
        n = len(self.t)
        self.slider = gui.add_slider(
            "time [s]",
            0.0,
            float(self.t[-1]) if n > 1 else 0.0,
            1.0 / PLAY_FPS,
            0.0,
            visible=n > 1,
        )
        self.slider.on_update(lambda _: self._on_slider())
        self.play = gui.add_button("play / pause", visible=n > 1)
        self.play.on_click(lambda _: self.toggle())
        self.status = gui.add_markdown(self._status())
        if data.trials:
            self._trial_picker(data.trials)
        if n:
            self.set_frame(0)

    def _trial_picker(self, trials: tuple[StudyTrial, ...]) -> None:
        gui = self.server.gui
        keys = [t.key for t in trials]
        self.trial = gui.add_dropdown("trial", keys, initial_value=keys[0])
        self.trial_info = gui.add_markdown("")
        self.trial.on_update(lambda _: self.show_trial(self.trial.value))
        self.show_trial(keys[0])

    def show_trial(self, key: str) -> None:
        """Show a study trial: its scene, the plan it walked, its push and outcome."""
        trial = next(t for t in self.data.trials if t.key == key)
        scene = next((s for s in self.data.scenes if s.name == trial.scene), None)
        with self.server.atomic():
            for handle in self._handles:
                handle.remove()
            self._handles, self._pushes = [], []
            sub = ViewData("plan", trial.key, scene=scene, plan=trial.plan)
            self._draw(sub)
            if trial.push is not None and trial.plan is not None:
                at = _com_at(trial.plan, trial.push.start)
                self._push_arrows(
                    (PushMark(trial.push.start, trial.push.duration, trial.push.force, at),)
                )
        self.trial_info.content = f"{trial.outcome}" + (
            "" if trial.plan else " (no plan in the cache)"
        )

    def _status(self) -> str:
        if len(self.t) < 2:
            return "no recorded motion"
        return f"frame {self.frame + 1} / {len(self.t)}, t = {self.t[self.frame]:.2f} s"

    def _on_slider(self) -> None:
        if self._from_player:
            return
        self.set_frame(self.frame_at(float(self.slider.value)))

    def toggle(self) -> None:
        """Play or pause."""
        if self._playing.is_set():
            self._playing.clear()
        else:
            self._playing.set()

    def frame_at(self, t: float) -> int:
        """The last frame at or before ``t`` [s]."""
        return int(np.clip(np.searchsorted(self.t, t + 1e-9, side="right") - 1, 0, len(self.t) - 1))

    def set_frame(self, f: int) -> None:
        """Pose the robot and the markers at frame ``f``."""
        if not len(self.t):
            return
        f = int(np.clip(f, 0, len(self.t) - 1))
        self.frame = f
        t = float(self.t[f])
        with self.server.atomic():
            if self.motion is not None:
                for i, body in enumerate(self._bodies):
                    body.position = tuple(self.motion.pos[f, i])
                    body.wxyz = tuple(self.motion.wxyz[f, i])
            if self.data.walk is not None:
                self._place("/walk/cop", self.data.walk.cop, f)
                self._place("/walk/zmp", self.data.walk.zmp, f)
            q = self.data.quadruped
            if q is not None:
                self._place("/quadruped/cop", q.cop, f)
                self._place("/quadruped/zmp", q.zmp, f)
                seg = build.support_polygon(q.feet[f], q.contact[f])
                self.server.scene.add_line_segments(
                    "/quadruped/support",
                    seg if seg.size else np.zeros((1, 2, 3)),
                    (30, 30, 30),
                    thickness=0.008,
                )
            for p, handle in self._pushes:
                handle.visible = p.start - PUSH_SHOWN <= t <= p.start + p.duration + PUSH_SHOWN
            self.status.content = self._status()

    def _place(self, name: str, pts: FloatArray, f: int) -> None:
        marker = self._markers[name]
        ok = f < pts.shape[0] and bool(np.all(np.isfinite(pts[f])))
        marker.visible = ok
        if ok:
            marker.position = tuple(pts[f] + np.array([0.0, 0.0, 2 * build.LIFT]))

    def _play_loop(self) -> None:
        period = 1.0 / PLAY_FPS
        next_tick = time.perf_counter()
        while not self._stop.is_set():
            if not self._playing.wait(0.1):
                next_tick = time.perf_counter()
                continue
            f = (self.frame + 1) % max(1, len(self.t))
            self.set_frame(f)
            self._from_player = True
            try:
                self.slider.value = round(float(self.t[f]), 3)
            finally:
                self._from_player = False
            next_tick += period
            time.sleep(max(0.0, next_tick - time.perf_counter()))

    def close(self) -> None:
        """Stop playing and serving."""
        self._stop.set()
        self._playing.clear()
        self._player.join(timeout=1.0)
        stop_server(self.server)


def _com_at(plan: Any, t: float) -> FloatArray:
    """Roughly where the planned CoM is at ``t`` [s] of the walk: above the stance footstep of
    the step under way (the studies' push times count from the walk's start)."""
    i = int(
        np.clip(math.floor(t / (plan.robot.t_ss + plan.robot.t_ds)), 0, len(plan.footsteps) - 1)
    )
    return np.asarray(plan.footsteps[i]) + np.array([0.0, 0.0, plan.robot.com_height])


def _stack(arrays: list[FloatArray]) -> FloatArray:
    """The rows of ``arrays`` (each (..., 3)) as one (P, 3) array."""
    return np.vstack([a.reshape(-1, 3) for a in arrays]) if arrays else np.zeros((0, 3))
