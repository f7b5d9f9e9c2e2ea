"""A lower bound on the footsteps N of the MIQCQP planner's model, from reachable sets (no solve).

The smallest-N search (:func:`footfall.planning.plan_min_steps`) used to prove every N from the
distance bound up infeasible with a branch and bound, minutes per N. :func:`reachable_steps_bound`
rules most of those N out by geometry alone, from the very rows of the planner's model
(:mod:`footfall.planning.miqcqp`), relaxed so that what remains is a set propagation:

* footstep 0 is the stance foot ``p_0``; the last two footsteps are the goal feet at the goal
  heading (``_add_goal``);
* every footstep ``i >= 1`` lies in one region's polygon moved in by ``region_margin``
  (eq. 5.12i-j, 5.18) and on its plane (eq. 5.15-5.17), so its height lies in that region's
  height range; ``|z_{i+1} - z_i| <= step_height_max``;
* the heading ``theta_i`` lies in one segment ``[phi_l, phi_{l+1}]`` of
  ``[theta_0 - pi, theta_0 + pi]`` (eq. 5.12j-k, 5.14) and ``|theta_{i+1} - theta_i| <=
  theta_max`` (eq. 5.12e);
* the step ``p_{i+1} - p_i`` lies in the reach set of eq. (5.12f) as the model imposes it: for
  ``i = 0`` the trapezoid turned by ``theta_0``; for ``i >= 1`` the linear rows of the active
  segment, ``P_l = Rot(phi_l) T' ∩ Rot(phi_{l+1}) T'`` (``T'``: the trapezoid with its positive
  bounds shrunk by ``cos(pi / L)``), which do not depend on ``theta_i`` inside the segment; with
  ``reach_both_frames`` also ``P`` of the landing foot's segment;
* with ``swing_max``, ``p_{i+1} - p_{i-1}`` lies in the inscribed ``SWING_SIDES``-gon.

The ALIP dynamics, torque bound, sin/cos rows and objective are dropped. Headings are tracked in
*buckets* of consecutive segments (at most ``MAX_BUCKETS``; each a union of whole segments), and
for each footstep ``i``, bucket ``b`` and region ``r`` a convex polygon ``S_i[b, r]`` is kept that
contains every position ``p_i`` any sequence of footsteps 0..i satisfying the rows above can have
with ``theta_i`` in ``b`` and ``p_i`` in ``r``:

    S_{i+1}[b', r'] ⊇ hull( ∪_{b ~ b', r ~ r'} (S_i[b, r] ⊕ step(b, b')) ∩ region(r') ),

with ``b ~ b'`` when the buckets come within ``theta_max`` of each other, ``r ~ r'`` when their
height ranges come within ``step_height_max``, ``step(b, b')`` the hull of the ``P_l`` of the
segments of ``b`` (intersected with those of ``b'`` under ``reach_both_frames``), and then cut by
the swing polygon around the footstep ``i - 1`` sets. Each operation (convex hull, Minkowski sum,
intersection with rows loosened by ``SLACK``) only enlarges a set, so by induction each ``S_i``
contains every position the model allows.

A plan with N footsteps puts footstep N - 1 on its goal foot at the goal heading, so N is ruled out
unless that foot lies in some ``S_{N-1}[b, r]`` with ``b`` holding the goal heading (and the last
step, its region and its swing pass the same rows). The smallest N that is not ruled out is
therefore a valid lower bound on every N the planner's model can solve: the search may start
there without skipping any feasible N. It is a bound for the *planner's model* (its conservative
linear reach), exactly what the search proves infeasible.

Live members (:func:`live_members`). For a given N the same rows run backward from the goal feet
give sets ``B_i[b, r]`` holding every position of footstep ``i`` from which the goal can still be
reached in the remaining steps (Minkowski sums with the reversed step sets, cut by the regions).
A heading bucket or region that footstep ``i`` can use must have ``S_i[b, r]`` meet ``B_i[b, r]``;
the segments and regions of no such pair are used by no plan of the model, and the smallest-N
search fixes their binaries to 0 before it solves (the same feasible set; the walk plans' node
problems shrink by about a third and their searches by 3-20x, ``benchmarks/RESULTS.md``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from functools import partial

import numpy as np
from numpy.typing import NDArray

from footfall._geometry import (
    EDGE_TOL,
    clip_rows,
    convex_hull,
    distance_to_convex,
    minkowski_sum,
    rot2,
)
from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import (
    SWING_SIDES,
    PlannerOptions,
    check_n_steps,
    check_planning_arguments,
    goal_feet,
    wrap_near,
)
from footfall.terrain.scene import Scene

#: slack [m] added to every row the sets are cut by, and to every membership test: the sets stay
#: supersets of the model's despite rounding, and of plans a solver accepts within its tolerances
SLACK = 1e-4
#: slack [rad] on the heading rows (rate, segment membership)
ANGLE_SLACK = 1e-6
#: most heading buckets (a bucket is a run of consecutive segments; fewer buckets: faster, weaker;
#: 16 buckets of 22.5 deg gave the same bounds as 32 on the built-in scenes but one, in half the
#: time)
MAX_BUCKETS = 16
#: half-width [m] of the square every polygon given by rows alone is cut from (reach sets and
#: regions are bounded, so this only has to be larger than any of them)
_BOX = 1e4


@dataclass(frozen=True)
class StepsBound:
    """A lower bound on the footsteps N of the planner's model (:func:`reachable_steps_bound`).

    Attributes:
        n_steps: the smallest N not ruled out; ``horizon + 1`` when every N up to ``horizon`` is.
        horizon: the largest N examined.
        reason: one sentence saying what rules out the N below ``n_steps``.
    """

    n_steps: int
    horizon: int
    reason: str

    @property
    def exhausted(self) -> bool:
        """Whether every N up to ``horizon`` was ruled out."""
        return self.n_steps > self.horizon


def _rows_polygon(a: FloatArray, b: FloatArray) -> FloatArray:
    """The polygon ``{q : a q <= b + SLACK}`` (V, 2), (0, 2) when empty; must be bounded."""
    box = _BOX * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    return convex_hull(clip_rows(box, a, b + SLACK)) if len(a) else box


def _rows_of(poly: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Outward rows ``a q <= b`` (V, 2), (V,) of a convex CCW polygon with at least 3 vertices."""
    edges = np.roll(poly, -1, axis=0) - poly
    length = np.linalg.norm(edges, axis=1)
    # a (near-)repeated vertex has no reliable edge direction to cut by; leaving its row out
    # keeps a superset (the other rows of a convex polygon still bound it)
    keep = length > EDGE_TOL
    normals = np.stack([edges[keep, 1], -edges[keep, 0]], axis=1) / length[keep, None]
    return normals, np.einsum("ij,ij->i", normals, poly[keep])


