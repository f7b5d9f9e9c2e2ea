"""Region-aware footstep corrections: the MPC of eq. (5.19) with the next footstep in a foothold.

Beyond the document: section 5.4 leaves foothold regions and reach to the planner, and its MPC
(eq. 5.19a-e) moves the next footstep ``p_{i+1}`` freely. Here the footstep the MPC may choose
is kept in a convex foothold region (eq. 5.18) inset by the sole, as linear rows ``G d <= h`` on
the footstep offset ``d = p_{i+1} - p_i`` (x, y) *in the same QP* as the torques:

    minimise  1/2 z^T H z + z^T F theta + c(theta)        (5.19a, condensed; z = [u; d])
    s.t.      ||u_j / U||_2 <= 1  per torque block         (5.19e)
              G d <= h                                     (region rows, beyond the document)

``H``, ``F``, ``c`` are those of :func:`footfall.control.mpc.build_mpc`. The sole inset
(:func:`sole_inset_offsets`) is exact for a rectangle ``foot_length x foot_width`` at the
footstep's heading: row ``g`` moves in by the sole's support ``L/2 |g . t| + W/2 |g . s|``
(``t``, ``s`` the sole's forward and lateral axes), i.e. the region shrunk by the Minkowski
difference with the sole, so every point of the sole lies in the region.

Solution (exact, three stages, cheapest first):

1. the unconstrained optimum (:meth:`MPC.solve_theta`); if it satisfies the rows it is optimal;
2. with the torque balls inactive the torques are eliminated in closed form,
   ``u(d) = u_0(theta) + K d``, leaving a strictly convex 2-D QP in ``d`` over the polygon. Its
   minimiser is the unconstrained one or lies on one row (the minimiser on that row's line) or on
   two (their intersection): every candidate is evaluated and the feasible one with the least
   cost is the optimum (:func:`solve_polygon_qp`). If ``u(d)`` then satisfies the balls, the
   pair is a KKT point of the full problem (zero ball multipliers) and hence optimal;
3. otherwise the torque bounds bind: for a guess of the active rows (stage 2's first, then
   every single row and pair) the footstep is eliminated and the torques solve the ball QP of
   eq. (5.19e) exactly (:func:`footfall.control.ball_qp.solve_ball_qp`); the first guess whose point
   satisfies every row with multipliers >= 0 is a KKT point of the whole convex problem, hence
   optimal. Clarabel on the full second-order cone program is the last resort.

Several regions (dairlib's ``AlipMultiQP`` approach): one QP per candidate region, the planned
(or previously chosen) region first; another is chosen when the first has no feasible footstep,
or when its optimal cost exceeds another's by more than ``switch_margin``
(:func:`choose_region`). The cost compared is the full eq. (5.19a) cost.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np

from footfall._geometry import polygons_intersect, rot2
from footfall._typing import FloatArray
from footfall.control.ball_qp import solve_ball_qp
from footfall.control.mpc import MPC, MPCSolution, MPCStatus, _clarabel_in_polygon
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.terrain.region import Region

#: a footstep this far [m] outside a region row still satisfies it (solver tolerance)
ROW_TOL = 1e-9
#: a torque block this much above its bound (relative) still counts as inside (stage 2 test)
BALL_TOL = 1e-9
#: a region row's multiplier this far below zero (relative to the footstep gradient) still counts
#: as >= 0 in the KKT test of an active-set guess
MU_TOL = 1e-7
#: how a region solution was found (:class:`RegionSolution.method`)
METHODS = ("unconstrained", "polygon_qp", "active_set", "clarabel", "pruned", "infeasible")


def sole_inset_offsets(
    a: FloatArray, b: FloatArray, heading: float, length: float, width: float, margin: float = 0.0
) -> FloatArray:
    """Offsets ``h`` (E,) [m] of the rows ``a p <= h`` that keep a whole sole in ``a p <= b``.

    The sole is a ``length x width`` rectangle centred on ``p`` (2,) and turned by ``heading``
    [rad]; row ``a_i`` (a unit outward normal) moves in by the sole's support in that direction,
    ``length/2 |a_i . t| + width/2 |a_i . s|`` with ``t = (cos, sin)``, ``s = (-sin, cos)``, plus
    ``margin`` [m].

    Args:
        a: unit outward normals (E, 2) of the region (eq. 5.18).
        b: offsets (E,) [m].
        heading: sole heading [rad].
        length: sole length [m].
        width: sole width [m].
        margin: extra inset [m], >= 0.
    """
    t = np.array([math.cos(heading), math.sin(heading)])
    s = np.array([-t[1], t[0]])
    return np.asarray(b - 0.5 * length * np.abs(a @ t) - 0.5 * width * np.abs(a @ s) - margin)


def solve_polygon_qp(
    m_hess: FloatArray, m_lin: FloatArray, g: FloatArray, h: FloatArray, tol: float = ROW_TOL
) -> tuple[FloatArray, tuple[int, ...]] | None:
    """Exact minimiser of ``1/2 d^T M d + m^T d`` over the polygon ``G d <= h`` (2-D, M > 0).

    The KKT point has at most two active rows (in 2-D any vertex is the intersection of two of
    its rows), so it is among: the unconstrained minimiser, the minimiser on each row's line, and
    each pair of rows' intersection. The feasible candidate of least cost is the optimum.

    Args:
        m_hess: M (2, 2), symmetric positive definite.
        m_lin: m (2,).
        g: rows (E, 2).
        h: offsets (E,).
        tol: feasibility tolerance of a candidate [same units as ``h``].

    Returns:
        ``(d (2,), active rows)`` or None when the polygon is empty.
    """
    m_inv = np.linalg.inv(m_hess)
    d0 = -m_inv @ m_lin
    if np.all(g @ d0 <= h + tol):
        return d0, ()
    e = g.shape[0]
    cands = [d0[None, :]]
    idx: list[tuple[int, ...]] = [()]
    # minimiser on the line g_i d = h_i: d0 + M^-1 g_i (h_i - g_i d0) / (g_i M^-1 g_i)
    mg = g @ m_inv  # (E, 2), rows M^-1 g_i (M symmetric)
    den = np.einsum("ij,ij->i", mg, g)
    cands.append(d0 + mg * ((h - g @ d0) / den)[:, None])
    idx += [(i,) for i in range(e)]
    ii, jj = np.triu_indices(e, 1)
    det = g[ii, 0] * g[jj, 1] - g[ii, 1] * g[jj, 0]
    ok = np.abs(det) > 1e-12
    ii, jj, det = ii[ok], jj[ok], det[ok]
    # Cramer's rule for [g_i; g_j] d = [h_i; h_j]
    px = (h[ii] * g[jj, 1] - h[jj] * g[ii, 1]) / det
    py = (g[ii, 0] * h[jj] - g[jj, 0] * h[ii]) / det
    cands.append(np.stack([px, py], axis=1))
    idx += [(int(i), int(j)) for i, j in zip(ii, jj, strict=True)]
    pts = np.vstack(cands)
    feas = np.all(pts @ g.T <= h + tol, axis=1)
    if not feas.any():
        return None
    cost = 0.5 * np.einsum("ij,jk,ik->i", pts, m_hess, pts) + pts @ m_lin
    cost[~feas] = np.inf
    best = int(np.argmin(cost))
    return pts[best], idx[best]


@dataclass(frozen=True)
class RegionRows:
    """A candidate foothold: the region rows ``g d <= h`` on the footstep offset from the stance.

    Attributes:
        name: the region's name.
        g: unit outward normals (E, 2), in the MPC's frame.
        h: offsets (E,) [m] of ``d = p_{i+1} - p_i`` (already inset by the sole).
    """

    name: str
    g: FloatArray
    h: FloatArray

    def __post_init__(self) -> None:
        g = np.asarray(self.g, dtype=float)
        h = np.asarray(self.h, dtype=float)
        if g.ndim != 2 or g.shape[1] != 2 or g.shape[0] < 1 or not np.all(np.isfinite(g)):
            raise InputError(f"regions[{self.name}].g", g.tolist(), "finite rows of shape (E, 2)")
        if h.shape != (g.shape[0],) or not np.all(np.isfinite(h)):
            raise InputError(f"regions[{self.name}].h", h.tolist(), f"shape ({g.shape[0]},)")
        object.__setattr__(self, "g", g)
        object.__setattr__(self, "h", h)

    def violation(self, d: FloatArray) -> float:
        """``max(g d - h)`` [m]: <= 0 when ``d`` (2,) satisfies every row."""
        return float(np.max(self.g @ d - self.h))


def region_rows(
    region: Region,
    stance: FloatArray,
    heading: float,
    robot: BipedParams,
    margin: float = 0.0,
    rot: FloatArray | None = None,
) -> RegionRows:
    """The rows of ``region`` on the footstep offset ``d = p_{i+1} - p_i`` from ``stance`` (3,):
    the region inset by the sole (``robot.foot_length x robot.foot_width`` at ``heading`` [rad])
    plus ``margin`` [m] (:func:`sole_inset_offsets`), expressed in the frame turned by ``rot``
    (2, 2) (world frame when None: ``d_world = rot d``)."""
    a, b = region.halfspaces()
    h = sole_inset_offsets(a, b, heading, robot.foot_length, robot.foot_width, margin)
    return RegionRows(region.name, a if rot is None else a @ rot, h - a @ stance[:2])


def regions_in_reach(
    regions: Sequence[Region], stance: FloatArray, heading: float, side: Side, robot: BipedParams
) -> tuple[str, ...]:
    """Names of the regions a step from ``stance`` (3,) [m] (stance foot ``side``, heading
    [rad]) can reach: the polygon meets the reach trapezoid (eq. 5.12f) and its centroid's height
    is within ``robot.step_height_max`` of the stance foot's."""
    rot = rot2(heading)
    reach = stance[:2] + robot.reach.for_stance(side) @ rot.T
    return tuple(
        r.name
        for r in regions
        if abs(float(r.centroid[2]) - float(stance[2])) <= robot.step_height_max
        and polygons_intersect(reach, r.vertices)
    )


