"""The MP4 writer every MuJoCo plant shares: offscreen frames of one camera at ``VIDEO_FPS``."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from footfall._io import PendingFile

#: video frame rate [1/s]
VIDEO_FPS = 30


class Video:
    """MP4 of a named camera (offscreen GL), one frame every ``1 / VIDEO_FPS`` of simulated time
    (every ``frame_every`` control ticks of ``dt``). Without a path it does nothing; without GL
    there is no video and :attr:`note` says why, and the walk goes on. The file is written under
    a temporary name beside ``path`` and put in place only when :meth:`close` says the walk is
    complete (:class:`~footfall._io.PendingFile`): an interrupted walk leaves the previous video.

    Attributes:
        note: why there is no video ("" when there is one or none was asked).
        render_time: wall time spent rendering [s] (loops subtract it from their own).
    """

    def __init__(
        self,
        mujoco: Any,
        model: Any,
        path: Path | None,
        size: tuple[int, int],
        dt: float,
        camera: str,
    ) -> None:
        self.renderer: Any = None
        self.writer: Any = None
        self.file: PendingFile | None = None
        self.note = ""
        self.render_time = 0.0
        self.path = path
        self.camera = camera
        self.frame_every = max(1, round(1.0 / (VIDEO_FPS * dt)))
        if path is None:
            return
        try:
            self.renderer = mujoco.Renderer(model, height=size[1], width=size[0])
        except Exception as exc:  # any GL failure means "no video", never a crash
            self.note = f"no offscreen GL ({type(exc).__name__}: {exc}); video skipped"
            return
        import imageio.v2 as imageio

        # written beside the destination and renamed over it when complete (close)
        self.file = PendingFile(path)
        self.writer = imageio.get_writer(str(self.file.tmp), fps=VIDEO_FPS, macro_block_size=8)

    def frame(self, k: int, data: Any) -> bool:
        """Render control tick ``k`` if a frame is due; whether one was."""
        if self.writer is None or k % self.frame_every != 0:
            return False
        r0 = time.perf_counter()
        self.renderer.update_scene(data, camera=self.camera)
        self.writer.append_data(self.renderer.render())
        self.render_time += time.perf_counter() - r0
        return True

    def close(self, complete: bool = True) -> Path | None:
        """Finish the file (put in place when ``complete``; removed, the previous video left,
        when the walk was interrupted) and free the renderer; the file's path, None when none
        was written."""
        written = False
        try:
            if self.writer is not None:
                self.writer.close()
                assert self.file is not None
                self.file.finish(complete)
                written = complete
        finally:
            if self.renderer is not None:
                self.renderer.close()
                self.renderer = None
            self.writer = None
        return self.path if written else None