def _segment_reach(robot: BipedParams, side: Side, phi_a: float, phi_b: float) -> FloatArray:
    """``P_l`` (V, 2) [m]: the steps the linear reach rows of eq. (5.12f) allow from a ``side``
    stance foot whose heading lies in the segment ``[phi_a, phi_b]`` (miqcqp ``_add_reach``)."""
    g, h = robot.reach.halfspaces(side)
    half = 0.5 * (phi_b - phi_a)
    h_eff = np.where(h > 0.0, h * math.cos(half), h)
    rows = np.vstack([g @ rot2(phi_a).T, g @ rot2(phi_b).T])
    return _rows_polygon(rows, np.concatenate([h_eff, h_eff]))


@dataclass(frozen=True)
class _Setup:
    """The rows of the model that the propagation uses (see the module docstring)."""

    sides: tuple[Side, ...]
    theta0: float
    #: bucket b holds headings [lo[b], hi[b]] [rad]
    lo: FloatArray
    hi: FloatArray
    #: step polygons per side and bucket (None: empty)
    step: dict[Side, list[FloatArray | None]]
    #: first step (footstep 0 -> 1) per side of footstep 0: the trapezoid turned by theta_0
    first: FloatArray
    #: region rows (with margin and slack), polygons and height ranges [m]
    region_rows: list[tuple[FloatArray, FloatArray]]
    region_poly: list[FloatArray]
    z_range: list[tuple[float, float]]
    swing: FloatArray | None
    p0: FloatArray
    z0: float
    swing_from: FloatArray
    theta_goal: float
    feet: dict[Side, FloatArray]
    #: memo of :func:`_both_frames_step`
    pair_steps: dict[tuple[Side, int, int], FloatArray | None] = field(default_factory=dict)
    #: the regions' boxes (lower and upper corners, (R, 2)) and height ranges ((R,) each)
    boxes: tuple[FloatArray, FloatArray, FloatArray, FloatArray] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        # the regions' bounding boxes and height ranges as arrays: a set is tested against all
        # of them at once (a scene may hold 1000 regions; a loop per region and set was most of
        # the search's time), and only the regions it can meet are cut
        n = len(self.region_poly)
        lo, hi = np.full((n, 2), np.inf), np.full((n, 2), -np.inf)
        for r, poly in enumerate(self.region_poly):
            if poly.shape[0]:
                lo[r], hi[r] = poly.min(axis=0), poly.max(axis=0)
        zr = np.array(self.z_range, dtype=float).reshape(n, 2)
        zr[~np.isfinite(zr).all(axis=1)] = 0.0  # an empty region: its infinite box excludes it
        object.__setattr__(self, "boxes", (lo, hi, zr[:, 0], zr[:, 1]))

    def regions_near(
        self, lo: FloatArray, hi: FloatArray, z_lo: float, z_hi: float, dz: float
    ) -> NDArray[np.int64]:
        """Indices (ascending) of the non-empty regions whose box comes within ``SLACK`` of the
        box ``[lo, hi]`` [m] and whose height range within ``dz`` [m] of ``[z_lo, z_hi]``: every
        region a set in that box can meet within a step height (a superset)."""
        r_lo, r_hi, rz_lo, rz_hi = self.boxes
        gap_z = np.maximum(0.0, np.maximum(rz_lo - z_hi, z_lo - rz_hi))
        ok = np.all(r_lo <= hi + SLACK, axis=1) & np.all(r_hi >= lo - SLACK, axis=1) & (gap_z <= dz)
        return np.flatnonzero(ok)


