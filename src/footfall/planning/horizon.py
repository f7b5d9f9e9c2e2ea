"""Short-horizon footstep MIQP for the control loop: document 000's planner over H = 3 steps.

The full-horizon MIQCQP (:mod:`footfall.planning.miqcqp`, eq. 5.11-5.18) plans every step to the
goal before the walk. In the loop the robot needs the next few footsteps again at every control
tick, from the *measured* ALIP state, over the scene's convex regions (dairlib's ALIP footstep
MIQP for Cassie plans 3 footsteps this way). This module solves that problem exactly:

    minimise   sum_{j,b} w_u (dt_b / dt_K) ||u_{j,b}||^2                     (torque, eq. 5.11)
             + lambda_x ||x_H - x_H^ref||^2_{Q_x}                             (terminal, eq. 5.11)
             + lambda_l sum_j (p_{j+1} - p_j)^T Q_l (p_{j+1} - p_j)           (step, eq. 5.11)
             + w_p sum_j ||p_j - p_j^ref||^2                                  (plan tracking)
    s.t.       ALIP dynamics (5.12a) over K - 1 torque blocks per single support, the first
               one shortened to the time left in the current step; reset maps (5.12b);
               x_0 = the measured state (5.12c);
               torque in the regular TORQUE_SIDES-gon inscribed in ||u|| <= U_max (5.12d);
               reach (5.12f) in the stance foot's frame at the planned heading;
               |z_{j+1} - z_j| <= step_height_max;
               each p_j (j = 1..H) on one region's plane (5.15-5.17) and in its polygon (5.18).

Choices, each made so the problem is a mixed-integer QP that an active-set solver takes exactly:

* **Headings are the plan's** (``HorizonInput.headings``), as in dairlib's MIQP: with the
  heading fixed, reach (5.12f) is exactly linear (no sin/cos segments), and the only binaries
  are the regions.
* **The torque ball is its inscribed regular octagon** (``TORQUE_SIDES`` rows
  ``n_k^T u <= U_max cos(pi / 8)``): a planned torque never exceeds U_max and is at most
  ``1 - cos(pi / 8)`` (7.6 %) short of it in the worst direction, like the planner's swing bound.
  Beyond the document, ``HorizonOptions.torque_limits`` makes it the walker MPC's ellipse
  ``(v_x / U_x)^2 + (v_y / U_y)^2 <= 1`` over the torque ``v = R(theta_j)^T u`` in stance j's
  frame (eq. 5.19e as :func:`footfall.control.mpc.build_mpc` takes it), with the octagon
  inscribed in it: rows ``(R(theta_j) D^-1 n_k)^T u <= cos(pi / 8)``, ``D = diag(U_x, U_y)``.
  The loop's MPC then lands the footstep with the torques this problem assumed.
* **The tracking term** ``w_p ||p_j - p_j^ref||^2`` (weight ``HorizonOptions.track``, eq. 5.19a's
  W) keeps the footsteps near the full-horizon plan, whose goal lies beyond the horizon.

Solver: branch and bound over the region of each step, in step order, best-first on the bound,
with ``daqp`` (dense active-set QP) as the node solver. States are condensed out (they are affine
in the torques and footsteps), so a node is a strictly convex QP in ``2 H (K - 1) + 3 H``
variables. A node whose later steps have no region yet keeps them in the bounding box of their
candidate regions: the box holds each candidate region, so the node's optimum is a lower bound on
every completion. A child is warm-started from its parent's point (``primal_start``: daqp starts
from the rows active there), and the search from the previous tick's regions
(``warm``: that leaf is solved first and is the first incumbent). A node is pruned when its bound
is within the relative gap of the incumbent (SCIP's definition); the result is ``optimal`` only
when every node was solved or pruned, ``infeasible`` only when every leaf and node was proven
infeasible by daqp, and any daqp failure makes it ``failed`` or (with an incumbent) ``feasible``.

:func:`footfall.planning.horizon_model.horizon_problem` writes the same problem as a :class:`~footfall.solvers.problem.MIQCQP`
(ALIP states as variables, big-M region rows, the octagon as rows): any backend (SCIP, ``bnb``)
solves it, and the tests compare their optima with this search's.
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from footfall._geometry import rot2
from footfall._typing import FloatArray
from footfall._validate import finite, finite_array, positive
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan, PlannerWeights
from footfall.solvers.base import relative_gap
from footfall.terrain.scene import Scene
from footfall.terrain.terrain import Terrain

#: facets of the regular polygon inscribed in the torque ball ||u|| <= U_max (eq. 5.12d)
TORQUE_SIDES = 8
#: the default horizon H (footsteps planned per tick)
DEFAULT_HORIZON = 3
#: outcome of :meth:`HorizonPlanner.solve`
STATUSES = ("optimal", "feasible", "infeasible", "node_limit", "failed")
#: daqp exit flags: a solution (1 optimal, 2 soft-optimal) and a proof of infeasibility
_DAQP_SOLVED = (1, 2)
_DAQP_INFEASIBLE = -1
#: a region whose horizontal polygon is this far [m] outside a footstep's reachable box is no
#: candidate for it (a tolerance only: the box is already conservative)
_BOX_TOL = 1e-9


@dataclass(frozen=True)
class HorizonOptions:
    """Options of the short-horizon problem.

    Attributes:
        horizon: H, footsteps planned per solve (>= 1; 3 in the loop).
        weights: the objective weights of eq. (5.11) (torque, terminal, step); the heading term
            is constant here (headings are the plan's).
        track: w_p [1/m^2], weight on each footstep's distance from the plan's.
        region_margin: keep footsteps this far inside their region's polygon [m] (eq. 5.18 with
            the edges moved in).
        gap: relative optimality gap at which the search stops.
        node_limit: most QP solves per call; the search then stops with status ``node_limit``
            and an honest gap (a limit on work, not on time, so results do not depend on the
            machine).
        torque_limits: semi-axes ``(U_x, U_y)`` [N m] of the ankle-torque ellipse in each stance
            foot's frame (the walker MPC's, e.g.
            :func:`footfall.control.adjusters.sole_torque_limits`); None: the document's ball
            ``||u|| <= U_max`` (5.12d).
    """

    horizon: int = DEFAULT_HORIZON
    weights: PlannerWeights = field(default_factory=PlannerWeights)
    track: float = 10.0
    region_margin: float = 0.0
    gap: float = 1e-4
    node_limit: int = 5000
    torque_limits: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        h = self.horizon
        if isinstance(h, bool) or not isinstance(h, int) or not 1 <= h <= 10:
            raise InputError("horizon", h, "an integer number of footsteps in 1..10")
        if not isinstance(self.weights, PlannerWeights):
            raise InputError("weights", self.weights, "a footfall.planning.PlannerWeights")
        track = finite("track", self.track)
        if track < 0.0:
            raise InputError("track", track, "a weight >= 0 [1/m^2]")
        object.__setattr__(self, "track", track)
        margin = finite("region_margin", self.region_margin)
        if margin < 0.0:
            raise InputError("region_margin", margin, "a distance >= 0 [m]")
        object.__setattr__(self, "region_margin", margin)
        gap = finite("gap", self.gap)
        if gap < 0.0:
            raise InputError("gap", gap, "a relative gap >= 0")
        object.__setattr__(self, "gap", gap)
        nl = self.node_limit
        if isinstance(nl, bool) or not isinstance(nl, int) or nl < 1:
            raise InputError("node_limit", nl, "an integer >= 1")
        lim = self.torque_limits
        if lim is not None:
            expected = "two finite numbers (U_x, U_y) > 0 [N m], or None for the ball U_max"
            try:
                vals = tuple(float(v) for v in lim)
            except (TypeError, ValueError):
                raise InputError("torque_limits", lim, expected) from None
            if len(vals) != 2 or not all(math.isfinite(v) and v > 0.0 for v in vals):
                raise InputError("torque_limits", lim, expected)
            object.__setattr__(self, "torque_limits", vals)


def torque_facets(
    u_max: float, torque_limits: tuple[float, float] | None, heading: float
) -> tuple[FloatArray, FloatArray]:
    """The ``TORQUE_SIDES``-gon of eq. (5.12d) as rows ``normals @ u <= bounds`` over the world
    frame torque ``u`` (2,) of a stance foot at ``heading`` [rad]: inscribed in the ball
    ``||u|| <= u_max`` [N m] when ``torque_limits`` is None, else in the ellipse of semi-axes
    ``torque_limits = (U_x, U_y)`` [N m] in the stance frame. Returns ``normals`` (S, 2) and
    ``bounds`` (S,); facet ``k + S/2`` is facet ``k`` negated."""
    phi = 2.0 * math.pi * np.arange(TORQUE_SIDES) / TORQUE_SIDES
    unit = np.column_stack([np.cos(phi), np.sin(phi)])
    inscribed = math.cos(math.pi / TORQUE_SIDES)
    if torque_limits is None:
        return unit, np.full(TORQUE_SIDES, u_max * inscribed)
    normals = (unit / np.asarray(torque_limits, dtype=float)) @ rot2(heading).T
    return normals, np.full(TORQUE_SIDES, inscribed)


@dataclass(frozen=True)
class HorizonInput:
    """What the loop knows at a tick: the stance, the measured state and the plan ahead.

    Attributes:
        stance: the standing foot's side.
        stance_foot: p_0 (3,) [m], the standing foot's contact point.
        alip_state: measured ALIP state (4,) relative to p_0: CoM (x, y) [m], angular momentum
            (L_x, L_y) [kg m^2/s] (eq. 5.1).
        time_left: time left in the current single support [s], in (0, T_ss].
        headings: theta_0..theta_H (H + 1,) [rad], the plan's headings (fixed here).
        footsteps_ref: p_1..p_H of the plan (H, 3) [m].
        state_ref: the plan's ALIP state (4,) at the start of step H's single support, relative
            to its footstep.
    """

    stance: Side
    stance_foot: FloatArray
    alip_state: FloatArray
    time_left: float
    headings: FloatArray
    footsteps_ref: FloatArray
    state_ref: FloatArray

    def __post_init__(self) -> None:
        try:
            object.__setattr__(self, "stance", Side(self.stance))
        except ValueError:
            raise InputError("stance", self.stance, "'left' or 'right'") from None
        object.__setattr__(self, "stance_foot", _shaped("stance_foot", self.stance_foot, (3,)))
        object.__setattr__(self, "alip_state", _shaped("alip_state", self.alip_state, (4,)))
        object.__setattr__(self, "time_left", positive("time_left", self.time_left))
        heads = finite_array("headings", self.headings)
        if heads.ndim != 1 or len(heads) < 2:
            raise InputError("headings", self.headings, "H + 1 headings [rad], shape (H + 1,)")
        object.__setattr__(self, "headings", heads)
        refs = _shaped("footsteps_ref", self.footsteps_ref, (len(heads) - 1, 3))
        object.__setattr__(self, "footsteps_ref", refs)
        object.__setattr__(self, "state_ref", _shaped("state_ref", self.state_ref, (4,)))

    @property
    def horizon(self) -> int:
        """H, the number of footsteps this input asks for."""
        return len(self.headings) - 1


def _shaped(fld: str, value: object, shape: tuple[int, ...]) -> FloatArray:
    """``value`` as a finite float array of ``shape``, or :class:`InputError` naming ``fld``."""
    arr = finite_array(fld, value)
    if arr.shape != shape:
        raise InputError(fld, value, f"finite numbers of shape {shape}")
    return arr


@dataclass(frozen=True)
class HorizonSolution:
    """Result of one short-horizon solve.

    Attributes:
        status: one of :data:`STATUSES`.
        footsteps: p_1..p_H (H, 3) [m] (empty (0, 3) without a solution).
        regions: the region name of each footstep (H names; empty without a solution).
        torques: ankle torques (H, K - 1, 2) [N m] per block (block 0 of step 0 acts now).
        final_state: x_H (4,), the ALIP state at the start of step H's single support.
        objective: cost of the solution (nan without one).
        bound: proven lower bound on the optimum (inf when proven infeasible).
        gap: ``(objective - bound) / min(|objective|, |bound|)`` (inf when unknown).
        nodes: QP solves made.
        warm_used: the warm-start regions gave the first incumbent.
        solve_time: wall time of the call [s] (from the planner's clock).
        message: why, when there is no optimal solution.
    """

    status: str
    footsteps: FloatArray
    regions: tuple[str, ...]
    torques: FloatArray
    final_state: FloatArray
    objective: float
    bound: float
    gap: float
    nodes: int
    warm_used: bool
    solve_time: float
    message: str = ""

    @property
    def has_solution(self) -> bool:
        """True when there are footsteps."""
        return len(self.regions) > 0

    def next_regions(self, stepped: bool) -> tuple[str, ...] | None:
        """The warm start for the next tick: these regions, or, when the robot has stepped onto
        footstep 1 since, the later ones with the last repeated; None without a solution."""
        if not self.regions:
            return None
        if not stepped or len(self.regions) < 2:
            return self.regions
        return self.regions[1:] + self.regions[-1:]


@dataclass(frozen=True)
class _Region:
    """A region's rows: plane ``n . p = -d`` (5.15-5.17), polygon ``a xy <= b`` (5.18), box."""

    name: str
    normal: FloatArray
    offset: float
    a: FloatArray
    b: FloatArray
    lo: FloatArray  # (3,) box corner
    hi: FloatArray


@dataclass
class _Qp:
    """The condensed problem of one call: cost ``1/2 z^T H z + f^T z + c`` and the rows that do not
    depend on the regions (``lo <= A z <= hi``; ``eq`` marks equalities)."""

    hess: FloatArray
    lin: FloatArray
    const: float
    rows: FloatArray
    lo: FloatArray
    hi: FloatArray
    z_lo: FloatArray
    z_hi: FloatArray
    terminal: FloatArray  # (4, nz + 1): x_H = terminal[:, :nz] z + terminal[:, nz]


class HorizonPlanner:
    """The short-horizon footstep MIQP of a scene's terrain and robot (module docstring).

    Build it once; :meth:`solve` then takes one tick's :class:`HorizonInput`.

    Args:
        scene: a scene (its regions and, unless ``robot`` is given, its robot) or a bare
            :class:`~footfall.terrain.terrain.Terrain` with ``robot``.
        robot: the biped's parameters (reach, T_ss, T_ds, K, U_max, ...).
        options: horizon, weights, gap, node limit.
        clock: the clock that times a solve (``time.perf_counter``; tests inject their own).
    """

    def __init__(
        self,
        scene: Scene | Terrain,
        robot: BipedParams | None = None,
        options: HorizonOptions | None = None,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        if isinstance(scene, Scene):
            terrain = scene.terrain
            robot = scene.robot if robot is None else robot
        elif isinstance(scene, Terrain):
            terrain = scene
            if robot is None:
                raise InputError("robot", robot, "the robot's parameters with a bare terrain")
        else:
            raise InputError("scene", scene, "a footfall.terrain.Scene or Terrain")
        if not isinstance(robot, BipedParams):
            raise InputError("robot", robot, "a footfall.models.BipedParams")
        options = HorizonOptions() if options is None else options
        if not isinstance(options, HorizonOptions):
            raise InputError("options", options, "a footfall.planning.horizon.HorizonOptions")
        import daqp  # a dependency; imported here so that reading plans does not need it

        self._daqp = daqp
        self.terrain, self.robot, self.options, self.clock = terrain, robot, options, clock
        self.h = options.horizon
        self.blocks = robot.n_nodes - 1
        self.nu = 2 * self.h * self.blocks
        self.nz = self.nu + 3 * self.h
        alip = robot.alip()
        self._alip = alip
        self._ad, self._bd = alip.discretize(robot.node_dt)
        self._ar, self._br = alip.reset_map(robot.t_ds)
        self._first: tuple[float, FloatArray, FloatArray] = (robot.node_dt, self._ad, self._bd)
        self.regions: list[_Region] = []
        for region in terrain:
            a_poly, b_poly = region.halfspaces()
            v3 = region.vertices3d
            self.regions.append(
                _Region(
                    name=region.name,
                    normal=np.asarray(region.normal, dtype=float),
                    offset=float(region.offset),
                    a=a_poly,
                    b=b_poly - options.region_margin,
                    lo=v3.min(axis=0),
                    hi=v3.max(axis=0),
                )
            )
        self._names = [r.name for r in self.regions]
        self._lo = np.array([r.lo for r in self.regions])  # (R, 3) region boxes
        self._hi = np.array([r.hi for r in self.regions])
        self._box = terrain.bounds()

    # ---------------------------------------------------------------- indices
    def u_index(self, step: int, block: int) -> int:
        """Column of ``u_{step, block}[0]`` in the condensed variables ``z``."""
        return 2 * (step * self.blocks + block)

    def p_index(self, step: int) -> int:
        """Column of ``p_step[0]`` (step = 1..H) in ``z``."""
        return self.nu + 3 * (step - 1)

    # ---------------------------------------------------------------- input
    def check_input(self, inp: HorizonInput) -> None:
        """Raise :class:`InputError` when ``inp`` does not fit this planner."""
        if not isinstance(inp, HorizonInput):
            raise InputError("input", inp, "a footfall.planning.horizon.HorizonInput")
        if inp.horizon != self.h:
            raise InputError(
                "headings", inp.headings.tolist(), f"{self.h + 1} headings (H = {self.h})"
            )
        if inp.time_left > self.robot.t_ss + 1e-9:
            raise InputError(
                "time_left", inp.time_left, f"a time in (0, T_ss = {self.robot.t_ss:g}] [s]"
            )

    def _phase(self, dt: float) -> tuple[FloatArray, FloatArray]:
        """ZOH matrices of one torque block of ``dt`` [s] (the last one is cached: ticks repeat)."""
        if abs(dt - self._first[0]) <= 1e-15:
            return self._first[1], self._first[2]
        if abs(dt - self.robot.node_dt) <= 1e-15:
            return self._ad, self._bd
        ad, bd = self._alip.discretize(dt)
        self._first = (dt, ad, bd)
        return ad, bd

    # ---------------------------------------------------------------- condensed QP
    def _condense(self, inp: HorizonInput) -> _Qp:
        """The cost and the region-free rows of ``inp`` over ``z = [u; p_1..p_H]``."""
        h, nz, rb = self.h, self.nz, self.robot
        w, opt = self.options.weights, self.options
        p0 = inp.stance_foot
        # x = X[:, :nz] z + X[:, nz], propagated through the phases and resets
        x = np.zeros((4, nz + 1))
        x[:, nz] = inp.alip_state
        dt0 = inp.time_left / self.blocks
        cost_rows: list[FloatArray] = []  # each row: (nz + 1) coefficients, last = -target
        cost_w: list[float] = []
        for j in range(h):
            dt = dt0 if j == 0 else rb.node_dt
            ad, bd = self._phase(dt)
            for blk in range(self.blocks):
                iu = self.u_index(j, blk)
                x = ad @ x
                x[:, iu : iu + 2] += bd
                for k in range(2):
                    row = np.zeros(nz + 1)
                    row[iu + k] = 1.0
                    cost_rows.append(row)
                    cost_w.append(w.torque * dt / rb.node_dt)
            # reset onto p_{j+1}: x+ = A_r x- + B_r (p_{j+1} - p_j)
            x = self._ar @ x
            ip = self.p_index(j + 1)
            x[:, ip : ip + 3] += self._br
            if j == 0:
                x[:, nz] -= self._br @ p0
            else:
                iq = self.p_index(j)
                x[:, iq : iq + 3] -= self._br
        q_x = w.terminal_diag(rb)
        for k in range(4):
            row = x[k].copy()
            row[nz] -= inp.state_ref[k]
            cost_rows.append(row)
            cost_w.append(w.terminal * float(q_x[k]))
        for j in range(h):
            for k in range(3):
                row = np.zeros(nz + 1)
                row[self.p_index(j + 1) + k] = 1.0
                if j == 0:
                    row[nz] = -p0[k]
                else:
                    row[self.p_index(j) + k] = -1.0
                cost_rows.append(row)
                cost_w.append(w.step * float(w.step_matrix[k]))
                track = np.zeros(nz + 1)
                track[self.p_index(j + 1) + k] = 1.0
                track[nz] = -inp.footsteps_ref[j, k]
                cost_rows.append(track)
                cost_w.append(opt.track)
        f_mat = np.array(cost_rows)
        wts = np.array(cost_w)
        fz, fc = f_mat[:, :nz], f_mat[:, nz]
        hess = 2.0 * (fz.T * wts) @ fz
        lin = 2.0 * (fz.T * wts) @ fc
        const = float(np.sum(wts * fc * fc))
        rows, lo, hi = self._rows(inp)
        z_lo = np.full(nz, -np.inf)
        z_hi = np.full(nz, np.inf)
        lim = self.options.torque_limits
        # the ball's octagon: its axis facets are these bounds; an ellipse at any heading lies
        # in the box of its larger semi-axis (its facets are all rows, see _rows)
        u_box = rb.u_max * math.cos(math.pi / TORQUE_SIDES) if lim is None else max(lim)
        z_lo[: self.nu], z_hi[: self.nu] = -u_box, u_box
        for j in range(1, h + 1):
            ip = self.p_index(j)
            z_lo[ip : ip + 3], z_hi[ip : ip + 3] = self._box[0], self._box[1]
        return _Qp(hess, lin, const, rows, lo, hi, z_lo, z_hi, x)

    def _rows(self, inp: HorizonInput) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Octagon diagonals (5.12d), reach (5.12f) and step height: ``lo <= A z <= hi``."""
        h, nz, rb = self.h, self.nz, self.robot
        rows: list[FloatArray] = []
        lo: list[float] = []
        hi: list[float] = []
        lim = self.options.torque_limits
        # the ball's octagon: its axis rows are the variable bounds, its two diagonal rows here;
        # an ellipse's octagon: its four facet pairs here (two-sided rows)
        diag = rb.u_max * math.cos(math.pi / TORQUE_SIDES) * math.sqrt(2.0)
        half = TORQUE_SIDES // 2
        for j in range(h):
            if lim is not None:
                normals, bounds = torque_facets(rb.u_max, lim, float(inp.headings[j]))
            for blk in range(self.blocks):
                iu = self.u_index(j, blk)
                if lim is None:
                    for sx in (1.0, -1.0):
                        row = np.zeros(nz)
                        row[iu], row[iu + 1] = 1.0, sx
                        rows.append(row)
                        lo.append(-diag)
                        hi.append(diag)
                    continue
                for k in range(half):
                    row = np.zeros(nz)
                    row[iu], row[iu + 1] = normals[k]
                    rows.append(row)
                    lo.append(-float(bounds[k]))
                    hi.append(float(bounds[k]))
        sides = [inp.stance]
        for _ in range(h):
            sides.append(sides[-1].other)
        p0 = inp.stance_foot
        for j in range(h):
            g, hh = self.robot.reach.halfspaces(sides[j])
            a = g @ rot2(float(inp.headings[j])).T  # (Rot g)^T d for each row
            ip = self.p_index(j + 1)
            for r in range(len(hh)):
                row = np.zeros(nz)
                row[ip : ip + 2] = a[r]
                rhs = float(hh[r])
                if j == 0:
                    rhs += float(a[r] @ p0[:2])
                else:
                    iq = self.p_index(j)
                    row[iq : iq + 2] -= a[r]
                rows.append(row)
                lo.append(-np.inf)
                hi.append(rhs)
            row = np.zeros(nz)
            row[ip + 2] = 1.0
            offs = 0.0
            if j == 0:
                offs = float(p0[2])
            else:
                row[self.p_index(j) + 2] = -1.0
            rows.append(row)
            lo.append(offs - rb.step_height_max)
            hi.append(offs + rb.step_height_max)
        return np.array(rows), np.array(lo), np.array(hi)

    # ---------------------------------------------------------------- candidates
    def candidates(self, inp: HorizonInput) -> list[list[int]]:
        """For each step 1..H, the regions it could stand in: those whose box meets the box of
        every point within ``j`` reach radii and ``j`` step heights of p_0 (conservative: no
        region a feasible plan uses is left out)."""
        p0 = inp.stance_foot
        reach = np.array([self.robot.reach.radius] * 2 + [self.robot.step_height_max])
        out: list[list[int]] = []
        for j in range(1, self.h + 1):
            lo, hi = p0 - j * reach, p0 + j * reach
            meets = np.all(self._lo <= hi + _BOX_TOL, axis=1) & np.all(
                self._hi >= lo - _BOX_TOL, axis=1
            )
            out.append(np.flatnonzero(meets).tolist())
        return out

    # ---------------------------------------------------------------- node QP
    def _node(
        self, qp: _Qp, assigned: Sequence[int], cands: list[list[int]], start: FloatArray | None
    ) -> tuple[int, float, FloatArray | None]:
        """Solve the node with steps 1..len(assigned) in their regions and the later ones in the
        box of their candidates: ``(daqp exit flag, bound, z)``."""
        z_lo, z_hi = qp.z_lo.copy(), qp.z_hi.copy()
        extra: list[FloatArray] = []
        e_lo: list[float] = []
        e_hi: list[float] = []
        sense_eq: list[bool] = []
        for j in range(1, self.h + 1):
            ip = self.p_index(j)
            if j <= len(assigned):
                reg = self.regions[assigned[j - 1]]
                row = np.zeros(self.nz)
                row[ip : ip + 3] = reg.normal
                extra.append(row)
                e_lo.append(-reg.offset)
                e_hi.append(-reg.offset)
                sense_eq.append(True)
                for a_r, b_r in zip(reg.a, reg.b, strict=True):
                    row = np.zeros(self.nz)
                    row[ip : ip + 2] = a_r
                    extra.append(row)
                    e_lo.append(-np.inf)
                    e_hi.append(float(b_r))
                    sense_eq.append(False)
                box_lo, box_hi = reg.lo, reg.hi
            else:
                members = [self.regions[r] for r in cands[j - 1]]
                box_lo = np.min([m.lo for m in members], axis=0)
                box_hi = np.max([m.hi for m in members], axis=0)
            z_lo[ip : ip + 3] = np.maximum(z_lo[ip : ip + 3], box_lo)
            z_hi[ip : ip + 3] = np.minimum(z_hi[ip : ip + 3], box_hi)
        if np.any(z_lo > z_hi):
            return _DAQP_INFEASIBLE, math.inf, None
        a_mat = np.vstack([qp.rows, *extra]) if extra else qp.rows
        b_hi = np.concatenate([z_hi, qp.hi, e_hi])
        b_lo = np.concatenate([z_lo, qp.lo, e_lo])
        # daqp takes +-1e30 as "no bound"
        b_hi = np.where(np.isfinite(b_hi), b_hi, 1e30)
        b_lo = np.where(np.isfinite(b_lo), b_lo, -1e30)
        sense = np.zeros(len(b_hi), dtype=np.int32)
        if sense_eq:
            n_base = self.nz + len(qp.hi)
            sense[n_base:][np.array(sense_eq)] = 5
        kwargs = {} if start is None else {"primal_start": start}
        z, fval, flag, _ = self._daqp.solve(qp.hess, qp.lin, a_mat, b_hi, b_lo, sense, **kwargs)
        if flag in _DAQP_SOLVED:
            return flag, float(fval) + qp.const, np.asarray(z, dtype=float)
        return flag, math.inf, None

    # ---------------------------------------------------------------- search
    def solve(self, inp: HorizonInput, warm: Sequence[str] | None = None) -> HorizonSolution:
        """Plan H footsteps from ``inp`` (see the module docstring).

        Args:
            inp: the tick's stance, measured state and plan ahead.
            warm: region names of the previous solution for steps 1..H
                (:meth:`HorizonSolution.next_regions`); that leaf is solved first. Names not in
                the scene raise; a warm start never changes the optimum, only the work.
        """
        t0 = self.clock()
        self.check_input(inp)
        warm_idx: tuple[int, ...] | None = None
        if warm is not None:
            names = list(warm)
            if len(names) != self.h:
                raise InputError("warm", names, f"{self.h} region names")
            for n in names:
                if n not in self._names:
                    raise InputError("warm", n, f"a region of the scene ({', '.join(self._names)})")
            warm_idx = tuple(self._names.index(n) for n in names)
        qp = self._condense(inp)
        cands = self.candidates(inp)
        gap_tol = self.options.gap
        inc_obj: float = math.inf
        inc_z: FloatArray | None = None
        inc_regions: tuple[int, ...] = ()
        nodes, failed, warm_used = 0, 0, False

        def offer(bound: float, z: FloatArray, leaf: tuple[int, ...]) -> None:
            nonlocal inc_obj, inc_z, inc_regions
            if bound < inc_obj:
                inc_obj, inc_z, inc_regions = bound, z, leaf

        if any(not c for c in cands):
            return self._result(
                "infeasible",
                qp,
                None,
                (),
                math.inf,
                math.inf,
                0,
                False,
                t0,
                "a footstep has no region within reach",
            )
        limit = self.options.node_limit
        heap: list[tuple[float, int, tuple[int, ...], FloatArray | None]] = []
        # the least bound of every subtree left unexplored: pruned within the gap, cut off by
        # the node limit, or lost to a failed solve (-inf: nothing is known of it)
        dropped = math.inf
        flag, val, z = self._node(qp, (), cands, None)
        nodes += 1
        counter = 0
        if z is not None:
            heap.append((val, counter, (), z))
        elif flag != _DAQP_INFEASIBLE:
            failed += 1
            dropped = -math.inf
        fits = warm_idx is not None and all(r in c for r, c in zip(warm_idx, cands, strict=True))
        if fits and heap and nodes < limit:
            assert warm_idx is not None
            flag, val, z = self._node(qp, warm_idx, cands, heap[0][3])
            nodes += 1
            if z is not None:
                offer(val, z, warm_idx)
                warm_used = True
        limit_hit = False
        while heap:
            bound, _, assigned, zp = heap[0]
            if self._closed(bound, inc_obj, gap_tol):
                break
            if nodes >= limit:
                limit_hit = True
                break
            heapq.heappop(heap)
            depth = len(assigned)
            order = sorted(cands[depth], key=lambda r: self._distance(r, zp, depth + 1))
            for r in order:
                child = (*assigned, r)
                if child == warm_idx and warm_used:
                    continue  # solved first (an infeasible warm leaf is solved again: cheap)
                if nodes >= limit:  # the rest of this node's children stay unexplored
                    limit_hit = True
                    dropped = min(dropped, bound)
                    break
                flag, val, z = self._node(qp, child, cands, zp)
                nodes += 1
                if z is None:
                    if flag != _DAQP_INFEASIBLE:
                        failed += 1
                        dropped = -math.inf
                    continue
                if len(child) == self.h:
                    offer(val, z, child)
                elif self._closed(val, inc_obj, gap_tol):
                    dropped = min(dropped, val)
                else:
                    counter += 1
                    heapq.heappush(heap, (val, counter, child, z))
            if limit_hit:
                break
        open_bound = heap[0][0] if heap else math.inf
        bound = min(open_bound, dropped, inc_obj)
        if inc_z is None:
            if limit_hit:
                status, msg = (
                    "node_limit",
                    f"no plan found within {self.options.node_limit} QP solves",
                )
            elif failed:
                status, msg = "failed", f"{failed} node QPs failed in daqp and no plan was found"
            else:
                status, msg = (
                    "infeasible",
                    "no footsteps in the regions satisfy reach, step height and torque limits",
                )
            return self._result(
                status,
                qp,
                None,
                (),
                math.inf if status == "infeasible" else bound,
                math.inf,
                nodes,
                warm_used,
                t0,
                msg,
            )
        gap = relative_gap(inc_obj, bound)
        if limit_hit:
            status, msg = (
                "node_limit",
                f"node limit {self.options.node_limit} reached; gap {gap:.3g}",
            )
        elif failed:
            status, msg = "feasible", f"{failed} node QPs failed in daqp: not proven optimal"
        else:
            status, msg = "optimal", f"optimal within gap {gap_tol:g}"
        return self._result(
            status, qp, inc_z, inc_regions, bound, inc_obj, nodes, warm_used, t0, msg
        )

    @staticmethod
    def _closed(bound: float, inc: float, gap: float) -> bool:
        """True when a node of ``bound`` cannot improve ``inc`` by more than the relative gap."""
        if not math.isfinite(inc):
            return False
        return bound >= inc or relative_gap(inc, bound) <= gap

    def _distance(self, r: int, z: FloatArray | None, step: int) -> float:
        """How far the relaxed footstep ``step`` lies outside region ``r`` (child order)."""
        if z is None:
            return 0.0
        reg = self.regions[r]
        xy = z[self.p_index(step) : self.p_index(step) + 2]
        return float(np.max(reg.a @ xy - reg.b))

    def _result(
        self,
        status: str,
        qp: _Qp,
        z: FloatArray | None,
        regions: tuple[int, ...],
        bound: float,
        objective: float,
        nodes: int,
        warm_used: bool,
        t0: float,
        message: str,
    ) -> HorizonSolution:
        h, nz = self.h, self.nz
        if z is None:
            steps, torques, final = (
                np.zeros((0, 3)),
                np.zeros((0, self.blocks, 2)),
                np.full(4, np.nan),
            )
            objective = math.nan
            gap = math.inf
        else:
            steps = z[self.nu :].reshape(h, 3).copy()
            torques = z[: self.nu].reshape(h, self.blocks, 2).copy()
            final = qp.terminal[:, :nz] @ z + qp.terminal[:, nz]
            gap = relative_gap(objective, bound)
        return HorizonSolution(
            status=status,
            footsteps=steps,
            regions=tuple(self._names[r] for r in regions),
            torques=torques,
            final_state=final,
            objective=objective,
            bound=bound,
            gap=gap,
            nodes=nodes,
            warm_used=warm_used,
            solve_time=self.clock() - t0,
            message=message,
        )


def horizon_input(
    plan: FootstepPlan,
    step: int,
    time_left: float,
    alip_state: FloatArray,
    horizon: int = DEFAULT_HORIZON,
) -> HorizonInput:
    """The :class:`HorizonInput` of a tick while standing on ``plan``'s footstep ``step``.

    Args:
        plan: a full-horizon plan with ALIP states (``plan.states`` (N, K, 4)).
        step: the footstep stood on (0..N - H).
        time_left: time left in its single support [s].
        alip_state: the measured state (4,) relative to that footstep.
        horizon: H.
    """
    if not plan.has_solution or plan.states is None or len(plan.states) == 0:
        raise InputError("plan", plan.planner, "a plan with footsteps and ALIP states")
    n = plan.n_steps
    if isinstance(step, bool) or not isinstance(step, int) or not 0 <= step <= n - horizon:
        raise InputError(
            "step", step, f"a footstep index in 0..{n - horizon} (N = {n}, H = {horizon})"
        )
    state_ref = plan.final_state if step + horizon == n else plan.states[step + horizon, 0]
    return HorizonInput(
        stance=plan.sides[step],
        stance_foot=plan.footsteps[step],
        alip_state=alip_state,
        time_left=time_left,
        headings=plan.headings[step : step + horizon + 1],
        footsteps_ref=plan.footsteps[step + 1 : step + horizon + 1],
        state_ref=state_ref,
    )
