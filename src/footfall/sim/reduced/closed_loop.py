"""Closed-loop reduced-order simulation: footstep plan -> MPC (eq. 5.19) -> ALIP plant with a real foot.

Plant. The continuous ALIP dynamics (eq. 5.2-5.4) with the *true* mass and CoM height (model
mismatch options), integrated exactly (matrix exponential) with the applied torque held constant
over sub-steps of the control period; push forces switch on and off on the sub-step grid. When
nothing switches inside a control tick the sub-steps compose into the exact one-tick matrices (the
same numbers up to rounding), which keeps the loop fast. A horizontal push force ``F`` on the CoM
at height ``z_H`` changes the angular momentum about the contact point like the torque
``z_H (-F_y, F_x)``.

Foot. Each sole is a ``foot_length x foot_width`` rectangle centred on the footstep and aligned with
its planned heading. The MPC's torque command implies a centre of pressure (CoP)
``stance + (-tau_y, tau_x) / (m g)``; the ground can only put the CoP inside the sole, so the CoP
is clipped to the rectangle (in the foot frame) and the applied torque is the one of the clipped
CoP, with the true weight.

Double support. After each single support the swing foot lands at the MPC's footstep (plus the
optional placement error) and the contact point moves linearly from the old to the new foot over
``T_ds`` with no ankle torque: exactly the assumption of the reset map (eq. 5.8-5.10), integrated
here with the true parameters; the state is then re-expressed relative to the new foot.

Fall (precise definition). Let ``xi = c + v / omega`` be the ALIP's divergent component (capture
point) relative to the stance foot, in the foot's heading frame, and ``T_r`` the time left until
the next touchdown. The robot has *fallen* when, at any sample of a single support, along either
axis ``|xi| > d_0 + (d_inf + l - d_0) exp(-omega T_r)``, where ``d_0`` is the sole half-size along
that axis, ``l`` the reach of a step in that direction (bounding box of the reach trapezoid:
forward ``max x``, backward ``-min x``, sideways ``max |y|``), and
``d_inf = d_0 + l e / (1 - e)``, ``e = exp(-omega (T_ss + T_ds))``, the fixed point of the N-step
capturability recursion ``d_n = d_0 + (d_{n-1} + l - d_0) e`` (Koolen et al. 2012). The bound is
optimistic (CoP anywhere in the sole, the whole reach box, instantaneous transfer at touchdown), so
outside it no footstep sequence with the robot's timing can stop the robot: a sure fall. The run
stops at the fall. The state also counts as fallen when it becomes non-finite. Separately, the run
*stops* (comes to rest without another step) when after the last footstep the capture point lies in
the convex hull of the two final soles; ``success = not fell and stopped``.

Engines. The loop runs either in Python (the reference: numpy and the :class:`MPC` class) or
compiled with numba (:mod:`footfall.sim.reduced._kernel`, the default when numba is installed), which
mirrors it operation by operation. Both read the same inputs, built once per run (plant matrices,
noise, push table, the MPC's condensed matrices), and the metrics are computed from their
trajectories by the same code, so they agree to rounding (tests check 1e-9).

ZMP measure (document 000, section 5.5): the distance of the realised CoP from the stance foot centre
at every control tick of every single support; mean, RMS and max over the walk and per phase.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._geometry import rot2
from footfall._typing import FloatArray
from footfall._validate import check_fields, non_negative, positive
from footfall.control.adjusters import check_region_mode
from footfall.control.mpc import (
    MPC,
    SOLVERS,
    CondensedMPC,
    MPCSolution,
    MPCWeights,
    build_mpc,
)
from footfall.errors import InputError, SolverUnavailableError
from footfall.models._linear import zoh
from footfall.models.alip import ALIP
from footfall.models.biped import BipedParams
from footfall.planning.plan import FootstepPlan
from footfall.results.reduced import SimMetrics, SimResult
from footfall.sim.disturbance import Push
from footfall.sim.reduced.regions import RegionFeet, region_metrics
from footfall.terrain.region import Region

#: ways to run the loop (:attr:`SimOptions.engine`)
ENGINES = ("auto", "compiled", "python")


#: highest MPC rate [Hz]: the loop stores a sample per tick, so memory grows with the rate
MAX_CONTROL_RATE = 10_000.0


@dataclass(frozen=True)
class SimOptions:
    """Options of :func:`simulate`.

    Attributes:
        control_rate: MPC rate [Hz] (the period is adjusted so T_ss is a whole number of ticks).
        substeps: plant sub-steps per control tick (push switching resolution), >= 1.
        noise_pos: standard deviation of the CoM position estimate [m].
        noise_vel: standard deviation of the CoM velocity estimate [m/s] (momentum noise
            ``m z_H noise_vel``).
        mass_scale: true mass / model mass (model mismatch), > 0.
        com_height_scale: true CoM height / model CoM height, > 0.
        pushes: push disturbances.
        placement_error: standard deviation of the landing position error, per axis [m].
        seed: random seed of the noise and placement error.
        foot_length: sole length [m] (default: the robot's).
        foot_width: sole width [m] (default: the robot's).
        weights: MPC weights (eq. 5.19a).
        mpc_nodes: torque blocks + 1 of the MPC (default: the plan robot's K).
        solver: MPC backend, ``newton`` or ``clarabel``.
        engine: how the loop runs: ``python`` (the numpy reference), ``compiled`` (the same loop
            compiled with numba, newton solver only; same trajectories up to rounding; its speed
            is measured by ``footfall bench sim``) or ``auto`` (compiled when numba is installed
            and the solver is ``newton``).
        region_aware: ``off`` (document 000: the MPC moves the footstep freely), ``planned``
            or ``nearby``: the footstep is kept in its planned region inset by the sole, or in
            the best region within reach; ``horizon``: in the region that the short-horizon
            MIQP (:class:`footfall.planning.HorizonPlanner`, 3 footsteps from the measured state)
            chooses, re-solved at 50 Hz (:mod:`footfall.control.horizon_regions`;
            every mode but ``off`` needs the scene's regions and runs the python engine).
    """

    control_rate: float = 500.0
    substeps: int = 4
    noise_pos: float = 0.0
    noise_vel: float = 0.0
    mass_scale: float = 1.0
    com_height_scale: float = 1.0
    pushes: tuple[Push, ...] = ()
    placement_error: float = 0.0
    seed: int = 0
    foot_length: float | None = None
    foot_width: float | None = None
    weights: MPCWeights = field(default_factory=MPCWeights)
    mpc_nodes: int | None = None
    solver: str = "newton"
    engine: str = "auto"
    region_aware: str = "off"

    def __post_init__(self) -> None:
        object.__setattr__(self, "control_rate", positive("control_rate", self.control_rate))
        if self.control_rate > MAX_CONTROL_RATE:
            raise InputError("control_rate", self.control_rate, f"at most {MAX_CONTROL_RATE:g} Hz")
        check_fields(self, non_negative, ("noise_pos", "noise_vel", "placement_error"))
        check_fields(self, positive, ("mass_scale", "com_height_scale"))
        for name in ("foot_length", "foot_width"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, positive(name, getattr(self, name)))
        for name, lo in (("substeps", 1), ("seed", 0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < lo:
                raise InputError(name, v, f"an integer >= {lo}")
        if isinstance(self.pushes, Push):
            object.__setattr__(self, "pushes", (self.pushes,))
        pushes = tuple(self.pushes)
        for i, p in enumerate(pushes):
            if not isinstance(p, Push):
                raise InputError(f"pushes[{i}]", p, "a footfall.sim.Push")
            if p.force[2] != 0.0:
                raise InputError(
                    f"pushes[{i}].force",
                    p.force.tolist(),
                    "a horizontal force (z = 0): the reduced-order plant has no vertical motion",
                )
        object.__setattr__(self, "pushes", pushes)
        if not isinstance(self.weights, MPCWeights):
            raise InputError("weights", self.weights, "an MPCWeights")
        if self.solver not in SOLVERS:
            raise InputError("solver", self.solver, f"one of {', '.join(SOLVERS)}")
        if self.engine not in ENGINES:
            raise InputError("engine", self.engine, f"one of {', '.join(ENGINES)}")
        check_region_mode(self.region_aware)
        if self.engine == "compiled" and self.region_aware != "off":
            raise InputError(
                "engine",
                self.engine,
                "'python' or 'auto' with region_aware (the compiled kernel has no region rows)",
            )
        if self.engine == "compiled" and self.solver != "newton":
            raise InputError(
                "engine",
                self.engine,
                "'python' or 'auto' with solver 'clarabel' (compiled: newton)",
            )

    def to_dict(self) -> dict[str, Any]:
        """The disturbance and loop options as plain JSON data (MPC weights and sole size
        omitted: they come from the plan's robot unless set)."""
        return {
            "control_rate": self.control_rate,
            "substeps": self.substeps,
            "pushes": [p.to_dict() for p in self.pushes],
            "noise_pos": self.noise_pos,
            "noise_vel": self.noise_vel,
            "placement_error": self.placement_error,
            "mass_scale": self.mass_scale,
            "com_height_scale": self.com_height_scale,
            "seed": self.seed,
            "solver": self.solver,
            "engine": self.engine,
            "region_aware": self.region_aware,
        }


def viability_bounds(
    robot: BipedParams, omega: float, foot_length: float, foot_width: float
) -> tuple[FloatArray, FloatArray]:
    """Per-direction constants of the fall test (module docstring).

    Returns:
        ``(d0, d_plus_l)``, each (4,) for the directions (+x, -x, +y, -y) of the foot frame:
        the sole half-size ``d_0`` and ``d_inf + l - d_0`` [m].
    """
    v = robot.reach.vertices
    reach = np.array([v[:, 0].max(), -v[:, 0].min(), np.abs(v[:, 1]).max(), np.abs(v[:, 1]).max()])
    d0 = np.array([foot_length, foot_length, foot_width, foot_width]) / 2.0
    e = math.exp(-omega * (robot.t_ss + robot.t_ds))
    d_inf = d0 + reach * e / (1.0 - e)
    return d0, d_inf + reach - d0


def _in_hull(point: FloatArray, corners: FloatArray) -> bool:
    """Whether ``point`` (2,) lies in the convex hull of ``corners`` (n, 2)."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(corners)
    return bool(np.all(hull.equations[:, :2] @ point + hull.equations[:, 2] <= 1e-12))


def _sole_corners(foot: FloatArray, heading: float, length: float, width: float) -> FloatArray:
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * np.array([length, width]) / 2.0
    return np.asarray(foot[:2] + half @ rot2(heading).T)


def mpc_model(robot: BipedParams, opts: SimOptions) -> CondensedMPC:
    """The condensed MPC (eq. 5.19) the loop runs for ``robot`` with ``opts``' weights, rate and
    nodes (:func:`~footfall.control.mpc.build_mpc`; a plant that walks many plans of one robot
    builds it once and passes it to :func:`simulate`)."""
    return build_mpc(robot, opts.weights, 1.0 / opts.control_rate, opts.mpc_nodes)


def mpc_key(robot: BipedParams, opts: SimOptions) -> str:
    """What :func:`mpc_model` depends on, as text (``BipedParams`` compares by identity, and
    unpickled copies differ, but its repr describes it fully)."""
    return f"{robot!r}|{opts.weights!r}|{opts.control_rate!r}|{opts.mpc_nodes!r}"


@dataclass(frozen=True, eq=False)
class _Walk:
    """Everything the closed loop reads, built once by :func:`_prepare` and shared by both
    engines (so they differ only in how they run the loop)."""

    plan: FootstepPlan
    mdl: CondensedMPC
    solver: str
    n: int  # footsteps N
    m_ticks: int  # M, control ticks per single support
    n_ds: int  # double-support ticks
    n_sub: int  # plant sub-steps per tick
    dt: float  # control period [s]
    dt_ds: float  # double-support tick [s]
    t_ds: float  # T_ds [s]
    mg: float  # true weight [N]
    mzh: float  # true m z_H [kg m]
    omega: float  # true omega [1/s]
    half: FloatArray  # sole half-sizes (2,) [m]
    f_len: float
    f_wid: float
    goal_xy: FloatArray
    p_refs: FloatArray  # planned next footstep per phase (n, 3) [m]
    x_refs: FloatArray  # planned state after each phase's reset (n, 4)
    cos_h: FloatArray  # stance heading cosine per phase (n,)
    sin_h: FloatArray
    ad_t: FloatArray  # true one-tick ZOH (4, 4), (4, 2)
    bd_t: FloatArray
    ad_s: FloatArray  # true sub-step ZOH
    bd_s: FloatArray
    ad_ds: FloatArray  # double support, augmented with the moving contact (8, 8)
    ad_dss: FloatArray
    bd_dss: FloatArray  # (8, 2)
    push_tab: FloatArray  # (rows, n_sub, 2) [N m], row i (M + n_ds) + k
    push_any: NDArray[np.bool_]
    push_const: NDArray[np.bool_]
    noise: FloatArray  # (n M, 4)
    place_err: FloatArray  # (n, 2) [m]
    decay: FloatArray  # exp(-omega T_r) per tick (M,)
    d0: FloatArray
    d_span: FloatArray
    regions: tuple[Region, ...] = ()  # the scene's regions (region metrics, region_aware)
    region_aware: str = "off"


@dataclass
class _Trace:
    """What one engine's loop produced (sample arrays preallocated by :func:`_new_trace`)."""

    t: FloatArray
    stance: NDArray[np.int64]
    single: NDArray[np.bool_]
    com: FloatArray
    cop: FloatArray
    cop_off: FloatArray
    tau_cmd: FloatArray
    tau: FloatArray
    sat: NDArray[np.bool_]
    solve_times: FloatArray
    samples: int = 0
    feet: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    x: FloatArray = field(default_factory=lambda: np.zeros(4))
    time: float = 0.0
    fell: bool = False
    fall_time: float = math.nan
    n_solves: int = 0
    n_fallbacks: int = 0


def _true_plant(true: ALIP, dt: float, dt_ds: float, n_sub: int) -> tuple[FloatArray, ...]:
    """Exact matrices of the true plant (model mismatch): ``(Ad, Bd)`` of one tick and of one
    sub-step (eq. 5.7), and of the double support augmented with the contact point moving at
    constant velocity (eq. 5.8-5.10): ``A`` of one tick, ``(A, B)`` of one sub-step (8 states)."""
    ad_t, bd_t = true.discretize(dt)
    ad_s, bd_s = true.discretize(dt / n_sub)
    a_aug = np.zeros((8, 8))
    a_aug[:4, :4] = true.A
    a_aug[:4, 4:6] = true.E[:, :2]  # contact displacement acts like the torque E d (eq. 5.10)
    a_aug[4:6, 6:8] = np.eye(2)
    b_aug = np.zeros((8, 2))
    b_aug[2:4] = np.eye(2)
    ad_ds, _ = zoh(a_aug, b_aug, dt_ds)
    ad_dss, bd_dss = zoh(a_aug, b_aug, dt_ds / n_sub)
    return ad_t, bd_t, ad_s, bd_s, ad_ds, ad_dss, bd_dss


def _push_table(
    robot: BipedParams,
    opts: SimOptions,
    n: int,
    m_ticks: int,
    dt: float,
    n_ds: int,
    dt_ds: float,
    zh: float,
) -> FloatArray:
    """Push torque ``z_H (-F_y, F_x)`` [N m] on every plant sub-step of the walk, tabulated once:
    row ``i (M + n_ds) + k`` is tick k of phase i (k >= M: double support), columns the
    sub-steps; shape (n (M + n_ds), n_sub, 2)."""
    n_sub = opts.substeps
    starts = np.concatenate(
        [np.arange(m_ticks) * dt, robot.t_ss + np.arange(n_ds) * dt_ds]
    )  # tick start within a step
    lengths = np.concatenate([np.full(m_ticks, dt), np.full(n_ds, dt_ds)])
    step_period = robot.t_ss + robot.t_ds
    t_start = (np.arange(n)[:, None] * step_period + starts[None]).ravel()
    h_sub = np.tile(lengths, n) / n_sub
    mids = t_start[:, None] + (np.arange(n_sub)[None] + 0.5) * h_sub[:, None]
    push_tab = np.zeros((t_start.shape[0], n_sub, 2))
    for p in opts.pushes:
        on = (mids >= p.start) & (mids < p.start + p.duration)
        f = p.force[:2]
        push_tab[on] += zh * np.array([-f[1], f[0]])
    return push_tab


def _prepare(
    plan: FootstepPlan,
    opts: SimOptions,
    goal: FloatArray | None,
    regions: tuple[Region, ...] = (),
    mdl: CondensedMPC | None = None,
) -> _Walk:
    robot = plan.robot
    n = plan.n_steps
    if mdl is None:
        mdl = mpc_model(robot, opts)
    dt, m_ticks = mdl.control_dt, mdl.n_ticks
    n_ds = max(1, round(robot.t_ds / dt))
    dt_ds = robot.t_ds / n_ds
    n_sub = opts.substeps
    f_len = opts.foot_length or robot.foot_length
    f_wid = opts.foot_width or robot.foot_width
    goal_xy = (
        0.5 * (plan.footsteps[-1, :2] + plan.footsteps[-2, :2])
        if goal is None
        else np.asarray(goal, dtype=float)[:2]
    )

    true = ALIP(robot.mass * opts.mass_scale, robot.com_height * opts.com_height_scale, robot.g)
    mzh, zh = true.mass * true.com_height, true.com_height
    ad_t, bd_t, ad_s, bd_s, ad_ds, ad_dss, bd_dss = _true_plant(true, dt, dt_ds, n_sub)
    d0, d_span = viability_bounds(robot, true.omega, f_len, f_wid)
    push_tab = _push_table(robot, opts, n, m_ticks, dt, n_ds, dt_ds, zh)

    rng = np.random.default_rng(opts.seed)
    noise = rng.standard_normal((n * m_ticks, 4)) * np.array(
        [opts.noise_pos, opts.noise_pos, mzh * opts.noise_vel, mzh * opts.noise_vel]
    )
    place_err = rng.standard_normal((n, 2)) * opts.placement_error
    x_refs = np.array([plan.states[i + 1, 0] if i + 1 < n else plan.final_state for i in range(n)])
    heads = [float(plan.headings[i]) for i in range(n)]
    return _Walk(
        plan=plan,
        mdl=mdl,
        solver=opts.solver,
        n=n,
        m_ticks=m_ticks,
        n_ds=n_ds,
        n_sub=n_sub,
        dt=dt,
        dt_ds=dt_ds,
        t_ds=robot.t_ds,
        mg=true.mass * true.g,
        mzh=mzh,
        omega=true.omega,
        half=np.array([f_len, f_wid]) / 2.0,
        f_len=f_len,
        f_wid=f_wid,
        goal_xy=goal_xy,
        p_refs=np.array(plan.footsteps[1 : n + 1], dtype=float),
        x_refs=np.asarray(x_refs, dtype=float).reshape(n, 4),
        cos_h=np.array([math.cos(h) for h in heads]),
        sin_h=np.array([math.sin(h) for h in heads]),
        ad_t=ad_t,
        bd_t=bd_t,
        ad_s=ad_s,
        bd_s=bd_s,
        ad_ds=ad_ds,
        ad_dss=ad_dss,
        bd_dss=bd_dss,
        push_tab=push_tab,
        push_any=np.asarray(push_tab.any(axis=(1, 2)), dtype=bool),
        push_const=np.asarray(np.all(push_tab == push_tab[:, :1], axis=(1, 2)), dtype=bool),
        noise=noise,
        place_err=place_err,
        # exp(-omega T_r) of the fall bound for every tick (T_r = time to touchdown)
        decay=np.exp(-true.omega * (m_ticks - 1 - np.arange(m_ticks)) * dt),
        d0=d0,
        d_span=d_span,
        regions=regions,
        region_aware=opts.region_aware,
    )


def _new_trace(w: _Walk) -> _Trace:
    total = w.n * (w.m_ticks + w.n_ds)
    return _Trace(
        t=np.zeros(total),
        stance=np.zeros(total, dtype=np.int64),
        single=np.zeros(total, dtype=bool),
        com=np.zeros((total, 2)),
        cop=np.zeros((total, 2)),
        cop_off=np.zeros((total, 2)),
        tau_cmd=np.zeros((total, 2)),
        tau=np.zeros((total, 2)),
        sat=np.zeros(total, dtype=bool),
        solve_times=np.zeros(w.n * w.m_ticks),
    )


def _walk_python(w: _Walk) -> _Trace:
    """The reference loop (numpy, the :class:`MPC` class); see the module docstring."""
    return _PythonLoop(w).run()


class _PythonLoop:
    """The reference loop's state between ticks: true ALIP state, time, landed feet, samples.

    Each phase ``i`` is a single support (an MPC solve, the clipped CoP and the plant per tick,
    then the fall test) followed by the double support with the moving contact.
    """

    def __init__(self, w: _Walk) -> None:
        self.w = w
        self.tr = _new_trace(w)
        self.mpc = MPC(w.mdl, w.solver)
        self.region_feet = (
            RegionFeet(w.plan, w.regions, w.region_aware, self.mpc, w.f_len, w.f_wid)
            if w.region_aware != "off"
            else None
        )
        self.x = np.array(w.plan.states[0, 0], dtype=float)
        self.feet = [np.array(w.plan.footsteps[0], dtype=float)]
        self.fell = False
        self.fall_time = math.nan
        self.j = 0  # sample index
        self.t = 0.0
        self.n_solve = 0

    def run(self) -> _Trace:
        """Walk every phase until the end or a fall; the trace of the walk."""
        for i in range(self.w.n):
            sol = self.single_support(i)
            if self.fell:
                break
            assert sol is not None
            self.double_support(i, sol)
            if self.fell:
                break
        tr = self.tr
        tr.samples, tr.feet, tr.x, tr.time = self.j, np.array(self.feet), self.x, self.t
        tr.fell, tr.fall_time = self.fell, self.fall_time
        tr.solve_times = tr.solve_times[: self.n_solve]
        tr.n_solves, tr.n_fallbacks = self.mpc.n_solves, self.mpc.n_fallbacks
        return tr

    def single_support(self, i: int) -> MPCSolution | None:
        """The M ticks of phase ``i``'s single support; the last MPC solution."""
        w = self.w
        stance = self.feet[-1]
        p_ref = w.p_refs[i]
        sol = None
        cth, sth = float(w.cos_h[i]), float(w.sin_h[i])
        theta = np.empty(10)
        theta[4:6] = p_ref[:2] - stance[:2]
        theta[6:] = w.x_refs[i]
        for k in range(w.m_ticks):
            theta[:4] = self.x
            theta[:4] += w.noise[i * w.m_ticks + k]
            if self.region_feet is None:
                sol = self.mpc.solve_theta(k, theta, stance, p_ref)
            else:
                sol = self.region_feet.solve(i, k, theta, stance, p_ref)
            self.tr.solve_times[self.n_solve] = sol.solve_time
            self.n_solve += 1
            u = self._apply(i, stance, sol.torques[0], cth, sth)
            self._plant(i * (w.m_ticks + w.n_ds) + k, u)
            self.t += w.dt
            if self._falls(k, cth, sth):
                self.fell, self.fall_time = True, self.t
                break
        return sol

    def _apply(
        self, i: int, stance: FloatArray, u_cmd: FloatArray, c: float, s: float
    ) -> FloatArray:
        """Record the tick and return the applied torque: the command's CoP in the foot frame
        (heading cosine ``c``, sine ``s``) clipped to the sole (the foot rolls otherwise)."""
        w, tr, j = self.w, self.tr, self.j
        mg, hx, hy = w.mg, float(w.half[0]), float(w.half[1])
        cwx, cwy = -float(u_cmd[1]) / mg, float(u_cmd[0]) / mg
        ox, oy = c * cwx + s * cwy, -s * cwx + c * cwy
        cx, cy = min(max(ox, -hx), hx), min(max(oy, -hy), hy)
        wx, wy = c * cx - s * cy, s * cx + c * cy
        u = np.array([mg * wy, -mg * wx])
        tr.t[j], tr.stance[j], tr.single[j] = self.t, i, True
        tr.com[j] = stance[:2] + self.x[:2]
        tr.cop[j] = (stance[0] + wx, stance[1] + wy)
        tr.cop_off[j], tr.tau_cmd[j], tr.tau[j] = (cx, cy), u_cmd, u
        tr.sat[j] = cx != ox or cy != oy
        self.j += 1
        return u

    def _plant(self, jt: int, u: FloatArray) -> None:
        """One control tick of the true plant (eq. 5.7) under ``u`` and the pushes of row ``jt``."""
        w = self.w
        x = self.x
        if not w.push_any[jt]:
            x = w.ad_t @ x + w.bd_t @ u
        elif w.push_const[jt]:
            x = w.ad_t @ x + w.bd_t @ (u + w.push_tab[jt, 0])
        else:
            for q in range(w.n_sub):
                x = w.ad_s @ x + w.bd_s @ (u + w.push_tab[jt, q])
        self.x = x

    def _falls(self, k: int, c: float, s: float) -> bool:
        """The fall test on the true state after tick ``k`` (module docstring)."""
        w, x = self.w, self.x
        if not np.isfinite(x).all():
            return True
        kxi = 1.0 / (w.mzh * w.omega)
        gx, gy = float(x[0] + kxi * x[3]), float(x[1] - kxi * x[2])
        fx, fy = c * gx + s * gy, -s * gx + c * gy
        d0, d_span, e = w.d0, w.d_span, w.decay[k]
        return bool(
            fx > d0[0] + d_span[0] * e
            or -fx > d0[1] + d_span[1] * e
            or fy > d0[2] + d_span[2] * e
            or -fy > d0[3] + d_span[3] * e
        )

    def double_support(self, i: int, sol: MPCSolution) -> None:
        """Phase ``i``'s double support: the contact point moves linearly to the new foot
        (eq. 5.8-5.10); then the state is re-expressed relative to the new stance foot."""
        w, tr = self.w, self.tr
        stance = self.feet[-1]
        p_next = np.array(sol.next_footstep, dtype=float)
        p_next[:2] += w.place_err[i]
        delta = p_next[:2] - stance[:2]
        s_aug = np.concatenate([self.x, np.zeros(2), delta / w.t_ds])
        for k in range(w.n_ds):
            tr.t[self.j], tr.stance[self.j] = self.t, i
            tr.com[self.j] = stance[:2] + s_aug[:2]
            tr.cop[self.j] = stance[:2] + s_aug[4:6]
            self.j += 1
            jt = i * (w.m_ticks + w.n_ds) + w.m_ticks + k
            if not w.push_any[jt]:
                s_aug = w.ad_ds @ s_aug
            else:
                for q in range(w.n_sub):
                    s_aug = w.ad_dss @ s_aug + w.bd_dss @ w.push_tab[jt, q]
            self.t += w.dt_ds
        x = s_aug[:4].copy()
        x[:2] -= delta
        self.x = x
        self.feet.append(p_next)
        if not np.all(np.isfinite(x)):
            self.fell, self.fall_time = True, self.t


def _walk_compiled(w: _Walk) -> _Trace:
    """The same loop in the numba kernel :func:`footfall.sim.reduced._kernel.walk`."""
    from footfall.control.ball_qp import DUAL_TOL, MAX_NEWTON_ITER
    from footfall.sim.reduced import _kernel as kernel

    tr = _new_trace(w)
    pad = w.mdl.padded
    plan = w.plan
    feet = np.zeros((w.n + 1, 3))
    x_out = np.zeros(4)
    mem = np.zeros(kernel.MEM_SIZE, dtype=np.int64)
    mem[kernel.MEM_LAST_K] = -1
    scalars = np.array(
        [w.dt, w.dt_ds, w.t_ds, w.mg, 1.0 / (w.mzh * w.omega), float(w.half[0]), float(w.half[1])]
    )
    samples, n_feet, fell, fall_time, t = kernel.walk(
        np.array(plan.states[0, 0], dtype=float),
        np.array(plan.footsteps[0], dtype=float),
        (w.p_refs, w.x_refs, w.cos_h, w.sin_h),
        (
            pad.n_b,
            pad.first_block,
            pad.gain,
            pad.q_map,
            pad.p_scaled,
            pad.d_theta,
            pad.d_u,
            pad.u_limits,
        ),
        (DUAL_TOL, MAX_NEWTON_ITER),
        (w.ad_t, w.bd_t, w.ad_s, w.bd_s, w.ad_ds, w.ad_dss, w.bd_dss),
        (w.push_tab, w.push_any, w.push_const),
        (w.noise, w.place_err),
        (w.decay, w.d0, w.d_span),
        scalars,
        w.n_ds,
        (
            tr.t,
            tr.stance,
            tr.single,
            tr.com,
            tr.cop,
            tr.cop_off,
            tr.tau_cmd,
            tr.tau,
            tr.sat,
            feet,
            tr.solve_times,
            x_out,
        ),
        mem,
    )
    tr.samples, tr.feet, tr.x, tr.time = int(samples), feet[:n_feet], x_out, float(t)
    tr.fell, tr.fall_time = bool(fell), float(fall_time)
    tr.n_solves = int(mem[kernel.MEM_SOLVES])
    tr.n_fallbacks = int(mem[kernel.MEM_FALLBACKS])
    tr.solve_times = tr.solve_times[: tr.n_solves]
    return tr


def _result(w: _Walk, tr: _Trace, engine: str, wall0: float) -> SimResult:
    """Metrics (module docstring) and the trimmed trajectories of one run."""
    plan = w.plan
    sl = slice(0, tr.samples)
    ss = tr.single[sl]
    offs = np.linalg.norm(tr.cop_off[sl][ss], axis=1)
    phase_idx = tr.stance[sl][ss]
    n_phases = int(phase_idx.max()) + 1 if offs.size else 0
    ph_mean = tuple(float(offs[phase_idx == p].mean()) for p in range(n_phases))
    ph_max = tuple(float(offs[phase_idx == p].max()) for p in range(n_phases))
    feet_arr = tr.feet
    n_landed = feet_arr.shape[0] - 1
    headings = np.array(plan.headings[: n_landed + 1], dtype=float)
    dev = np.linalg.norm(feet_arr[1:, :2] - plan.footsteps[1 : n_landed + 1, :2], axis=1)
    stopped = False
    goal_error = math.nan
    x = tr.x
    if not tr.fell:
        com_final = feet_arr[-1, :2] + x[:2]
        goal_error = float(np.linalg.norm(com_final - w.goal_xy))
        xi_final = com_final + np.array([x[3], -x[2]]) / (w.mzh * w.omega)
        corners = np.vstack(
            [_sole_corners(feet_arr[q], headings[q], w.f_len, w.f_wid) for q in (-1, -2)]
        )
        stopped = _in_hull(xi_final, corners)
    st = tr.solve_times if tr.solve_times.size else np.zeros(1)
    sat = tr.sat[sl][ss]
    off, changed = region_metrics(w.regions, plan, feet_arr) if w.regions else (None, ())
    metrics = SimMetrics(
        fell=tr.fell,
        fall_time=tr.fall_time,
        stopped=stopped,
        success=(not tr.fell) and stopped,
        zmp_offset_mean=float(offs.mean()) if offs.size else math.nan,
        zmp_offset_rms=float(np.sqrt(np.mean(offs**2))) if offs.size else math.nan,
        zmp_offset_max=float(offs.max()) if offs.size else math.nan,
        zmp_offset_phase_mean=ph_mean,
        zmp_offset_phase_max=ph_max,
        saturated_time=float(sat.sum() * w.dt),
        saturated_fraction=float(sat.mean()) if ss.any() else 0.0,
        footstep_dev_mean=float(dev.mean()) if dev.size else 0.0,
        footstep_dev_max=float(dev.max()) if dev.size else 0.0,
        goal_error=goal_error,
        steps_taken=n_landed,
        mpc_solves=tr.n_solves,
        mpc_fallbacks=tr.n_fallbacks,
        mpc_time_median=float(np.median(st)),
        mpc_time_p99=float(np.percentile(st, 99)),
        mpc_time_max=float(st.max()),
        sim_time=float(tr.time),
        wall_time=time.perf_counter() - wall0,
        engine=engine,
        footsteps_off_regions=off,
        region_changes=changed,
    )
    return SimResult(
        metrics=metrics,
        t=tr.t[sl],
        stance=tr.stance[sl],
        single=tr.single[sl],
        com=tr.com[sl],
        cop=tr.cop[sl],
        cop_offset=tr.cop_off[sl],
        torque_cmd=tr.tau_cmd[sl],
        torque=tr.tau[sl],
        saturated=tr.sat[sl],
        footsteps=feet_arr,
        plan_footsteps=np.array(plan.footsteps),
        headings=headings,
        goal=w.goal_xy,
        u_max=plan.robot.u_max,
        foot_length=w.f_len,
        foot_width=w.f_wid,
        planner=plan.planner,
    )


@functools.cache
def compiled_available() -> bool:
    """Whether the compiled engine can run (numba imports)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def resolve_engine(options: SimOptions) -> str:
    """The engine :func:`simulate` runs for ``options``: ``auto`` is ``compiled`` when numba is
    installed, the MPC solver is ``newton`` and ``region_aware`` is off, else ``python``.

    Raises:
        SolverUnavailableError: ``engine="compiled"`` without numba.
    """
    if options.engine == "python":
        return "python"
    if options.engine == "compiled":
        if not compiled_available():
            raise SolverUnavailableError(
                "engine 'compiled' needs the package 'numba': pip install numba "
                "(or SimOptions(engine='python'))"
            )
        return "compiled"
    fast = options.solver == "newton" and options.region_aware == "off"
    return "compiled" if fast and compiled_available() else "python"


def simulate(
    plan: FootstepPlan,
    options: SimOptions | None = None,
    goal: FloatArray | None = None,
    regions: Sequence[Region] | None = None,
    mpc: CondensedMPC | None = None,
) -> SimResult:
    """Walk ``plan`` in closed loop: MPC (eq. 5.19) on the ALIP plant with a rectangular sole.

    Both engines (``options.engine``) run the same loop on the same inputs: the plant matrices,
    noise and push table are built once here, the loop runs in Python or in the compiled kernel,
    and the metrics are computed here from its trajectories.

    Args:
        plan: a footstep plan with states (its robot is the controller's model).
        options: simulation options.
        goal: goal position (2,) or (3,) [m]; default the midpoint of the last two footsteps.
        regions: the scene's regions: the region metrics are computed with them, and
            ``options.region_aware`` needs them.
        mpc: the condensed MPC of ``plan.robot`` and ``options`` (:func:`mpc_model`, keyed by
            :func:`mpc_key`); None builds it.

    Returns:
        A :class:`SimResult`. Falls are reported in the metrics, never raised.
    """
    wall0 = time.perf_counter()
    opts = options or SimOptions()
    if not isinstance(plan, FootstepPlan):
        raise InputError("plan", type(plan).__name__, "a FootstepPlan")
    if not isinstance(opts, SimOptions):
        raise InputError("options", opts, "a SimOptions")
    n = plan.n_steps
    if n < 1 or plan.states.shape[0] != n:
        raise InputError("plan", plan.message or plan.status, "a plan with at least one footstep")
    regs = tuple(regions) if regions is not None else ()
    if opts.region_aware != "off" and not regs:
        raise InputError("regions", regions, "the scene's regions (SimOptions.region_aware)")
    engine = resolve_engine(opts)
    w = _prepare(plan, opts, goal, regs, mpc)
    tr = _walk_compiled(w) if engine == "compiled" else _walk_python(w)
    return _result(w, tr, engine, wall0)


def run_report(
    scene_name: str, plan: FootstepPlan, options: SimOptions, result: SimResult
) -> dict[str, Any]:
    """What ``footfall simulate`` writes to ``sim.json``: the plan in brief, the options (with
    the engine that actually ran), the metrics and the landed footsteps."""
    return {
        "scene": scene_name,
        "planner": result.planner,
        "plan": {
            "status": plan.status.value,
            "steps": plan.n_steps,
            "planning_time": plan.solve_time,
            "message": plan.message,
            "footsteps": plan.footsteps.tolist(),
        },
        "options": options.to_dict() | {"engine": result.metrics.engine},
        "metrics": result.metrics.to_dict(),
        "footsteps": result.footsteps.tolist(),
    }