def _setup(scene: Scene, robot: BipedParams, options: PlannerOptions, horizon: int) -> _Setup:
    start = scene.start
    theta0 = float(start.heading)
    n_seg = options.heading_segments
    breaks = theta0 - math.pi + 2.0 * math.pi * np.arange(n_seg + 1) / n_seg
    firsts, lasts = _bucket_segments(n_seg)
    step: dict[Side, list[FloatArray | None]] = {}
    for side in (Side.LEFT, Side.RIGHT):
        buckets: list[FloatArray | None] = []
        for f, last in zip(firsts, lasts, strict=True):
            parts = [_segment_reach(robot, side, breaks[k], breaks[k + 1]) for k in range(f, last)]
            parts = [q for q in parts if q.shape[0] > 0]
            buckets.append(convex_hull(np.vstack(parts)) if parts else None)
        step[side] = buckets
    g, h = robot.reach.halfspaces(start.stance)
    first = _rows_polygon(g @ rot2(theta0).T, h)
    rows, polys, zr = [], [], []
    for region in scene.terrain:
        a, b = region.halfspaces()
        b_eff = b - options.region_margin + SLACK
        rows.append((a, b_eff))
        poly = _rows_polygon(a, b - options.region_margin)
        polys.append(poly)
        z = np.asarray(region.height_at(poly)) if poly.shape[0] else np.zeros(0)
        zr.append((float(z.min()), float(z.max())) if z.size else (math.inf, -math.inf))
    swing = None
    if options.swing_max is not None:
        phis = 2.0 * math.pi * np.arange(SWING_SIDES) / SWING_SIDES
        normals = np.stack([np.cos(phis), np.sin(phis)], axis=1)
        rhs = np.full(SWING_SIDES, options.swing_max * math.cos(math.pi / SWING_SIDES))
        swing = _rows_polygon(normals, rhs)
    sides = [start.stance]
    for _ in range(horizon + 1):
        sides.append(sides[-1].other)
    theta_goal = wrap_near(float(scene.goal.heading), theta0)
    p0 = np.asarray(start.foot(start.stance), dtype=float)
    return _Setup(
        sides=tuple(sides),
        theta0=theta0,
        lo=np.array([breaks[f] for f in firsts]),
        hi=np.array([breaks[last] for last in lasts]),
        step=step,
        first=first,
        region_rows=rows,
        region_poly=polys,
        z_range=zr,
        swing=swing,
        p0=p0[:2],
        z0=float(p0[2]),
        swing_from=np.asarray(start.foot(sides[1]), dtype=float)[:2],
        theta_goal=theta_goal,
        feet=goal_feet(robot, scene.goal.position[:2], theta_goal),
    )


