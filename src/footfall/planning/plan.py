"""The result every footstep planner returns, and the planner options."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import check_fields, instance_of, non_negative, positive
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.solvers import DEFAULT_SOLVER, KNOWN_BACKENDS
from footfall.solvers.base import SolverOptions, SolverResult, SolveStatus
from footfall.solvers.settings import BnbSettings
from footfall.terrain.scene import Scene, robot_to_dict

#: sides M of the regular polygon inscribed in the swing disc ``||d|| <= L_swing`` (option
#: ``swing_max``, eq. rows of :mod:`footfall.planning.miqcqp` and the reachable sets of
#: :mod:`footfall.planning.bounds`): 16 facets lose at most 1 - cos(pi / 16) = 1.9 % of L_swing
#: (about 1 cm)
SWING_SIDES = 16

PLANNERS = ("miqcqp", "kinematic", "reactive")
#: the words of plan.json's ``alip.layout`` (see :meth:`FootstepPlan.to_dict`)
ALIP_LAYOUT = (
    "states[i] are the K nodes of single support on footstep i (stance_footstep[i] = i), "
    "measured from footstep i; torques[i] act during that support; final_state is measured "
    "from footstep N"
)


@dataclass(frozen=True)
class PlannerWeights:
    """Weights of the objective (5.11). Defaults are chosen so each term is O(1) on a 10-step walk.

    Attributes:
        torque: Q_u = torque * I, on every ankle torque [1/(N m)^2]. 1e-3 makes a 30 N m torque
            held over a node cost about 1.
        terminal: lambda_x, on the terminal-state error.
        terminal_state: diagonal of the norm on ``x_N - x_goal``: CoM position [1/m^2] and angular
            momentum [1/(kg m^2/s)^2]; the momentum entries default to ``1/(m z_H)^2`` so they
            weigh the CoM velocity error in (m/s)^2 (set per robot by :func:`terminal_scale`).
        heading: lambda_theta, on the heading second difference [1/rad^2].
        step: lambda_l, on the step vectors.
        step_matrix: diagonal of Q_l on (p_{i+1} - p_i) [1/m^2] (x, y, z).
    """

    torque: float = 1e-3
    terminal: float = 10.0
    terminal_state: tuple[float, float, float, float] | None = None
    heading: float = 1.0
    step: float = 1.0
    step_matrix: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def __post_init__(self) -> None:
        check_fields(
            self, non_negative, ("torque", "terminal", "heading", "step"), prefix="weights."
        )

    def terminal_diag(self, robot: BipedParams) -> FloatArray:
        """Diagonal of the terminal norm for ``robot`` (see ``terminal_state``)."""
        if self.terminal_state is not None:
            return np.asarray(self.terminal_state, dtype=float)
        mzh = robot.mass * robot.com_height
        return np.array([1.0, 1.0, 1.0 / mzh**2, 1.0 / mzh**2])


#: most footsteps N a horizon planner accepts (the problem grows linearly in N; the built-in
#: scenes need at most 20)
MAX_STEPS = 200
#: most heading segments L (eq. 5.12g-h): one binary per segment and footstep
MAX_HEADING_SEGMENTS = 1024


def available_cores() -> int:
    """Cores this process may run on (the affinity mask where the OS reports one)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


