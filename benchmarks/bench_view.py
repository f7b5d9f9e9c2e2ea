"""``footfall view`` in headless Chromium: how fast the page shows, how smoothly a walk plays.

Run (from the repository root; needs the ``sim`` and ``view`` extras and Debian's ``chromium``):

    OPENBLAS_NUM_THREADS=1 MUJOCO_GL=egl PYTHONPATH=src python benchmarks/bench_view.py \
        [--out out/bench_view] [--repeats 3] [--play-seconds 5]

1. Data: a 20 s walk (``footfall walk --scene flat_long --planner kinematic --steps 30
   --controller servo --no-video``, made once into ``OUT/walk``) and a 40-region scene
   (``random_stepping_stones(seed=1, n_regions=40)``, ``OUT/stones40.yaml``), shown together
   with ``footfall view OUT/walk --scene OUT/stones40.yaml``: 40 region slabs, the 31 planned
   soles with labels, the landed soles, the CoP / ZMP traces and the robot's 600 frames.
2. Time to show: with a headless Chromium already running (a user's browser), the clock starts
   when the ``footfall view`` process is started; the page is requested as soon as the port
   answers and the clock stops when the page holds the whole scene (its last node) and has drawn
   two frames. Median and max over ``--repeats`` fresh processes, with the server's share (until
   the port answers).
3. Playback: *play* is clicked in the page; for ``--play-seconds`` the page counts, at every
   animation frame, whether the robot's pelvis moved since the last one (distinct robot poses
   drawn per second: the playback's frame rate) and the page's count of pictures drawn.
   ``--antialias`` 0 or 1 overrides the page's choice (multisampling off in a software WebGL).
"""

from __future__ import annotations

import argparse
import os
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MUJOCO_GL", "egl")

#: counts, at each animation frame, the robot poses and three.js renders the page shows
_PLAY_PROBE = """seconds => new Promise(done => {
  const page = window.footfall;
  const pelvis = () => page.bodyPosition('pelvis')[0];
  const t0 = performance.now(), r0 = page.renders;
  let last = pelvis(), poses = 0, ticks = 0;
  function tick() {
    ticks++;
    const x = pelvis();
    if (x !== last) { poses++; last = x; }
    const dt = (performance.now() - t0) / 1000;
    if (dt < seconds) requestAnimationFrame(tick);
    else done({poses: poses / dt, renders: (page.renders - r0) / dt, raf: ticks / dt});
  }
  requestAnimationFrame(tick);
})"""


def _footfall(*args: str) -> list[str]:
    return [sys.executable, "-m", "footfall", *args]


def make_data(out: Path) -> tuple[Path, Path]:
    """The walk folder and the 40-region scene file (made once)."""
    from footfall.terrain import random_stepping_stones, scene_to_yaml

    walk = out / "walk"
    if not (walk / "replay.npz").is_file():
        args = ["--planner", "kinematic", "--steps", "30", "--controller", "servo"]
        cmd = _footfall("walk", "--scene", "flat_long", *args, "--no-video", "--quiet")
        subprocess.run([*cmd, "--out", str(walk)], check=True)
    scene = out / "stones40.yaml"
    scene.write_text(scene_to_yaml(random_stepping_stones(1, n_regions=40)))
    return walk, scene


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def time_to_show(
    context: object, walk: Path, scene: Path, query: str = ""
) -> tuple[float, float, object, object]:
    """Seconds from starting ``footfall view`` until the port answers and until the page shows
    the whole scene; the page and the process (still serving)."""
    from footfall.viz.view.browser import wait_loaded

    port = _free_port()
    page = context.new_page()  # type: ignore[attr-defined]
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        _footfall("view", str(walk), "--scene", str(scene), "--port", str(port)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    while True:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.05):
                break
        except OSError:
            if proc.poll() is not None:
                raise RuntimeError("footfall view exited before serving") from None
            time.sleep(0.01)
    t_port = time.perf_counter() - t0
    page.goto(f"http://127.0.0.1:{port}/{query}")
    wait_loaded(page)
    return t_port, time.perf_counter() - t0, page, proc


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("out/bench_view"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--play-seconds", type=float, default=5.0)
    parser.add_argument("--antialias", choices=("auto", "0", "1"), default="auto")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    walk, scene = make_data(args.out)

    import numpy as np

    from footfall.viz.view.browser import chromium
    from footfall.viz.view.replay import read_replay

    replay = read_replay(walk / "replay.npz")
    size_kb = (walk / "replay.npz").stat().st_size / 1000
    print(
        f"walk: {replay.t[-1]:.1f} s, {len(replay.t)} frames, replay.npz {size_kb:.0f} kB; "
        f"scene: 40 regions; load average {os.getloadavg()[0]:.1f}"
    )
    shows, ports, plays = [], [], []
    with chromium() as context:
        # a first page warms the browser's caches, as a user's browser would have them
        _, _, page, proc = time_to_show(context, walk, scene)
        page.close()
        proc.terminate()
        proc.wait()
        for _ in range(args.repeats):
            query = "" if args.antialias == "auto" else f"?antialias={args.antialias}"
            t_port, t_show, page, proc = time_to_show(context, walk, scene, query)
            ports.append(t_port)
            shows.append(t_show)
            page.get_by_text("play / pause").click()
            plays.append(page.evaluate(_PLAY_PROBE, args.play_seconds))
            antialias = page.evaluate("() => window.footfall.antialias")
            page.close()
            proc.terminate()
            proc.wait()
    poses = [p["poses"] for p in plays]
    renders = [p["renders"] for p in plays]
    print(
        f"time to show: median {statistics.median(shows):.2f} s, max {max(shows):.2f} s "
        f"(server answering after median {statistics.median(ports):.2f} s)"
    )
    print(
        f"playback: {statistics.median(poses):.1f} robot poses/s drawn (min {min(poses):.1f}), "
        f"{statistics.median(renders):.1f} renders/s, animation frames "
        f"{np.median([p['raf'] for p in plays]):.0f}/s (multisampling {'on' if antialias else 'off'})"
    )


if __name__ == "__main__":
    main()