def _gap(lo_a: float, hi_a: float, lo_b: float, hi_b: float) -> float:
    """Distance between the intervals [lo_a, hi_a] and [lo_b, hi_b] (0 when they overlap)."""
    return max(lo_b - hi_a, lo_a - hi_b, 0.0)


def _near(poly: FloatArray, x: FloatArray) -> bool:
    return distance_to_convex(x, poly) <= SLACK


def _regions_at(s: _Setup, x: FloatArray) -> list[int]:
    """The regions (their polygons with the margin) within ``SLACK`` of the point ``x`` [m]."""
    near = s.regions_near(x, x, -math.inf, math.inf, math.inf)
    return [int(r) for r in near if _near(s.region_poly[r], x)]


_Sets = dict[tuple[int, int], FloatArray]


def _first_sets(s: _Setup, robot: BipedParams, both: bool) -> _Sets:
    """``S_1``: footstep 1 from the fixed stance foot at heading theta_0."""
    theta0 = s.theta0
    side = s.sides[0]
    out: _Sets = {}
    for b in range(len(s.lo)):
        if _gap(theta0, theta0, s.lo[b], s.hi[b]) > robot.theta_max + ANGLE_SLACK:
            continue
        step = s.first
        if both:
            other = s.step[side][b]
            if other is None:
                continue
            # a degenerate set has no rows to cut by: keep the larger step (still a superset)
            step = clip_rows(step, *_rows_of(other)) if other.shape[0] >= 3 else step
        if step.shape[0] == 0:
            continue
        reach = s.p0 + step
        if s.swing is not None:
            reach = clip_rows(reach, *_shifted_rows(s.swing, s.swing_from))
        if reach.shape[0] == 0:
            continue
        near = s.regions_near(
            reach.min(axis=0), reach.max(axis=0), s.z0, s.z0, robot.step_height_max + SLACK
        )
        for r in near:
            piece = clip_rows(reach, *s.region_rows[r])
            if piece.shape[0]:
                out[(b, r)] = convex_hull(piece)
    return out


