"""Headless matplotlib setup shared by the figure modules."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from footfall._io import save_figure


def save(fig: Figure, path: Path) -> Path:
    """Save ``fig`` to ``path`` atomically (parents created), close it and return the path."""
    return save_figure(fig, path, dpi=120, bbox_inches="tight")


__all__ = ["plt", "save"]
