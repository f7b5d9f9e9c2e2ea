"""Small helpers shared by the MJCF generators (quadruped, biped, terrain)."""

from __future__ import annotations

import numpy as np


def fmt(*values: float | np.floating, digits: int = 6) -> str:
    """Numbers as an MJCF attribute string with ``digits`` significant digits."""
    return " ".join(f"{float(v):.{digits}g}" for v in values)


def box_inertia(mass: float, sx: float, sy: float, sz: float) -> tuple[float, float, float]:
    """Principal inertia [kg m^2] of a solid box with full side lengths sx, sy, sz [m]."""
    return (
        mass * (sy * sy + sz * sz) / 12.0,
        mass * (sx * sx + sz * sz) / 12.0,
        mass * (sx * sx + sy * sy) / 12.0,
    )


def rod_inertia(mass: float, length: float, radius: float) -> tuple[float, float, float]:
    """Slender rod along z: principal inertia about its centre [kg m^2]."""
    transverse = mass * (3.0 * radius * radius + length * length) / 12.0
    return transverse, transverse, 0.5 * mass * radius * radius
