"""Headless matplotlib setup shared by the figure modules."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.figure import Figure


def save(fig: Figure, path: Path) -> Path:
    """Save ``fig`` to ``path`` (parents created), close it and return the path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


__all__ = ["plt", "save"]
