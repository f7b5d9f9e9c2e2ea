"""Biped robot parameters consumed by the footstep planners (document 000, section 5.3).

The reachable set of the swing foot (eq. 5.12f) is a convex trapezoid ``R_reach`` expressed in the
heading frame of the stance foot (x forward, y to the left). It is stored for a RIGHT stance foot,
whose swing foot is the left one (so every vertex has y > 0); for a LEFT stance foot it is mirrored
about the x axis. Reachability of footstep ``i+1`` from stance foot ``p_i`` with heading ``theta_i``
then reads ``Rot(theta_i)^T (p_{i+1} - p_i)[:2] in R_reach(side_i)`` (eq. 5.12f, 5.13).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

import numpy as np
from numpy.typing import ArrayLike

from footfall._geometry import convexity_defect, outward_halfspaces, signed_area
from footfall._typing import FloatArray
from footfall._validate import in_range
from footfall.errors import InputError
from footfall.models.alip import ALIP
from footfall.models.lip import GRAVITY

#: default reach trapezoid for a RIGHT stance foot, (4, 2) [m], CCW: a 0.55 m fore-aft range next to
#: the stance foot narrowing to 0.37 m at the widest lateral reach, as in document 000 fig. 5.3(b)
DEFAULT_REACH = ((-0.20, 0.12), (0.35, 0.12), (0.25, 0.32), (-0.12, 0.32))


class Side(str, Enum):
    """A foot of the biped."""

    LEFT = "left"
    RIGHT = "right"

    @property
    def other(self) -> Side:
        """The opposite foot."""
        return Side.RIGHT if self is Side.LEFT else Side.LEFT

    @property
    def sign(self) -> int:
        """+1 for the left foot, -1 for the right (the sign of its lateral offset from the body)."""
        return 1 if self is Side.LEFT else -1


def _default_reach() -> FloatArray:
    return np.array(DEFAULT_REACH, dtype=float)


@dataclass(frozen=True, eq=False)
class ReachTrapezoid:
    """Convex reachable set ``R_reach`` of the next footstep, relative to the stance (eq. 5.12f).

    Attributes:
        vertices: shape (4, 2) [m], convex, counter-clockwise, in the stance foot's heading frame
            for a RIGHT stance foot (the next foot is the left one, so every y > 0). Clockwise
            input is reversed on construction.
    """

    vertices: FloatArray = field(default_factory=_default_reach)

    def __post_init__(self) -> None:
        try:
            v = np.array(self.vertices, dtype=float)
        except (TypeError, ValueError):
            raise InputError("reach", self.vertices, "4 vertices [[x, y], ...] [m]") from None
        if v.shape != (4, 2):
            raise InputError("reach", self.vertices, "4 vertices [[x, y], ...] [m], shape (4, 2)")
        if not np.all(np.isfinite(v)):
            raise InputError("reach", v.tolist(), "finite vertex coordinates")
        if np.any(v[:, 1] <= 0.0):
            # The stored trapezoid is for the left swing foot: it must stay on the left of the
            # right stance foot, otherwise the legs would cross.
            raise InputError(
                "reach", v.tolist(), "every vertex with y > 0 (left of a right stance foot)"
            )
        area = signed_area(v)
        if abs(area) <= 1e-6:
            raise InputError("reach", v.tolist(), "a polygon with non-zero area")
        if area < 0.0:
            v = v[::-1].copy()
        defect = convexity_defect(v)
        if defect is not None:
            raise InputError("reach", v.tolist(), f"a convex polygon, but {defect}")
        v.setflags(write=False)
        object.__setattr__(self, "vertices", v)

    @property
    def radius(self) -> float:
        """The longest step [m]: distance of the farthest vertex from the stance foot (any heading)."""
        return float(np.max(np.linalg.norm(self.vertices, axis=1)))

    def for_stance(self, stance: Side) -> FloatArray:
        """CCW vertices (4, 2) [m] of the reachable set when ``stance`` is the standing foot.

        For a LEFT stance foot the trapezoid is mirrored (y -> -y); mirroring flips the orientation,
        so the order is reversed to stay counter-clockwise.
        """
        if Side(stance) is Side.RIGHT:
            return np.array(self.vertices)
        mirrored = self.vertices * np.array([1.0, -1.0])
        return np.array(mirrored[::-1])

    def halfspaces(self, stance: Side) -> tuple[FloatArray, FloatArray]:
        """Half-spaces ``G q <= h`` of the reachable set for ``stance`` (eq. 5.12f).

        ``q`` (2,) [m] is the next footstep relative to the stance foot, in its heading frame.

        Returns:
            ``(G, h)`` of shapes (4, 2) and (4,); rows of ``G`` are outward unit normals.
        """
        return outward_halfspaces(self.for_stance(stance))

    def contains(self, q: ArrayLike, stance: Side, tol: float = 1e-9) -> bool:
        """Whether the relative position ``q`` (2,) [m] is reachable from a ``stance`` foot."""
        g, h = self.halfspaces(stance)
        return bool(np.all(g @ np.asarray(q, dtype=float)[:2] - h <= tol))


#: most ALIP nodes K per single support (the problem grows linearly in K; the document uses 5)
MAX_NODES = 50
#: physical range of each parameter (and its unit): a 10 g toy to a 100 t machine. Beyond it the
#: models' products underflow or overflow (m z_H squared is 0 for m = 1e-300)
RANGES: dict[str, tuple[float, float, str]] = {
    "mass": (1e-2, 1e5, "kg"),
    "com_height": (1e-2, 1e2, "m"),
    "t_ss": (1e-3, 60.0, "s"),
    "t_ds": (1e-3, 60.0, "s"),
    "u_max": (1e-6, 1e7, "N m"),
    "stance_width": (1e-4, 1e2, "m"),
    "step_height_max": (1e-6, 1e2, "m"),
    "foot_length": (1e-4, 1e2, "m"),
    "foot_width": (1e-4, 1e2, "m"),
    "g": (1e-2, 1e3, "m/s^2"),
}
#: longest single or double support in time constants 1 / omega = sqrt(z_H / g) (the ALIP's
#: matrices hold cosh(omega T): beyond ~20 its foot placement has no significant digit left)
MAX_TIME_CONSTANTS = 20.0


@dataclass(frozen=True, eq=False)
class BipedParams:
    """Everything the footstep planners need to know about the biped.

    Attributes:
        mass: total mass m [kg].
        com_height: CoM height z_H above the stance foot [m].
        t_ss: single-support duration T_ss [s].
        t_ds: double-support duration T_ds [s] (reset map, eq. 5.8-5.10).
        n_nodes: number K of ALIP nodes per single support (eq. 5.12a), >= 2.
        u_max: ankle-torque bound U_max [N m] (eq. 5.12d).
        reach: reachable set of the next footstep (eq. 5.12f).
        theta_max: maximum heading change per step [rad] (eq. 5.12e), in [0, pi].
        stance_width: nominal lateral distance between the feet [m]; must lie inside the reach
            trapezoid straight beside the stance foot (x = 0).
        step_height_max: bound on ``|z_{i+1} - z_i|`` between consecutive footsteps [m].
        foot_length: sole length [m].
        foot_width: sole width [m].
        g: gravity [m/s^2].
    """

    mass: float = 32.0
    com_height: float = 0.60
    t_ss: float = 0.40
    t_ds: float = 0.10
    n_nodes: int = 5
    u_max: float = 30.0
    reach: ReachTrapezoid = field(default_factory=ReachTrapezoid)
    theta_max: float = math.radians(30.0)
    stance_width: float = 0.20
    step_height_max: float = 0.25
    foot_length: float = 0.20
    foot_width: float = 0.10
    g: float = GRAVITY

    def __post_init__(self) -> None:
        for name, (lo, hi, unit) in RANGES.items():
            object.__setattr__(self, name, in_range(name, getattr(self, name), lo, hi, unit))
        omega = math.sqrt(self.g / self.com_height)
        for name in ("t_ss", "t_ds"):
            if omega * getattr(self, name) > MAX_TIME_CONSTANTS:
                longest = MAX_TIME_CONSTANTS / omega
                raise InputError(
                    name,
                    getattr(self, name),
                    f"at most {longest:.3g} s ({MAX_TIME_CONSTANTS:g} time constants "
                    "sqrt(com_height / g) of this robot)",
                )
        n = self.n_nodes
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 2 <= n <= MAX_NODES:
            raise InputError(
                "n_nodes", n, f"an integer in 2..{MAX_NODES} (nodes per single support)"
            )
        object.__setattr__(self, "n_nodes", int(n))
        theta = self.theta_max
        if isinstance(theta, bool) or not isinstance(theta, int | float | np.integer | np.floating):
            raise InputError("theta_max", theta, "an angle in [0, pi] [rad]")
        if not (math.isfinite(float(theta)) and 0.0 <= float(theta) <= math.pi):
            raise InputError("theta_max", theta, "an angle in [0, pi] [rad]")
        object.__setattr__(self, "theta_max", float(theta))
        if not isinstance(self.reach, ReachTrapezoid):
            object.__setattr__(self, "reach", ReachTrapezoid(np.asarray(self.reach)))
        # The nominal stance (feet side by side) must itself be a reachable step, otherwise the
        # robot could not even stand still in place.
        if not self.reach.contains((0.0, self.stance_width), Side.RIGHT):
            raise InputError(
                "stance_width",
                self.stance_width,
                "a lateral distance inside the reach trapezoid at x = 0",
            )

    @property
    def node_dt(self) -> float:
        """Time between ALIP nodes ``T_ss / (K - 1)`` [s]."""
        return self.t_ss / (self.n_nodes - 1)

    def alip(self) -> ALIP:
        """The ALIP model (eq. 5.1-5.10) of this robot."""
        return ALIP(self.mass, self.com_height, self.g)
