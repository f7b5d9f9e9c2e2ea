"""Plan-view shapes of generated regions, read from their vertices by hand (terrain tests)."""

from __future__ import annotations

import numpy as np

from footfall.terrain.region import Region


def rect(r: Region) -> tuple[float, float, float, float]:
    """(x_min, x_max, y_min, y_max) of a region that is an axis-aligned rectangle in plan view."""
    v = np.asarray(r.vertices)
    assert v.shape == (4, 2), r.name
    xs, ys = sorted(set(v[:, 0].tolist())), sorted(set(v[:, 1].tolist()))
    assert len(xs) == 2 and len(ys) == 2, f"{r.name} is not an axis-aligned rectangle"
    return xs[0], xs[1], ys[0], ys[1]


def level(r: Region, tol: float = 0.0) -> float:
    """The height of a level region: every corner at the same z (within ``tol`` [m])."""
    z = np.asarray(r.vertices3d)[:, 2]
    assert np.ptp(z) <= tol, f"{r.name} is not level: {z}"
    return float(z[0])
