"""The ``footfall demo`` pipeline: every capability on its built-in default, into one folder."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from footfall._io import write_json
from footfall.planning.lip_examples import EXAMPLES
from footfall.planning.lip_io import lip_walk_to_dict
from footfall.planning.lip_walk import lip_walk


def run_demo(out: Path) -> dict[str, Any]:
    """Run the demo and write ``out/demo.json`` plus one sub-folder of outputs per part.

    Returns:
        The summary written to ``demo.json``; ``lines`` holds a human-readable digest.
    """
    from footfall.viz.lip_plot import plot_lip_walk

    lines: list[str] = []
    lip_summary: dict[str, Any] = {}
    for name, make in EXAMPLES.items():
        walk = lip_walk(make())
        folder = out / "lip" / name
        write_json(folder / "lip_walk.json", lip_walk_to_dict(walk))
        plot_lip_walk(walk, folder / "lip_walk.png", title=f"LIP walk: {name} (document 004)")
        speed = math.hypot(*walk.final_vel)
        lip_summary[name] = {"steps": int(walk.footholds.shape[0]), "final_speed_mps": speed}
        lines.append(
            f"LIP {name:9s}: {walk.footholds.shape[0]:2d} steps, final speed {speed:.4f} m/s"
        )
    summary: dict[str, Any] = {"lip": lip_summary, "lines": lines}
    write_json(out / "demo.json", summary)
    return summary
