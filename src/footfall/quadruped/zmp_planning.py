"""ZMP planning for the walk gait, document 001 sec. 1.3 (fig. 3-4).

In a walk gait three legs support the body while the fourth swings, so the ZMP must lie in the
support triangle of the stance legs (eq. 8). Putting it at the incentre of every triangle
maximises the margin but makes the body move before every swing. The document's idea: swing the
legs in the order RH-RF-LH-LF so that two consecutive swings (RH then RF, LH then LF) share two
stance legs (the "main support edge"). The two support triangles then overlap in the
*suboptimal support triangle* A-D-I with ``I = BD ∩ AC1`` (fig. 4: A, B, C, D = LF, RF, RH, LH,
C1 = RH after its swing); its incentre, the *optimal stability point* (OSP), is inside both
triangles, so one body shift serves two swings.

With the conventional transverse order LF-RH-RF-LH, consecutive swings share a *diagonal* pair of
stance legs and their triangles only meet on that diagonal, so the trick cannot apply; that order
is planned with the incentre of each actual triangle.
"""

from __future__ import annotations

from enum import Enum

from numpy.typing import ArrayLike

from footfall._typing import FloatArray
from footfall.errors import InfeasibleError
from footfall.quadruped.robot import Leg
from footfall.quadruped.stability import clip_convex, incentre, line_intersection


class ZmpStrategy(str, Enum):
    """Where the ZMP is put before each swing (sec. 1.3)."""

    #: document's method: OSP of the suboptimal triangle, one body shift per pair of swings
    OSP = "osp"
    #: incentre of each actual support triangle, order RH-RF-LH-LF, one shift per swing
    INCENTRE = "incentre"
    #: conventional transverse walk LF-RH-RF-LH with the incentre of each support triangle
    TRANSVERSE = "transverse"


#: the document's walk order for the OSP method (sec. 1.3)
OSP_ORDER: tuple[Leg, ...] = (Leg.RH, Leg.RF, Leg.LH, Leg.LF)
#: the transverse walk order (sec. 1.3, ref. [11])
TRANSVERSE_ORDER: tuple[Leg, ...] = (Leg.LF, Leg.RH, Leg.RF, Leg.LH)


def swing_order(strategy: ZmpStrategy) -> tuple[Leg, ...]:
    """Legs in swing order within one gait cycle."""
    return TRANSVERSE_ORDER if strategy is ZmpStrategy.TRANSVERSE else OSP_ORDER


def swing_groups(strategy: ZmpStrategy) -> tuple[tuple[Leg, ...], ...]:
    """Swings served by one body shift: pairs for the OSP method, single swings otherwise."""
    order = swing_order(strategy)
    if strategy is ZmpStrategy.OSP:
        return (order[0:2], order[2:4])
    return tuple((leg,) for leg in order)


def document_point_i(a: ArrayLike, b: ArrayLike, d: ArrayLike, c1: ArrayLike) -> FloatArray:
    """The document's vertex ``I = BD ∩ AC1`` of the suboptimal triangle (fig. 4), shape (2,)."""
    return line_intersection(b, d, a, c1)


def suboptimal_triangle(first: ArrayLike, second: ArrayLike) -> FloatArray:
    """Common part of the support triangles of two consecutive swings (sec. 1.3, fig. 4).

    For the document's case the first triangle is A-B-D (RH swinging), the second A-C1-D (RF
    swinging) and the common part is the triangle A-D-I with ``I = BD ∩ AC1``.

    Args:
        first: support triangle during the first swing, shape (3, 2) [m].
        second: support triangle during the second swing, shape (3, 2) [m].

    Returns:
        The suboptimal triangle, counter-clockwise, shape (3, 2) [m].

    Raises:
        InfeasibleError: the triangles do not overlap in a triangle (e.g. they only share a
            diagonal, as in the transverse order).
    """
    common = clip_convex(first, second)
    if common.shape[0] != 3:
        raise InfeasibleError(
            f"support triangles overlap in {common.shape[0]} vertices, not a triangle; "
            "the swing pair does not share a main support edge"
        )
    return common


def optimal_stability_point(first: ArrayLike, second: ArrayLike) -> tuple[FloatArray, float]:
    """OSP = incentre of the suboptimal triangle and its margin (inradius) [m] (sec. 1.3)."""
    return incentre(suboptimal_triangle(first, second))


def zmp_target(triangles: list[FloatArray]) -> tuple[FloatArray, float]:
    """ZMP target for a group of swings served by one body shift and its planned margin.

    One triangle: its incentre (largest margin, eq. 8). Two triangles: the OSP.
    """
    if len(triangles) == 1:
        return incentre(triangles[0])
    if len(triangles) == 2:
        return optimal_stability_point(triangles[0], triangles[1])
    raise InfeasibleError(f"a body shift can serve one or two swings, not {len(triangles)}")
