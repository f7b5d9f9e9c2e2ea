"""The page of one path: :class:`ViewPage` packs a :class:`~footfall.viz.view.load.ViewData`
(:mod:`footfall.viz.view.payload`) and serves it (:mod:`footfall.viz.view.serve`) to the
browser's viewer, which draws it and plays the recorded motion itself.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.viz.view import payload
from footfall.viz.view.load import ViewData
from footfall.viz.view.replay import RobotMotion
from footfall.viz.view.serve import PageServer, start_server, stop_server


class ViewPage:
    """A page served at ``http://host:port`` (port 0: any free port). The server starts at
    once, so a browser can load the page while :meth:`show` packs ``data`` (given here, it is
    shown at once, the recorded motion at ``start`` [s]). ``trial_walker`` walks a study's trial
    again for the page (:func:`footfall.experiments.study.rewalk.trial_walker`; None: the page
    cannot)."""

    def __init__(
        self,
        data: ViewData | None = None,
        host: str = "127.0.0.1",
        port: int = 8080,
        start: float = 0.0,
        server: PageServer | None = None,
        trial_walker: payload.TrialWalker | None = None,
    ) -> None:
        # a server already started (:func:`~footfall.viz.view.serve.start_server`) is adopted
        self.server = server if server is not None else start_server(host, port)
        self.port = self.server.get_port()
        self.url = f"http://{host}:{self.port}/"
        self.data = ViewData("none", "")
        self.payload: dict[str, Any] = {}
        self.trial_walker = trial_walker
        if data is not None:
            self.show(data, start)

    @property
    def motion(self) -> RobotMotion | None:
        """The recorded robot motion shown (None: none)."""
        track = self.data.walk if self.data.walk is not None else self.data.quadruped
        return track.motion if track is not None else None

    @property
    def t(self) -> FloatArray:
        """The motion's frame times (F,) [s]."""
        motion = self.motion
        return motion.t if motion is not None else np.zeros(0)

    def show(self, data: ViewData, start: float = 0.0) -> None:
        """Serve ``data`` (once per page), the motion shown at ``start`` [s] first."""
        if self.data.kind != "none":
            raise InputError("show", data.title, "one call per page")
        self.payload = payload.page_payload(data, start)
        # the page offers "walk this trial again" only where someone can walk it
        self.payload["rewalk"] = bool(data.trials) and self.trial_walker is not None
        self.data = data
        walker = self.trial_walker
        self.server.publish(
            self.payload,
            lambda i: payload.trial_payload(data, i),
            None if walker is None else lambda i: payload.trial_walk_payload(data, i, walker),
        )

    def close(self) -> None:
        """Stop serving."""
        stop_server(self.server)