@dataclass(frozen=True)
class RegionSolution:
    """Eq. (5.19) solved with the next footstep in one region (or the region chosen among several).

    Attributes:
        solution: the MPC solution (torques, next footstep).
        region: the region the footstep is in ("" when no candidate was feasible: ``solution``
            is then the unconstrained one).
        method: one of :data:`METHODS`.
        cost: full eq. (5.19a) cost of the solution (inf when infeasible).
        reason: why this region: ``planned``, ``kept`` (the region chosen earlier in this
            support), ``first infeasible`` (the preferred region had no footstep the sole fits),
            ``cheaper`` (cost lower by more than the switch margin) or ``none feasible``.
        costs: every candidate's optimal cost by name (inf: infeasible); for a candidate
            ``pruned`` (not solved exactly: its torque-unbounded relaxation already cost more
            than the first's minus the switch margin) that lower bound.
    """

    solution: MPCSolution
    region: str
    method: str
    cost: float
    reason: str = ""
    costs: dict[str, float] = field(default_factory=dict)


class RegionMPC:
    """The MPC of eq. (5.19) with the next footstep kept in foothold regions (module docstring).

    Wraps an :class:`MPC` (its warm starts, counters and fallbacks) and precomputes, per tick,
    the elimination of the torques used by stage 2.

    Args:
        mpc: the MPC to wrap.
    """

    def __init__(self, mpc: MPC) -> None:
        if not isinstance(mpc, MPC):
            raise InputError("mpc", mpc, "an MPC")
        self.mpc = mpc
        mdl = mpc.model
        # ball multipliers of the last active-set solve per (region, active rows): warm starts
        self._warm: dict[tuple[str, tuple[int, ...]], tuple[int, FloatArray]] = {}
        self._u0: list[FloatArray] = []  # u_0 = u0_map theta, (n_u, 10)
        self._k: list[FloatArray] = []  # u = u_0 + K d, (n_u, 2)
        self._m: list[FloatArray] = []  # M (2, 2)
        self._m_lin: list[FloatArray] = []  # m = m_lin theta, (2, 10)
        self._m_inv: list[FloatArray] = []  # M^-1
        self._lam_min: list[float] = []  # smallest eigenvalue of M
        for k_s in range(mdl.n_ticks):
            h, f = mdl.H[k_s], mdl.F[k_s]
            n_u = h.shape[0] - 2
            h_uu, h_ud, h_dd = h[:n_u, :n_u], h[:n_u, n_u:], h[n_u:, n_u:]
            u0 = -np.linalg.solve(h_uu, f[:n_u])
            k = -np.linalg.solve(h_uu, h_ud)
            m = h_dd + h_ud.T @ k
            self._u0.append(np.asarray(u0, dtype=float))
            self._k.append(np.asarray(k, dtype=float))
            m = 0.5 * (m + m.T)
            self._m.append(m)
            self._m_inv.append(np.asarray(np.linalg.inv(m), dtype=float))
            self._lam_min.append(float(np.linalg.eigvalsh(m)[0]))
            self._m_lin.append(f[n_u:] + h_ud.T @ u0)

    @contextmanager
    def probe(self) -> Iterator[None]:
        """Solves inside leave no trace: the warm starts (this object's and the wrapped
        :class:`MPC`'s last solution) and the MPC's counters are restored on exit. For
        questions asked beside the solve that is applied (the adjuster's step timing solves
        other touchdown times), so that solve runs exactly as it would have."""
        mpc = self.mpc
        saved = (dict(self._warm), mpc._last, mpc.n_solves, mpc.n_fallbacks)
        try:
            yield
        finally:
            self._warm, mpc._last, mpc.n_solves, mpc.n_fallbacks = saved

    def relaxed(
        self, k_s: int, theta: FloatArray, rows: RegionRows
    ) -> tuple[FloatArray, FloatArray, tuple[int, ...], float] | None:
        """Stage 2: the problem without the torque bounds (5.19e), exactly.

        Returns:
            ``(u (n_u,) [N m], d (2,) [m], active rows, cost)`` or None when the rows leave no
            footstep. The cost is a lower bound on the region's optimal cost (a relaxation).
        """
        res = solve_polygon_qp(self._m[k_s], self._m_lin[k_s] @ theta, rows.g, rows.h)
        if res is None:
            return None
        d, active = res
        u = self._u0[k_s] @ theta + self._k[k_s] @ d
        return u, d, active, self.cost(k_s, u, d, theta)

    def solve_region(
        self,
        k_s: int,
        theta: FloatArray,
        p_stance: FloatArray,
        p_next_ref: FloatArray,
        rows: RegionRows,
        unconstrained: MPCSolution | None = None,
        relaxed: tuple[FloatArray, FloatArray, tuple[int, ...], float] | None = None,
    ) -> RegionSolution:
        """Eq. (5.19) at tick ``k_s`` with the next footstep in ``rows`` (module docstring).

        Args:
            k_s: control tick, 0 <= k_s < M.
            theta: ``[x_measured (4), (p_next_ref - p_stance)[:2], x_next_ref (4)]`` (10,).
            p_stance: stance footstep p_i (3,) [m].
            p_next_ref: planned next footstep (3,) [m] (its height is kept).
            rows: the region rows on ``d = p_{i+1} - p_i``.
            unconstrained: the unconstrained solution of this tick if already solved.
            relaxed: :meth:`relaxed` of these rows if already solved.

        Returns:
            The :class:`RegionSolution`; ``method`` ``infeasible`` (with the unconstrained
            solution and an infinite cost) when no footstep satisfies the rows.
        """
        t0 = time.perf_counter()
        sol = unconstrained
        if sol is None:
            sol = self.mpc.solve_theta(k_s, theta, p_stance, p_next_ref, t0)
        if sol.fallback:
            return RegionSolution(sol, "", "infeasible", math.inf)
        d = sol.next_footstep[:2] - p_stance[:2]
        if rows.violation(d) <= ROW_TOL:
            cost = self.cost(k_s, sol.torques, d, theta)
            return RegionSolution(sol, rows.name, "unconstrained", cost)
        rel = relaxed if relaxed is not None else self.relaxed(k_s, theta, rows)
        if rel is None:
            return RegionSolution(sol, "", "infeasible", math.inf)
        u, d, active, _ = rel
        mdl = self.mpc.model
        v = u.reshape(-1, 2) / mdl.u_limits
        method = "polygon_qp"
        lam = np.zeros(v.shape[0])
        iters = 0
        if np.einsum("ij,ij->i", v, v).max() > 1.0 + BALL_TOL:
            exact = self._active_sets(k_s, theta, rows, active)
            method = "active_set"
            if exact is None:
                exact = self._clarabel(k_s, theta, rows)
                method = "clarabel"
            if exact is None:
                return RegionSolution(sol, "", "infeasible", math.inf)
            u, d, lam, iters = exact
        out = MPCSolution(
            k_s=k_s,
            torques=u.reshape(-1, 2),
            block_ticks=mdl.block_ticks[k_s],
            next_footstep=np.array([p_stance[0] + d[0], p_stance[1] + d[1], p_next_ref[2]]),
            status=MPCStatus.OPTIMAL,
            fallback=False,
            solve_time=sol.solve_time + time.perf_counter() - t0,
            iterations=iters,
            multipliers=lam,
        )
        return RegionSolution(out, rows.name, method, self.cost(k_s, u, d, theta))

    def _active_sets(
        self, k_s: int, theta: FloatArray, rows: RegionRows, first: tuple[int, ...]
    ) -> tuple[FloatArray, FloatArray, FloatArray, int] | None:
        """Stage 3 with the torque bounds active: for a guess of the active rows (``first``,
        then every single row, then every pair) the footstep is eliminated (on the row's line,
        or fixed at the pair's corner), the torques solve the ball QP of eq. (5.19e) exactly
        (:func:`footfall.control.ball_qp.solve_ball_qp`), and the guess is kept when the KKT
        conditions of the whole problem hold: the footstep satisfies every row and the rows'
        multipliers are >= 0. The problem is convex, so that point is the optimum.

        Returns:
            ``(u, d, ball multipliers, iterations)`` or None when no guess passes.
        """
        e = rows.g.shape[0]
        guesses = [first] if first else []
        guesses += [(i,) for i in range(e) if (i,) != first]
        guesses += [(i, j) for i in range(e) for j in range(i + 1, e) if (i, j) != first]
        for act in guesses:
            res = self._solve_active(k_s, theta, rows, act)
            if res is not None:
                return res
        return None

    def _warm_start(self, k_s: int, key: tuple[str, tuple[int, ...]]) -> FloatArray | None:
        """The ball multipliers of the last solve with the same region and active rows, shifted
        to the blocks left at ``k_s`` (as :meth:`MPC.solve_theta` warm-starts); None in a new
        single support (``k_s`` not after the last one)."""
        last = self._warm.get(key)
        if last is None or last[0] >= k_s:
            return None
        mdl = self.mpc.model
        return last[1][mdl.first_block[k_s] - mdl.first_block[last[0]] :]

    def _solve_active(
        self, k_s: int, theta: FloatArray, rows: RegionRows, act: tuple[int, ...]
    ) -> tuple[FloatArray, FloatArray, FloatArray, int] | None:
        """The torque ball QP with rows ``act`` (1 or 2) active; None unless it is a KKT point."""
        mdl = self.mpc.model
        h, f = mdl.H[k_s], mdl.F[k_s] @ theta
        n_u = h.shape[0] - 2
        h_uu, h_ud, h_dd = h[:n_u, :n_u], h[:n_u, n_u:], h[n_u:, n_u:]
        f_u, f_d = f[:n_u], f[n_u:]
        g = rows.g[list(act)]
        if len(act) == 2:
            det = g[0, 0] * g[1, 1] - g[0, 1] * g[1, 0]
            if abs(det) <= 1e-12:
                return None
            d0 = np.linalg.solve(g, rows.h[list(act)])
            p_u, q_u = h_uu, f_u + h_ud @ d0
        else:
            gi = g[0] / np.linalg.norm(g[0])
            d0 = gi * rows.h[act[0]] / np.linalg.norm(g[0])
            nrm = np.array([-gi[1], gi[0]])  # along the row's line: d = d0 + nrm t
            hn = h_ud @ nrm
            s = float(nrm @ h_dd @ nrm)
            p_u = h_uu - np.outer(hn, hn) / s
            q_u = f_u + h_ud @ d0 - hn * float(nrm @ (h_dd @ d0 + f_d)) / s
        scale = np.tile(mdl.u_limits, n_u // 2)
        key = (rows.name, act)
        v, lam, iters, ok = solve_ball_qp(
            scale[:, None] * p_u * scale[None, :], scale * q_u, self._warm_start(k_s, key)
        )
        if not ok:
            return None
        self._warm[key] = (k_s, lam)
        u = v * scale
        if len(act) == 1:
            t = -float(nrm @ (h_ud.T @ u + h_dd @ d0 + f_d)) / s
            d = np.asarray(d0 + nrm * t, dtype=float)
        else:
            d = d0
        if rows.violation(d) > ROW_TOL:
            return None
        grad = h_ud.T @ u + h_dd @ d + f_d  # stationarity: grad + g^T mu = 0
        mu = np.linalg.lstsq(g.T, -grad, rcond=None)[0]
        if np.any(mu < -MU_TOL * (1.0 + float(np.abs(grad).max()))):
            return None
        return u, d, lam, iters

    def _clarabel(
        self, k_s: int, theta: FloatArray, rows: RegionRows
    ) -> tuple[FloatArray, FloatArray, FloatArray, int] | None:
        """Last resort: the full cone program; ``(u, d, ball multipliers, iterations)`` or None."""
        mdl = self.mpc.model
        n_u = mdl.H[k_s].shape[0] - 2
        scale = np.concatenate([np.tile(mdl.u_limits, n_u // 2), np.ones(2)])
        p = scale[:, None] * mdl.H[k_s] * scale[None, :]
        q = scale * (mdl.F[k_s] @ theta)
        try:
            res = _clarabel_in_polygon(p, q, rows.g, rows.h, n_u)
        except (ValueError, RuntimeError):  # pragma: no cover - solver internals
            return None
        if str(res.status) not in ("Solved", "AlmostSolved"):
            return None
        z = np.asarray(res.x, dtype=float)
        vb = z[:n_u].reshape(-1, 2)
        vb = vb / np.maximum(np.linalg.norm(vb, axis=1), 1.0)[:, None]
        duals = np.asarray(res.z, dtype=float)[rows.g.shape[0] :].reshape(-1, 3)[:, 0]
        return (vb * mdl.u_limits).ravel(), z[n_u:], duals, int(res.iterations)

    def cost(self, k_s: int, u: FloatArray, d: FloatArray, theta: FloatArray) -> float:
        """Full eq. (5.19a) cost at tick ``k_s`` of torques ``u`` (n_u,) [N m] and footstep
        offset ``d`` (2,) [m]."""
        return self.mpc.model.cost(k_s, np.concatenate([np.ravel(u), d]), theta)

    def solve(
        self,
        k_s: int,
        theta: FloatArray,
        p_stance: FloatArray,
        p_next_ref: FloatArray,
        candidates: Sequence[RegionRows],
        switch_margin: float,
        first_reason: str = "planned",
    ) -> RegionSolution:
        """Eq. (5.19) with one QP per candidate region; the chosen one (:func:`choose_region`).

        Args:
            k_s, theta, p_stance, p_next_ref: as for :meth:`solve_region`.
            candidates: the regions, the preferred one (planned or kept) first.
            switch_margin: another region is chosen over the first only if its cost is lower by
                more than this.
            first_reason: the reason reported when the first candidate is chosen.
        """
        if not candidates:
            raise InputError("candidates", candidates, "at least one region")
        t0 = time.perf_counter()
        unc = self.mpc.solve_theta(k_s, theta, p_stance, p_next_ref, t0)
        first = self.solve_region(k_s, theta, p_stance, p_next_ref, candidates[0], unc)
        sols = [first]
        if len(candidates) > 1:
            sols += self._others(
                k_s, theta, p_stance, p_next_ref, candidates, first, unc, switch_margin
            )
        best = choose_region(sols, switch_margin, first_reason)
        sol = best.solution
        sol = MPCSolution(  # the time of the whole choice (faster than dataclasses.replace)
            sol.k_s,
            sol.torques,
            sol.block_ticks,
            sol.next_footstep,
            sol.status,
            sol.fallback,
            time.perf_counter() - t0,
            sol.iterations,
            sol.multipliers,
            sol.message,
        )
        costs = {c.name: x.cost for c, x in zip(candidates, sols, strict=True)}
        if best.region:
            self.mpc._last = sol  # warm start / fallback from what is applied
        return RegionSolution(sol, best.region, best.method, best.cost, best.reason, costs)

    def _others(
        self,
        k_s: int,
        theta: FloatArray,
        p_stance: FloatArray,
        p_next_ref: FloatArray,
        candidates: Sequence[RegionRows],
        first: RegionSolution,
        unc: MPCSolution,
        switch_margin: float,
    ) -> list[RegionSolution]:
        """The candidates after the first, each solved only if it may beat the first by the
        margin. Lower bounds: the first's cost when the first holds the unconstrained optimum
        (the global one); else the bound-free relaxation's cost, which is the quadratic
        ``q(d) = q(d_0) + 1/2 (d - d_0)^T M (d - d_0)`` in the footstep, so at least
        ``q(d_0) + 1/2 lambda_min(M) v^2`` with ``v`` the largest row violation of its
        minimiser ``d_0`` (rows are unit normals: ``v`` is at most the distance to the region),
        and then the exact relaxation."""
        out = []
        bound_first = first.cost - switch_margin if math.isfinite(first.cost) else math.inf
        if first.method == "unconstrained":
            return [RegionSolution(unc, c.name, "pruned", first.cost) for c in candidates[1:]]
        lin = self._m_lin[k_s] @ theta
        d0 = -self._m_inv[k_s] @ lin
        q0 = 0.5 * float(d0 @ lin) + self.cost(k_s, self._u0[k_s] @ theta, np.zeros(2), theta)
        for c in candidates[1:]:
            viol = max(c.violation(d0), 0.0)
            cheap = q0 + 0.5 * self._lam_min[k_s] * viol * viol
            if cheap >= bound_first:
                out.append(RegionSolution(unc, c.name, "pruned", cheap))
                continue
            rel = self.relaxed(k_s, theta, c)
            if rel is None:
                out.append(RegionSolution(unc, "", "infeasible", math.inf))
            elif rel[3] >= bound_first:
                out.append(RegionSolution(unc, c.name, "pruned", rel[3]))
            else:
                out.append(self.solve_region(k_s, theta, p_stance, p_next_ref, c, unc, rel))
        return out


def choose_region(
    sols: Sequence[RegionSolution], switch_margin: float, first_reason: str = "planned"
) -> RegionSolution:
    """The region among ``sols`` (one per candidate, the preferred first) to step into.

    The first, unless it is infeasible (then the cheapest feasible: ``first infeasible``) or
    another is cheaper by more than ``switch_margin`` (``cheaper``); when none is feasible the
    first (unconstrained) solution with reason ``none feasible``.
    """
    first = sols[0]
    feas = [s for s in sols if math.isfinite(s.cost)]
    if not feas:
        return replace(first, region="", reason="none feasible")
    best = min(feas, key=lambda s: s.cost)
    if not math.isfinite(first.cost):
        return replace(best, reason="first infeasible")
    if best is not first and best.cost < first.cost - switch_margin:
        return replace(best, reason="cheaper")
    return replace(first, reason=first_reason)
