"""A study table row made by hand for the statistics tests (the columns of trials.parquet)."""

from __future__ import annotations

from typing import Any

from footfall.experiments.study.trials import normalise_row


def study_row(
    planner: str,
    seed: int,
    success: bool,
    zmp: float,
    *,
    scene: str = "s",
    impulse: float = 3.0,
    smallest: bool = True,
    equal: bool = False,
    error: str | None = None,
    n_steps: int = 7,
) -> dict[str, Any]:
    """One walk: ``planner`` on ``scene`` with ``seed``; an ``error`` row has no numbers."""
    return normalise_row(
        {
            "key": f"{scene}|{planner}|N={n_steps}|J={impulse:g}|seed={seed}|{smallest}{equal}",
            "scene": scene,
            "planner": planner,
            "n_steps": n_steps,
            "smallest_n": smallest,
            "equal_n": equal,
            "push_impulse": impulse,
            "seed": seed,
            "simulator": "reduced",
            "success": None if error else success,
            "fell": None if error else not success,
            "zmp_offset_mean": None if error else zmp,
            "zmp_offset_max": None if error else 2 * zmp,
            "footstep_error_mean": None if error else 0.001,
            "error": error,
        }
    )