@dataclass(frozen=True)
class PlannerOptions:
    """Options of the footstep planners.

    Attributes:
        weights: objective weights (eq. 5.11).
        heading_segments: L, number of sin/cos segments over a full turn (eq. 5.12g-h).
        solver: backend name: ``bnb`` (default: footfall's exact branch and bound for this
            problem, falls back to SCIP for other structures), ``scip`` (the direct model on
            SCIP), ``gurobi`` (optional).
        time_limit: solver wall-time limit [s]; in the smallest-N search
            (:func:`~footfall.planning.run.plan_min_steps`) each N tried gets this long, its
            checks before the solve included. A MIQCQP solve that finds no plan in it is
            followed by the heading-window search for as long again (``heading_windows``).
        gap: relative optimality gap at which the solver stops.
        threads: solver threads; for ``bnb``, the forked worker processes that solve node
            relaxations in parallel (1, the default: the serial search in the calling process, so
            a library call starts no processes unless asked; the CLI passes 2, the benchmark
            machine's cores). A worker that dies stops the solve with ``bnb.WorkerError``.
        verbose: print the solver log.
        momentum_bound: bound on |L| as a CoM speed [m/s] (|L| <= m z_H * bound); a physical limit
            that also gives the solver finite bounds.
        region_margin: keep every footstep at least this far inside its region's polygon [m]
            (eq. 5.18 with each edge moved inward). 0 is the document's point foothold; half the
            sole width (0.05 m) keeps the sole on narrow stones at any heading.
        reach_both_frames: beyond the document: every step ``p_{i+1} - p_i`` must lie in the
            reach set both in the stance foot's heading frame (eq. 5.12f) and in the landing
            foot's. False is the document's problem. With headings that differ between the
            feet, eq. (5.12f) alone lets the trailing foot end up beside or across the new
            stance foot in that foot's frame, and the next swing then passes through it.
        swing_max: beyond the document: bound L_swing [m] on every swing, the horizontal
            distance between consecutive footholds of the same foot,
            ``||p_{i+1} - p_{i-1}||_2 <= L_swing`` (i = 1..N; ``p_{-1}`` is the start position of
            the first swing foot). None (the default) is the document's problem. Eq. (5.12f)
            bounds each step from the other foot, so a swing may be almost twice the forward
            reach; a legged robot's swing, which must move the foot that far in T_ss + T_ds
            while the stance leg carries the body, may not allow that. Imposed as the inscribed
            regular ``SWING_SIDES``-gon (linear rows, never longer than L_swing).
        bnb: settings of the ``bnb`` backend (:class:`footfall.solvers.bnb.BnbSettings`; part of
            the plan cache key).
        heading_windows: beyond the document: when the MIQCQP's solve ends at its time limit
            without a plan, the heading-window search (:mod:`footfall.planning.windows`) gets as
            long again: headings pinned to the start-goal band except in a window of
            ``2 heading_windows + 1`` footsteps (doubled while no window has a plan). 0: no
            search. It only runs where the solve found nothing, so it changes no plan the solve
            finds.
    """

    weights: PlannerWeights = field(default_factory=PlannerWeights)
    heading_segments: int = 16
    solver: str = DEFAULT_SOLVER
    time_limit: float = 60.0
    gap: float = 1e-4
    threads: int = 1
    verbose: bool = False
    momentum_bound: float = 3.0
    region_margin: float = 0.0
    reach_both_frames: bool = False
    swing_max: float | None = None
    bnb: BnbSettings = field(default_factory=BnbSettings)
    heading_windows: int = 2

    def __post_init__(self) -> None:
        segments = self.heading_segments
        if isinstance(segments, bool) or not isinstance(segments, int):
            raise InputError(
                "heading_segments", segments, f"an integer in 4..{MAX_HEADING_SEGMENTS}"
            )
        if not 4 <= segments <= MAX_HEADING_SEGMENTS:
            raise InputError(
                "heading_segments", segments, f"an integer in 4..{MAX_HEADING_SEGMENTS}"
            )
        object.__setattr__(self, "time_limit", positive("time_limit", self.time_limit))
        object.__setattr__(self, "gap", non_negative("gap", self.gap))
        cores = available_cores()
        threads = self.threads
        if isinstance(threads, bool) or not isinstance(threads, int) or not 1 <= threads <= cores:
            raise InputError(
                "threads", threads, f"an integer in 1..{cores} (the cores this process may use)"
            )
        if self.solver not in KNOWN_BACKENDS:
            raise InputError("solver", self.solver, f"one of {', '.join(KNOWN_BACKENDS)}")
        object.__setattr__(self, "momentum_bound", positive("momentum_bound", self.momentum_bound))
        object.__setattr__(self, "region_margin", non_negative("region_margin", self.region_margin))
        if not isinstance(self.reach_both_frames, bool):
            raise InputError("reach_both_frames", self.reach_both_frames, "True or False")
        if self.swing_max is not None:
            object.__setattr__(self, "swing_max", positive("swing_max", self.swing_max))
        if not isinstance(self.bnb, BnbSettings):
            raise InputError("bnb", self.bnb, "a footfall.solvers.bnb.BnbSettings")
        windows = self.heading_windows
        if isinstance(windows, bool) or not isinstance(windows, int) or windows < 0:
            raise InputError("heading_windows", windows, "an integer >= 0 (0: no search)")

    def solver_options(self) -> SolverOptions:
        """The backend options these planner options imply."""
        return SolverOptions(
            time_limit=self.time_limit,
            gap=self.gap,
            threads=self.threads,
            verbose=self.verbose,
            bnb=self.bnb,
        )