def _shifted_rows(poly: FloatArray, shift: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Rows (with ``SLACK``) of the convex polygon ``poly + shift``."""
    a, b = _rows_of(poly)
    return a, b + a @ shift + SLACK


def _next_sets(
    s: _Setup, robot: BipedParams, both: bool, i: int, cur: _Sets, before: list[FloatArray]
) -> _Sets:
    """``S_{i+1}`` from ``S_i`` (``cur``) and the footstep ``i - 1`` sets ``before`` (per region)."""
    side = s.sides[i]
    n_b = len(s.lo)
    swing_rows = (
        [_rows_of(minkowski_sum(p, s.swing)) for p in before] if s.swing is not None else []
    )
    gathered: dict[tuple[int, int], list[FloatArray]] = {}
    for (b, r), piece in cur.items():
        step_b = s.step[side][b]
        if step_b is None:
            continue
        # without the landing frame the step set does not depend on the next bucket: the cuts
        # into the regions are made once and shared by every bucket b2 within reach of b
        plain = None if both else _cuts(s, robot, r, minkowski_sum(piece, step_b))
        for b2 in range(n_b):
            if _gap(s.lo[b], s.hi[b], s.lo[b2], s.hi[b2]) > robot.theta_max + ANGLE_SLACK:
                continue
            cuts = plain
            if cuts is None:
                step = _both_frames_step(s, side, b, b2)
                if step is None:
                    continue
                cuts = _cuts(s, robot, r, minkowski_sum(piece, step))
            for r2, cut in cuts:
                gathered.setdefault((b2, r2), []).append(cut)
    out: _Sets = {}
    for key, parts in gathered.items():
        hull = convex_hull(np.vstack(parts))
        if swing_rows:
            kept = [clip_rows(hull, a, rhs + SLACK) for a, rhs in swing_rows]
            kept = [k for k in kept if k.shape[0]]
            if not kept:
                continue
            hull = convex_hull(np.vstack(kept))
        out[key] = hull
    return out


def _cuts(s: _Setup, robot: BipedParams, r: int, moved: FloatArray) -> list[tuple[int, FloatArray]]:
    """The non-empty parts ``(r2, moved ∩ region r2)`` of the regions a footstep in region ``r``
    can step to (height ranges within ``step_height_max``)."""
    near = s.regions_near(
        moved.min(axis=0), moved.max(axis=0), *s.z_range[r], robot.step_height_max + SLACK
    )
    out = []
    for r2 in near:
        cut = clip_rows(moved, *s.region_rows[r2])
        if cut.shape[0]:
            out.append((int(r2), cut))
    return out


def _both_frames_step(s: _Setup, side: Side, b: int, b2: int) -> FloatArray | None:
    """The steps from a ``side`` stance foot with heading in bucket ``b`` that also lie in the
    reach set of the landing heading's bucket ``b2`` (``reach_both_frames``); memoised."""
    key = (side, b, b2)
    if key not in s.pair_steps:
        step_b, step_2 = s.step[side][b], s.step[side][b2]
        step = None
        if step_b is not None and step_2 is not None:
            # a degenerate set has no rows to cut by: keep the larger step_b (still a superset)
            cut = clip_rows(step_b, *_rows_of(step_2)) if step_2.shape[0] >= 3 else step_b
            step = cut if cut.shape[0] else None
        s.pair_steps[key] = step
    return s.pair_steps[key]


def _per_region(sets: _Sets) -> list[FloatArray]:
    """The union over heading buckets of each region's set, as one hull per region."""
    parts: dict[int, list[FloatArray]] = {}
    for (_, r), piece in sets.items():
        parts.setdefault(r, []).append(piece)
    return [convex_hull(np.vstack(p)) for p in parts.values()]


def _goal_reached(
    s: _Setup, robot: BipedParams, sets: _Sets, before: list[FloatArray], n: int
) -> bool:
    """Whether footstep N - 1 (``sets``) can be the goal foot and footstep N the other (N = n)."""
    side_a, side_b = s.sides[n - 1], s.sides[n]
    g_a, g_b = s.feet[side_a], s.feet[side_b]
    tg = s.theta_goal
    regions_b = _regions_at(s, g_b)
    if s.swing is not None and not any(_near(minkowski_sum(p, s.swing), g_b) for p in before):
        return False
    for (b, r), piece in sets.items():
        if not s.lo[b] - ANGLE_SLACK <= tg <= s.hi[b] + ANGLE_SLACK or not _near(piece, g_a):
            continue
        step = s.step[side_a][b]
        if step is None or not _near(step, g_b - g_a):
            continue
        if any(
            _gap(*s.z_range[r], *s.z_range[r2]) <= robot.step_height_max + SLACK for r2 in regions_b
        ):
            return True
    return False


def footstep_sets(
    scene: Scene, robot: BipedParams, options: PlannerOptions, horizon: int
) -> Iterator[tuple[int, _Sets, Callable[[int], bool]]]:
    """The reachable sets of footsteps 1, 2, ..., ``horizon - 1`` (module docstring).

    Yields:
        ``(i, sets, goal)``: ``sets[(b, r)]`` is the convex polygon (V, 2) [m] holding every
        position of footstep ``i`` with its heading in bucket ``b`` (``bucket_bounds``) and its
        region ``scene.terrain[r]``; ``goal(n)`` (for ``n = i + 1``) says whether footstep
        ``n - 1 = i`` can be the goal foot of a plan with ``n`` footsteps.
    """
    s = _setup(scene, robot, options, horizon)
    both = options.reach_both_frames
    history: list[list[FloatArray]] = [[s.p0[None, :]]]
    sets = _first_sets(s, robot, both)
    for i in range(1, horizon):
        before = history[-1]
        yield i, sets, partial(_goal_reached, s, robot, sets, before)
        if not sets:
            return
        history.append(_per_region(sets))
        sets = _next_sets(s, robot, both, i, sets, history[-2])


def bucket_bounds(options: PlannerOptions, theta0: float) -> tuple[FloatArray, FloatArray]:
    """Heading intervals ``[lo[b], hi[b]]`` [rad] of the buckets of :func:`footstep_sets` for a
    start heading ``theta0`` [rad]: runs of consecutive segments of eq. (5.12g-h)."""
    n_seg = options.heading_segments
    breaks = theta0 - math.pi + 2.0 * math.pi * np.arange(n_seg + 1) / n_seg
    firsts, lasts = _bucket_segments(n_seg)
    return breaks[firsts], breaks[lasts]


def _bucket_segments(n_seg: int) -> tuple[list[int], list[int]]:
    """First and one-past-last segment of each heading bucket (at most ``MAX_BUCKETS``)."""
    per = math.ceil(n_seg / MAX_BUCKETS)
    firsts = list(range(0, n_seg, per))
    return firsts, [min(f + per, n_seg) for f in firsts]


class ForwardSets:
    """The reachable sets of :func:`footstep_sets`, computed as far as asked and kept: the
    smallest-N search shares them between its bound and the live members of every N it tries."""

    def __init__(
        self, scene: Scene, robot: BipedParams, options: PlannerOptions, horizon: int
    ) -> None:
        self.horizon = horizon
        self._gen = footstep_sets(scene, robot, options, horizon)
        self._done: list[tuple[int, _Sets, Callable[[int], bool]]] = []
        self._ended = False

    def check_reaches(self, horizon: int) -> None:
        """Refuse to serve a caller that needs the sets up to ``horizon``, beyond this one's:
        sets cut short by the horizon would read as footsteps that cannot be placed."""
        if self.horizon < horizon:
            raise InputError("forward", self.horizon, f"reachable sets with a horizon >= {horizon}")

    def upto(self, last: int) -> Iterator[tuple[int, _Sets, Callable[[int], bool]]]:
        """``(i, sets, goal)`` of :func:`footstep_sets` for i = 1..``last`` (fewer when the
        sets run out or ``last`` passes the horizon)."""
        k = 0
        while k < last:
            if k == len(self._done):
                if self._ended:
                    return
                nxt = next(self._gen, None)
                if nxt is None:
                    self._ended = True
                    return
                self._done.append(nxt)
            yield self._done[k]
            k += 1


def reachable_steps_bound(
    scene: Scene,
    robot: BipedParams,
    options: PlannerOptions,
    horizon: int,
    forward: ForwardSets | None = None,
    deadline: float = math.inf,
) -> StepsBound:
    """The smallest N in 2..``horizon`` that the reachable sets do not rule out (module
    docstring), or ``horizon + 1`` if they rule out all of them.

    Args:
        scene: terrain, start and goal.
        robot: the planner's robot parameters (reach, theta_max, step_height_max, stance width).
        options: the planner options whose rows are used: ``heading_segments`` (L),
            ``region_margin``, ``reach_both_frames``, ``swing_max``.
        horizon: the largest N to examine (the work grows linearly with it).
        forward: the reachable sets of these arguments to use (and extend), e.g. shared with
            :func:`live_members`; its horizon must be at least ``horizon``.
        deadline: ``time.perf_counter()`` value past which :class:`TimeoutError` is raised
            (between two footsteps' sets; those computed are kept in ``forward``).

    Returns:
        A :class:`StepsBound`; every N below ``n_steps`` has no plan in the planner's model.
    """
    what = (
        f"reachable sets from the reach rows of eq. 5.12f with L = {options.heading_segments} "
        "heading segments, the heading rate (5.12e), the step height and the regions"
        + (f" {options.region_margin:g} m inside" if options.region_margin > 0 else "")
        + (f", swings of at most {options.swing_max:g} m" if options.swing_max is not None else "")
    )
    if forward is None:
        forward = ForwardSets(scene, robot, options, horizon)
    forward.check_reaches(horizon)
    for i, sets, goal in forward.upto(horizon - 1):
        _check_clock(deadline)
        n = i + 1  # footstep N - 1 = i must be the goal foot
        if not sets:
            return StepsBound(horizon + 1, horizon, f"no footstep {i} can be placed: {what}")
        if goal(n):
            return StepsBound(n, horizon, f"no footstep N - 1 can be the goal foot: {what}")
    return StepsBound(
        horizon + 1, horizon, f"no footstep N - 1 <= {horizon - 1} can be the goal foot: {what}"
    )


def _meet(p: FloatArray, q: FloatArray) -> bool:
    """Whether the convex polygons (or points, or segments) ``p`` and ``q`` come within
    ``SLACK`` of each other; True when neither has an area to cut by (a superset answer)."""
    if p.shape[0] == 0 or q.shape[0] == 0:
        return False
    if q.shape[0] >= 3:
        a, b = _rows_of(q)
        return clip_rows(p, a, b + SLACK).shape[0] > 0
    if p.shape[0] >= 3:
        a, b = _rows_of(p)
        return clip_rows(q, a, b + SLACK).shape[0] > 0
    return True


class BackwardSets:
    """The backward sets of :func:`live_members`, computed as far as asked and kept.

    ``B`` at ``j`` steps before the goal foot (footstep N - 1) depends on N only through the
    goal foot's side: level ``j`` holds, per heading bucket and region, a convex polygon with
    every position of footstep ``N - 1 - j`` from which the goal feet can still be reached by
    the reach, heading-rate, step-height and region rows (swings dropped: a superset). So the
    smallest-N search extends two chains (one per side of the goal foot) instead of computing
    every N's sets anew; a level cut short by a deadline is dropped, the finished ones kept."""

    def __init__(self, scene: Scene, robot: BipedParams, options: PlannerOptions) -> None:
        self.s = _setup(scene, robot, options, 1)
        self.robot = robot
        self.both = options.reach_both_frames
        #: per side of the goal foot: level 0 (the goal foot at the goal heading), 1, 2, ...
        self.chains: dict[Side, list[_Sets]] = {}

    def levels(self, side_a: Side, count: int, deadline: float = math.inf) -> list[_Sets]:
        """Levels 1..``count`` of the chain whose goal foot is on ``side_a``.

        Raises:
            TimeoutError: ``time.perf_counter()`` passed ``deadline`` first.
        """
        s = self.s
        chain = self.chains.get(side_a)
        if chain is None:
            g_a = s.feet[side_a]
            goal: _Sets = {}
            for b in range(len(s.lo)):
                if s.lo[b] - ANGLE_SLACK <= s.theta_goal <= s.hi[b] + ANGLE_SLACK:
                    for r in _regions_at(s, g_a):
                        goal[(b, r)] = g_a[None, :]
            chain = self.chains[side_a] = [goal]
        while len(chain) <= count:
            # level j is footstep N - 1 - j, whose stance side alternates from the goal foot's
            side = side_a if len(chain) % 2 == 0 else side_a.other
            chain.append(self._step_back(chain[-1], side, deadline))
        return chain[1 : count + 1]

    def _step_back(self, cur: _Sets, side: Side, deadline: float) -> _Sets:
        """The sets one footstep before ``cur``, whose stance foot is on ``side``."""
        s, robot = self.s, self.robot
        gathered: dict[tuple[int, int], list[FloatArray]] = {}
        for (b2, r2), piece in cur.items():
            _check_clock(deadline)
            for b in range(len(s.lo)):
                if _gap(s.lo[b], s.hi[b], s.lo[b2], s.hi[b2]) > robot.theta_max + ANGLE_SLACK:
                    continue
                step = _both_frames_step(s, side, b, b2) if self.both else s.step[side][b]
                if step is None:
                    continue
                for r, cut in _cuts(s, robot, r2, minkowski_sum(piece, -step)):
                    gathered.setdefault((b, r), []).append(cut)
        return {key: convex_hull(np.vstack(parts)) for key, parts in gathered.items()}


def _check_clock(deadline: float) -> None:
    """Raise :class:`TimeoutError` once ``time.perf_counter()`` has passed ``deadline``."""
    if time.perf_counter() > deadline:
        raise TimeoutError("the reachable sets were not complete within the time limit")


@dataclass(frozen=True)
class LiveMembers:
    """Which heading segments and regions each footstep of an N-step plan can use at all
    (:func:`live_members`).

    Attributes:
        segments: (N + 1, L) bool; True where footstep i may lie in heading segment l.
        regions: (N + 1, R) bool; True where footstep i may lie in region r.
    """

    segments: NDArray[np.bool_]
    regions: NDArray[np.bool_]


def live_members(
    scene: Scene,
    robot: BipedParams,
    options: PlannerOptions,
    n_steps: int,
    forward: ForwardSets | None = None,
    deadline: float = math.inf,
    backward: BackwardSets | None = None,
) -> LiveMembers:
    """The heading segments (eq. 5.12g-h) and regions (5.12i-j) each free footstep ``1..N-2`` of
    an ``n_steps`` plan can use: a pair (segment bucket, region) is live at footstep ``i`` when
    the forward reachable set ``S_i`` (module docstring) meets the backward set ``B_i`` of the
    positions from which the goal feet can still be reached in ``N - 1 - i`` steps by the same
    rows. Both are supersets of what the model allows, so a member that is not live is used by
    no plan of the model: fixing its binary to 0 leaves the feasible set (and the optimum) as it
    is. The goal feet (footsteps N - 1 and N) and footstep 0 are left live. ``forward`` and
    ``backward``: the reachable sets of these arguments to reuse (:class:`ForwardSets`,
    :class:`BackwardSets`).

    Raises:
        TimeoutError: ``time.perf_counter()`` passed ``deadline`` before the sets were complete
            (the members are an optimisation: a caller out of time solves without them).
    """
    check_planning_arguments(scene, robot, options)
    check_n_steps(n_steps)
    n_seg = options.heading_segments
    n_reg = len(scene.terrain)
    segments = np.ones((n_steps + 1, n_seg), dtype=bool)
    regions = np.ones((n_steps + 1, n_reg), dtype=bool)
    if n_steps < 3:
        return LiveMembers(segments, regions)
    if backward is None:
        backward = BackwardSets(scene, robot, options)
    side_a = scene.start.stance if n_steps % 2 == 1 else scene.start.stance.other
    # B_i for i = 1..N - 2 (index i - 1): level N - 1 - i of the goal foot's chain
    bwd_sets = backward.levels(side_a, n_steps - 2, deadline)[::-1]
    firsts, lasts = _bucket_segments(n_seg)
    if forward is None:
        forward = ForwardSets(scene, robot, options, n_steps)
    forward.check_reaches(n_steps)
    fwd_sets = {}
    for i, sets, _ in forward.upto(n_steps - 2):  # each level is kept: a later call goes on
        fwd_sets[i] = sets
        _check_clock(deadline)
    for i in range(1, n_steps - 1):
        fwd, bwd = fwd_sets.get(i, {}), bwd_sets[i - 1]
        live = [key for key, piece in fwd.items() if key in bwd and _meet(piece, bwd[key])]
        seg = np.zeros(n_seg, dtype=bool)
        for b, _ in live:
            seg[firsts[b] : lasts[b]] = True
        reg = np.zeros(n_reg, dtype=bool)
        reg[[r for _, r in live]] = True
        segments[i], regions[i] = seg, reg
    return LiveMembers(segments, regions)
