"""What a walk records for ``footfall view`` to replay it: ``replay.npz`` in the walk's folder.

The file holds the MuJoCo joint positions ``qpos`` sampled at a display rate (not every control
tick: a viewer draws at most a few tens of frames a second), the MJCF text of the model they
belong to, and a few measured traces resampled to the same instants (the centre of pressure, the
planned ZMP, ...). Everything is a plain numeric or text array written by
:func:`numpy.savez_compressed`; the viewer reads it with ``allow_pickle=False``, so a replay file
is data, never code. A walk of the biped takes about 4 kB a second (a 20 s walk: 73 kB).

Keys (F display frames, ``nq`` the model's position coordinates):

- ``format``: :data:`REPLAY_FORMAT`; ``kind``: ``biped`` or ``quadruped``.
- ``t``: (F,) float32 [s], the walk's time of each frame.
- ``qpos``: (F, nq) float32, MuJoCo's ``data.qpos`` at those instants.
- ``model_xml``: the MJCF text the simulation compiled (robot and terrain geoms).
- ``scene_yaml``: the walked scene as a scene file (biped walks; empty when unknown).
- ``trace/<name>``: (F, ...) arrays of measurements at the frames (see the writers' callers).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import atomic_open
from footfall._typing import FloatArray
from footfall.errors import InputError

#: the file a walk's folder holds its replay in
REPLAY_FILE = "replay.npz"
#: the layout version of the file; a reader refuses another
REPLAY_FORMAT = "footfall-replay-1"
#: frames a second recorded: what a browser shows smoothly, far below the control rate
DISPLAY_RATE = 30.0


class ReplayRecorder:
    """Samples ``data.qpos`` at ``rate`` frames a second while a simulation runs.

    The simulation calls :meth:`begin` with the MJCF text it compiled, then :meth:`sample` every
    control period with the simulated time; a frame is kept whenever a display instant has been
    reached (the first call always keeps one).
    """

    def __init__(self, kind: str, rate: float = DISPLAY_RATE) -> None:
        if not rate > 0.0:
            raise InputError("rate", rate, "a display rate > 0 [1/s]")
        self.kind, self.rate = kind, rate
        self.model_xml = ""
        self._t: list[float] = []
        self._qpos: list[FloatArray] = []
        self._next = -np.inf

    def begin(self, model_xml: str) -> None:
        """Start a recording of the model compiled from ``model_xml`` (earlier frames dropped)."""
        self.model_xml = model_xml
        self._t, self._qpos, self._next = [], [], -np.inf

    def sample(self, t: float, data: Any) -> None:
        """Keep ``data.qpos`` as the frame at ``t`` [s] when a display instant has come."""
        if t + 1e-9 < self._next:
            return
        self._t.append(t)
        self._qpos.append(np.array(data.qpos, dtype=np.float32))
        # the next instant on the display grid after t, so frames do not drift with the tick
        self._next = (np.floor(t * self.rate + 1e-6) + 1.0) / self.rate

    @property
    def times(self) -> FloatArray:
        """Times of the frames kept so far, shape (F,) [s]."""
        return np.array(self._t, dtype=float)

    def write(
        self,
        path: Path,
        traces: Mapping[str, FloatArray] | None = None,
        scene_yaml: str = "",
    ) -> Path:
        """Write the frames, the model and ``traces`` (each with F rows, see :func:`at_frames`)
        to ``path`` atomically (a temporary file, then a rename)."""
        n = len(self._t)
        arrays: dict[str, Any] = {
            "format": np.array(REPLAY_FORMAT),
            "kind": np.array(self.kind),
            "t": np.array(self._t, dtype=np.float32),
            "qpos": np.array(self._qpos, dtype=np.float32).reshape(n, -1),
            "model_xml": np.array(self.model_xml),
            "scene_yaml": np.array(scene_yaml),
        }
        for name, values in (traces or {}).items():
            values = np.asarray(values)
            if values.shape[:1] != (n,):
                raise InputError(f"traces[{name}]", values.shape, f"{n} rows, one a frame")
            arrays[f"trace/{name}"] = (
                values.astype(np.float32) if values.dtype.kind == "f" else values
            )
        # written whole or not at all, like every other output (footfall._io.atomic_open)
        with atomic_open(path, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        return path


def at_frames(t: FloatArray, values: Any, frames: FloatArray) -> Any:
    """``values`` (rows at times ``t``, ascending) at the instants ``frames``: the last row at
    or before each (a measurement holds until the next one)."""
    idx = np.searchsorted(np.asarray(t), np.asarray(frames) + 1e-9, side="right") - 1
    return np.asarray(values)[np.clip(idx, 0, len(t) - 1)]


def biped_traces(result: Any, frames: FloatArray) -> dict[str, Any]:
    """The MuJoCo biped's measurements at the replay's frames (a
    :class:`~footfall.results.walk.WalkTrace`): ``phase`` (single-support index, -1
    outside), ``feet`` (F, 2, 3) sole centres [m], ``com`` (F, 3) [m], ``cop_offset`` and
    ``zmp_offset`` (F, 2) [m]: the measured centre of pressure and the planned ZMP relative to
    the stance sole centre in its frame (NaN outside single support)."""
    t = result.t
    return {
        "phase": at_frames(t, result.phase, frames).astype(np.int16),
        "feet": at_frames(t, result.feet, frames),
        "com": at_frames(t, result.com, frames),
        "cop_offset": at_frames(t, result.zmp_offset, frames),
        "zmp_offset": at_frames(t, result.zmp_planned, frames),
    }


def quadruped_traces(result: Any, frames: FloatArray) -> dict[str, Any]:
    """The quadruped's measurements at the replay's frames (a
    :class:`~footfall.results.quadruped.QuadrupedTrace`): ``feet`` (F, 4, 3) [m], ``contact``
    (F, 4) the planned stance flags, ``cop`` and ``zmp`` (F, 2) [m] the measured centre of
    pressure and the planned ZMP."""
    t = result.t
    return {
        "feet": at_frames(t, result.feet, frames),
        "contact": at_frames(t, result.planned.contact, frames).astype(np.bool_),
        "cop": at_frames(t, result.cop, frames),
        "zmp": at_frames(t, result.planned.zmp, frames),
    }