def result_meta(result: SolverResult) -> dict[str, Any]:
    """The :class:`FootstepPlan` fields that come from a solver result."""
    return {
        "status": result.status,
        "objective": result.objective,
        "bound": result.bound,
        "gap": result.gap,
        "solve_time": result.solve_time,
        "solver": result.solver,
        "stats": dict(result.stats),
    }


@dataclass(frozen=True)
class FootstepPlan:
    """A footstep plan with its ALIP trajectory.

    Footstep 0 is the given initial stance foot; footsteps 1..N are planned. Single-support phase
    ``i`` (0..N-1) stands on footstep ``i`` and has K ALIP nodes; a double-support reset (eq. 5.8)
    moves to footstep ``i + 1``. ``final_state`` is the state after the last reset, relative to
    footstep N.

    Attributes:
        planner: ``miqcqp``, ``kinematic`` or ``reactive``.
        status: solve status.
        robot: the robot parameters used.
        footsteps: shape (N + 1, 3) [m].
        headings: shape (N + 1,) [rad].
        sides: foot of each footstep, length N + 1.
        regions: region name of each footstep, length N + 1.
        states: ALIP states per phase and node, shape (N, K, 4), relative to the stance foot.
        torques: ankle torques per phase and interval, shape (N, K - 1, 2) [N m].
        final_state: shape (4,).
        objective: objective value (nan without a solution).
        bound: proven lower bound (nan if none).
        gap: relative gap (inf if unknown).
        solve_time: planning wall time [s].
        solver: backend name (or "none" for planners without a solver).
        stats: solver statistics.
        message: human-readable explanation (diagnosis when infeasible).
        sin_cos: the piecewise-linear (sin, cos) of each heading, shape (N + 1, 2), when the
            planner models them (eq. 5.12g-h); empty otherwise.
        region_margin, reach_both_frames, swing_max: the :class:`PlannerOptions` the plan was
            made with (the checker holds the plan to them).
        heading_segments: L of the :class:`PlannerOptions` a miqcqp plan was made with (the
            conservative reach rows of each segment, eq. 5.12f-h, depend on it); None for the
            planners without heading segments.
        riser_inset: the landing tolerance [m] by which the riser edges of the scene's regions
            were moved in before planning (:func:`footfall.terrain.edges.inset_riser_edges`;
            0: the regions as they are). A walker keeps its corrected footsteps in the same
            regions the plan was made on.
    """

    planner: str
    status: SolveStatus
    robot: BipedParams
    footsteps: FloatArray
    headings: FloatArray
    sides: tuple[Side, ...]
    regions: tuple[str, ...]
    states: FloatArray
    torques: FloatArray
    final_state: FloatArray
    objective: float = math.nan
    bound: float = math.nan
    gap: float = math.inf
    solve_time: float = 0.0
    solver: str = "none"
    stats: dict[str, Any] = field(default_factory=dict)
    message: str = ""
    sin_cos: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    region_margin: float = 0.0
    reach_both_frames: bool = False
    swing_max: float | None = None
    heading_segments: int | None = None
    riser_inset: float = 0.0

    def __post_init__(self) -> None:
        """Shapes agree and every number that positions the robot is finite: a NaN footstep
        would otherwise reach the checker, the simulators and the walkers."""
        feet = np.asarray(self.footsteps, dtype=float)
        if feet.ndim != 2 or feet.shape[1] != 3:
            raise InputError("plan.footsteps", f"shape {feet.shape}", "shape (N + 1, 3)")
        rows = feet.shape[0]
        if rows > MAX_STEPS + 1:  # no planner makes more; the checker's work grows with them
            raise InputError("plan.footsteps", f"{rows} footsteps", f"at most {MAX_STEPS + 1}")
        headings = np.asarray(self.headings, dtype=float)
        if headings.shape != (rows,):
            raise InputError("plan.headings", f"shape {headings.shape}", f"shape ({rows},)")
        for name, arr in (("footsteps", feet), ("headings", headings)):
            if not np.all(np.isfinite(arr)):
                bad = int(np.argwhere(~np.isfinite(arr))[0][0])
                raise InputError(f"plan.{name}[{bad}]", arr[bad].tolist(), "finite numbers")
        object.__setattr__(self, "riser_inset", non_negative("plan.riser_inset", self.riser_inset))
        for name in ("sides", "regions"):
            if len(getattr(self, name)) != rows:
                raise InputError(f"plan.{name}", f"{len(getattr(self, name))} entries", f"{rows}")
        for name in ("states", "torques"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.ndim != 3 or arr.shape[0] > max(rows - 1, 0):
                raise InputError(f"plan.{name}", f"shape {arr.shape}", f"(n <= {rows - 1}, K, .)")
            if not np.all(np.isfinite(arr)):
                raise InputError(f"plan.{name}", "a NaN or inf entry", "finite numbers")

    @property
    def n_steps(self) -> int:
        """Number of planned footsteps N (0 when there is no solution)."""
        return max(0, self.footsteps.shape[0] - 1)

    @property
    def has_solution(self) -> bool:
        """True when the plan holds footsteps."""
        return self.footsteps.shape[0] > 0

    @property
    def reaches_goal(self) -> bool:
        """True when the plan holds footsteps that end at the goal: a solved optimisation
        (optimal, feasible, or an incumbent at the time limit) or a reactive walk that got there."""
        ok = (SolveStatus.OPTIMAL, SolveStatus.FEASIBLE, SolveStatus.TIME_LIMIT)
        return self.has_solution and self.status in ok

    @classmethod
    def empty(
        cls, planner: str, status: SolveStatus, robot: BipedParams, message: str, **kw: Any
    ) -> FootstepPlan:
        """A plan without a solution (infeasible, time limit without incumbent, error)."""
        return cls(
            planner=planner,
            status=status,
            robot=robot,
            footsteps=np.zeros((0, 3)),
            headings=np.zeros(0),
            sides=(),
            regions=(),
            states=np.zeros((0, robot.n_nodes, 4)),
            torques=np.zeros((0, robot.n_nodes - 1, 2)),
            final_state=np.full(4, np.nan),
            message=message,
            **kw,
        )

    def com_positions(self) -> FloatArray:
        """World CoM horizontal positions at every node, shape (N, K, 2) [m]."""
        return self.states[:, :, :2] + self.footsteps[: self.n_steps, None, :2]

    def zmp_offsets(self) -> FloatArray:
        """ZMP offset from the stance point at every torque node, shape (N, K - 1, 2) [m]."""
        mg = self.robot.mass * self.robot.g
        u = self.torques
        return np.stack([-u[..., 1], u[..., 0]], axis=-1) / mg

    def to_dict(self, scene_name: str = "") -> dict[str, Any]:
        """Plain-JSON dict of the plan (the ``plan.json`` of ``footfall plan``), SI units (m, rad,
        s, N m, kg m^2/s); :meth:`from_dict` reads it back.

        Keys: ``status``, ``planner``, ``scene``, ``message``, ``objective``, ``bound``, ``gap``,
        ``solve_time_s``, ``solver``, ``region_margin`` [m], ``reach_both_frames``, ``swing_max``
        [m] (null: no swing bound), ``heading_segments``, ``riser_inset`` [m], ``stats``,
        ``robot``, ``footsteps``
        (``index``, ``side``, ``position``, ``heading``, ``region``; index 0 is the initial stance
        foot) and ``alip``. Unknown numbers (NaN, inf) are null.

        ``robot`` holds every field of the robot (the scene YAML schema's ``robot:``, from
        :func:`footfall.terrain.scene.robot_to_dict`), so a reader can rebuild the robot the plan was
        made for even when it is not the scene's (a MuJoCo walker's).

        ``alip`` pairs each block of states with its footstep explicitly:

        - ``states``: N blocks, block ``i`` is the K nodes of single support on footstep ``i``
          (0..N-1; footstep 0 is the initial stance foot), measured from that footstep, each
          state laid out as ``state_layout`` (x_c, y_c [m], L_x, L_y [kg m^2/s]);
        - ``torques``: N blocks of K - 1 ankle torques (tau_x, tau_y) [N m], block ``i`` acting
          during the single support on footstep ``i``;
        - ``stance_footstep``: the footstep index of each block, ``[0, 1, ..., N-1]``;
        - ``layout``: the sentence above in words, for a reader without this docstring;
        - ``final_state``: the state after the last reset, relative to footstep N.
        """
        stats = {k: (_num(v) if isinstance(v, float) else v) for k, v in self.stats.items()}
        r = self.robot
        return {
            "status": self.status.value,
            "planner": self.planner,
            "scene": scene_name,
            "message": self.message,
            "objective": _num(self.objective),
            "bound": _num(self.bound),
            "gap": _num(self.gap),
            "solve_time_s": self.solve_time,
            "solver": self.solver,
            "region_margin": self.region_margin,
            "reach_both_frames": self.reach_both_frames,
            "swing_max": self.swing_max,
            "heading_segments": self.heading_segments,
            "riser_inset": self.riser_inset,
            "stats": stats,
            "robot": robot_to_dict(r),
            "footsteps": [
                {
                    "index": i,
                    "side": self.sides[i].value,
                    "position": self.footsteps[i].tolist(),
                    "heading": float(self.headings[i]),
                    "region": self.regions[i],
                }
                for i in range(self.footsteps.shape[0])
            ],
            "alip": {
                "state_layout": ["x_c [m]", "y_c [m]", "L_x [kg m^2/s]", "L_y [kg m^2/s]"],
                "layout": ALIP_LAYOUT,
                "stance_footstep": list(range(self.states.shape[0])),
                "states": self.states.tolist(),
                "torques": self.torques.tolist(),
                "final_state": [_num(v) for v in self.final_state],
            },
        }

    @classmethod
    def from_dict(cls, data: object, robot: BipedParams, source: str = "plan") -> FootstepPlan:
        """The plan written by :meth:`to_dict`, for ``robot`` (the file holds only part of it).

        Every field is checked (types, shapes for ``robot.n_nodes``, finite numbers, known
        statuses and sides); a bad one raises :class:`InputError` naming ``source`` and the field.
        Nothing in the file is executed: it is JSON data. ``alip.layout`` is informative and
        ignored; ``alip.stance_footstep``, when present, must be ``[0, 1, ..., N-1]`` (the only
        pairing this format has), so a file that pairs the states otherwise is refused rather than
        read with another meaning.
        """
        _check_stance_footsteps(data, source)
        return _plan_from_dict(data, robot, source)


def check_n_steps(n_steps: object) -> int:
    """``n_steps`` as the footsteps N of a plan: an integer in 1..``MAX_STEPS``, else
    :class:`InputError`."""
    if isinstance(n_steps, bool) or not isinstance(n_steps, int) or not 1 <= n_steps <= MAX_STEPS:
        raise InputError("n_steps", n_steps, f"an integer in 1..{MAX_STEPS}")
    return n_steps


def check_planning_arguments(scene: object, robot: object = None, options: object = None) -> None:
    """The argument types every planner takes: a :class:`Scene`, a :class:`BipedParams` or None,
    :class:`PlannerOptions` or None; :class:`InputError` naming the argument otherwise."""
    instance_of("scene", scene, Scene, "a Scene (footfall.terrain.resolve_scene)")
    if robot is not None:
        instance_of("robot", robot, BipedParams, "a BipedParams or None")
    if options is not None:
        instance_of("options", options, PlannerOptions, "a PlannerOptions or None")


def wrap_near(angle: float, reference: float) -> float:
    """``angle`` shifted by a multiple of 2 pi into [reference - pi, reference + pi)."""
    return reference + (angle - reference + math.pi) % (2.0 * math.pi) - math.pi


def goal_feet(robot: BipedParams, goal_xy: FloatArray, heading: float) -> dict[Side, FloatArray]:
    """Horizontal positions of the two final feet: the goal midpoint -/+ half the stance width."""
    left_normal = np.array([-math.sin(heading), math.cos(heading)])
    half = 0.5 * robot.stance_width
    return {Side.LEFT: goal_xy + half * left_normal, Side.RIGHT: goal_xy - half * left_normal}


def check_planner_name(name: str) -> str:
    """Validate a planner name."""
    if name not in PLANNERS:
        raise InputError("planner", name, f"one of {', '.join(PLANNERS)}")
    return name


def _num(v: float) -> float | None:
    """JSON has no NaN/inf: unknown numbers become null."""
    return float(v) if math.isfinite(v) else None


def _check_stance_footsteps(data: object, source: str) -> None:
    """``alip.stance_footstep`` of a plan file, when present, is ``[0, 1, ..., N-1]``."""
    alip = data.get("alip") if isinstance(data, dict) else None
    if not isinstance(alip, dict) or "stance_footstep" not in alip:
        return  # files written before the key existed
    pairing = alip["stance_footstep"]
    states = alip.get("states")
    n = len(states) if isinstance(states, list) else None
    if n is None or pairing != list(range(n)):
        want = f"[0, 1, ..., {n - 1}]" if n else "[] (one index per block of states)"
        raise InputError(f"{source}.alip.stance_footstep", pairing, want)


class _Reader:
    """Typed reads from a plan dict; errors name the field under ``source``."""

    def __init__(self, source: str) -> None:
        self.source = source

    def bad(self, fld: str, value: object, expected: str) -> InputError:
        return InputError(f"{self.source}.{fld}", value, expected)

    def get(self, d: object, key: str, where: str) -> Any:
        if not isinstance(d, dict) or key not in d:
            raise self.bad(
                where, d if not isinstance(d, dict) else sorted(d), f"an object with {key!r}"
            )
        return d[key]

    def array(
        self, value: object, fld: str, shape: tuple[int, ...], nan_ok: bool = False
    ) -> FloatArray:
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise self.bad(fld, value, f"numbers of shape {shape}") from None
        if arr.shape != shape:
            raise self.bad(fld, value, f"numbers of shape {shape}, got {arr.shape}")
        if not nan_ok and not np.all(np.isfinite(arr)):
            raise self.bad(fld, value, "finite numbers")
        return arr

    def number(self, value: object, fld: str, default: float) -> float:
        if value is None:
            return default
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.bad(fld, value, "a number or null")
        return float(value)

    def nullable_list(self, value: object, fld: str) -> list[Any]:
        """A list whose nulls (unknown numbers) become NaN."""
        if not isinstance(value, list):
            raise self.bad(fld, value, "a list of numbers or nulls")
        return [math.nan if v is None else v for v in value]

    def flag(self, value: object, fld: str) -> bool:
        if not isinstance(value, bool):
            raise self.bad(fld, value, "true or false")
        return value

    def sides(self, steps: list[Any]) -> list[Side]:
        """The side of every footstep, checking that each also names its region."""
        sides = []
        for i, st in enumerate(steps):
            side = self.get(st, "side", f"footsteps[{i}]")
            try:
                sides.append(Side(side))
            except (TypeError, ValueError):
                raise self.bad(f"footsteps[{i}].side", side, "'left' or 'right'") from None
            region = self.get(st, "region", f"footsteps[{i}]")
            if not isinstance(region, str):
                raise self.bad(f"footsteps[{i}].region", region, "a region name")
        return sides


def _plan_from_dict(data: object, robot: BipedParams, source: str) -> FootstepPlan:
    """See :meth:`FootstepPlan.from_dict`."""
    r = _Reader(source)
    bad, get, array, number = r.bad, r.get, r.array, r.number
    status_value = get(data, "status", "status")
    try:
        status = SolveStatus(status_value)
    except (TypeError, ValueError):
        raise bad("status", status_value, "a SolveStatus value") from None
    steps = get(data, "footsteps", "footsteps")
    if not isinstance(steps, list):
        raise bad("footsteps", steps, "a list of footsteps")
    n = len(steps) - 1
    if n < 0:
        return _empty_from_dict(data, status, robot)
    if n > MAX_STEPS:  # refused before any work per footstep
        raise bad("footsteps", f"{n + 1} footsteps", f"at most {MAX_STEPS + 1} (N <= {MAX_STEPS})")
    k = robot.n_nodes
    sides = r.sides(steps)
    alip = get(data, "alip", "alip")
    planner = get(data, "planner", "planner")
    if planner not in PLANNERS:
        raise bad("planner", planner, f"one of {', '.join(PLANNERS)}")
    segments = data.get("heading_segments") if isinstance(data, dict) else None
    if segments is not None and (isinstance(segments, bool) or not isinstance(segments, int)):
        raise bad("heading_segments", segments, "an integer or null")
    swing = data.get("swing_max") if isinstance(data, dict) else None
    assert isinstance(data, dict)
    positions = [get(st, "position", f"footsteps[{i}]") for i, st in enumerate(steps)]
    headings = [get(st, "heading", f"footsteps[{i}]") for i, st in enumerate(steps)]
    return FootstepPlan(
        planner=planner,
        status=status,
        robot=robot,
        footsteps=array(positions, "footsteps[].position", (n + 1, 3)),
        headings=array(headings, "footsteps[].heading", (n + 1,)),
        sides=tuple(sides),
        regions=tuple(st["region"] for st in steps),
        states=array(get(alip, "states", "alip"), "alip.states", (n, k, 4)),
        torques=array(get(alip, "torques", "alip"), "alip.torques", (n, k - 1, 2)),
        final_state=array(
            r.nullable_list(get(alip, "final_state", "alip"), "alip.final_state"),
            "alip.final_state",
            (4,),
            nan_ok=True,
        ),
        objective=number(data.get("objective"), "objective", math.nan),
        bound=number(data.get("bound"), "bound", math.nan),
        gap=number(data.get("gap"), "gap", math.inf),
        solve_time=number(data.get("solve_time_s"), "solve_time_s", 0.0),
        solver=str(data.get("solver", "none")),
        message=str(data.get("message", "")),
        region_margin=number(data.get("region_margin"), "region_margin", 0.0),
        reach_both_frames=r.flag(data.get("reach_both_frames", False), "reach_both_frames"),
        swing_max=None if swing is None else number(swing, "swing_max", math.nan),
        heading_segments=segments,
        riser_inset=number(data.get("riser_inset"), "riser_inset", 0.0),
    )


def _empty_from_dict(data: object, status: SolveStatus, robot: BipedParams) -> FootstepPlan:
    """A plan without footsteps read from ``data`` (planner, status and message only)."""
    d = data if isinstance(data, dict) else {}
    return FootstepPlan.empty(
        str(d.get("planner", "none")), status, robot, str(d.get("message", ""))
    )
