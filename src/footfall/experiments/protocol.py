"""The field's push-recovery protocol as a benchmark.

A walking humanoid is pushed once, for ``PROTOCOL_DURATION`` (0.05 s), with a velocity change
``dv`` [m/s] (impulse = robot mass x ``dv`` [N s]), at 20 %, 45 % and 70 % of one single support
(by default the middle one of the plan), in four directions relative to the walk at the push:
forward, backward, inward (toward the stance foot's side) and outward (toward the swing foot's
side). A ``dv`` level passes only when every case (3 phases x 4 directions) walks on to the goal
without a fall; the result is the largest level at which every case passes.

:class:`PushProtocol` says what is walked (its :meth:`~PushProtocol.disturbances` are
:class:`~footfall.sim.disturbance.Disturbance`\\ s in the ``walk`` frame), :func:`run_protocol`
plans once (:func:`~footfall.sim.biped.plans.plan_for_walk`, with the plan cache) and walks every
case through the trial pipeline (:func:`~footfall.sim.trial.run_trial`, the ``mujoco`` plant),
and :func:`summarise` counts the passes per level.
"""

from __future__ import annotations

import csv
import dataclasses
import functools
import io
import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from footfall._validate import finite, positive
from footfall.errors import InfeasibleError, InputError
from footfall.sim.disturbance import Disturbance

#: push directions of the protocol in the ``walk`` frame [rad]
#: (:attr:`footfall.sim.disturbance.Disturbance.frame`)
DIRECTIONS: dict[str, float] = {
    "forward": 0.0,
    "backward": math.pi,
    "inward": math.pi / 2,
    "outward": -math.pi / 2,
}
#: phases of the single support at which the protocol pushes (shares of it)
PROTOCOL_PHASES = (0.2, 0.45, 0.7)
#: length of a protocol push [s]
PROTOCOL_DURATION = 0.05
#: the columns of a protocol row, in order
COLUMNS = (
    "dv_m_s",
    "phase",
    "direction",
    "impulse_Ns",
    "step",
    "push_start_s",
    "fell",
    "fall_time_s",
    "reached_goal",
    "success",
)


@dataclass(frozen=True)
class PushCase:
    """One walk of the protocol: a velocity change [m/s], a phase (share of the single
    support) and a direction name of :data:`DIRECTIONS`."""

    dv: float
    phase: float
    direction: str

    @property
    def label(self) -> str:
        """``direction@phase``, e.g. ``inward@0.45``."""
        return f"{self.direction}@{self.phase:g}"


@dataclass(frozen=True)
class PushProtocol:
    """What the protocol walks.

    Attributes:
        dv: the velocity-change levels [m/s], each > 0.
        phases: shares of the pushed single support at which a push starts, in [0, 1].
        directions: names of :data:`DIRECTIONS`.
        duration: push length [s].
        step: the pushed single support (0-based); None: the middle one of the plan, N // 2.
        robot: the walker (``biped``, a built-in robot name or a robot file).
        scene: a built-in scene name or a scene file.
        steps: footsteps N of the plan (None: the planner's smallest N).
        planner: ``miqcqp``, ``kinematic`` or ``reactive``.
        controller: the walker's controller (``wbc`` or ``servo``).
        region_aware: how the walker's MPC keeps footsteps on the terrain
            (:attr:`footfall.sim.biped.options.WalkOptions.region_aware`).
        leg_momentum: the share of the legs' forecast momentum the walker's MPC carries
            (:attr:`footfall.sim.biped.options.WalkOptions.leg_momentum`; 0: off; None: the
            walker's default for ``controller``, stored resolved).
        walk_on: stopping steps the walker may add to reach the goal
            (:attr:`footfall.sim.biped.options.WalkOptions.walk_on`; 0: never; None: the
            walker's default, stored resolved).
        step_timing: whether the walker's MPC may end a single support sooner
            (:attr:`footfall.sim.biped.options.WalkOptions.step_timing`; None: the walker's
            default, stored resolved).
    """

    dv: tuple[float, ...]
    phases: tuple[float, ...] = PROTOCOL_PHASES
    directions: tuple[str, ...] = tuple(DIRECTIONS)
    duration: float = PROTOCOL_DURATION
    step: int | None = None
    robot: str = "biped"
    scene: str = "flat_long"
    steps: int | None = None
    planner: str = "miqcqp"
    controller: str = "wbc"
    region_aware: str = "horizon"  # WalkOptions.region_aware's default (a test keeps them equal)
    leg_momentum: float | None = None
    walk_on: int | None = None
    step_timing: bool | None = None

    def __post_init__(self) -> None:
        from footfall.control.adjusters import check_region_mode
        from footfall.sim.biped.options import CONTROLLERS, WalkOptions

        check_region_mode(self.region_aware)
        if self.controller in CONTROLLERS:  # an unknown controller: run_protocol says so
            walker = WalkOptions(controller=self.controller, leg_momentum=self.leg_momentum)
            if self.walk_on is not None:
                walker = dataclasses.replace(walker, walk_on=self.walk_on)
            if self.step_timing is not None:
                walker = dataclasses.replace(walker, step_timing=self.step_timing)
            object.__setattr__(self, "walk_on", walker.walk_on)
            object.__setattr__(self, "step_timing", walker.step_timing)
            object.__setattr__(self, "leg_momentum", walker.legs_share)
        dv = tuple(finite("dv [m/s]", v) for v in self.dv)
        if not dv or any(v <= 0 for v in dv) or len(set(dv)) != len(dv):
            raise InputError("dv [m/s]", list(self.dv), "distinct velocity changes > 0")
        object.__setattr__(self, "dv", tuple(sorted(dv)))
        phases = tuple(finite("phases", p) for p in self.phases)
        if (
            not phases
            or any(not 0.0 <= p <= 1.0 for p in phases)
            or len(set(phases)) != len(phases)
        ):
            raise InputError("phases", list(self.phases), "distinct shares in [0, 1]")
        object.__setattr__(self, "phases", phases)
        dirs = tuple(self.directions)
        if not dirs or any(d not in DIRECTIONS for d in dirs) or len(set(dirs)) != len(dirs):
            raise InputError(
                "directions", ",".join(map(str, dirs)), f"distinct of {', '.join(DIRECTIONS)}"
            )
        object.__setattr__(self, "directions", dirs)
        object.__setattr__(self, "duration", positive("push duration [s]", self.duration))
        if self.step is not None and (
            isinstance(self.step, bool) or not isinstance(self.step, int) or self.step < 0
        ):
            raise InputError("step", self.step, "an integer >= 0")
        if self.steps is not None and (
            isinstance(self.steps, bool) or not isinstance(self.steps, int) or self.steps < 1
        ):
            raise InputError("steps", self.steps, "an integer >= 1")

    def cases(self) -> list[PushCase]:
        """Every walk: per level, per phase, per direction."""
        return [PushCase(v, p, d) for v in self.dv for p in self.phases for d in self.directions]

    @property
    def cases_per_level(self) -> int:
        """Walks per velocity change (12 for the field's 3 phases x 4 directions)."""
        return len(self.phases) * len(self.directions)

    def pushed_step(self, n_steps: int) -> int:
        """The pushed single support of a plan of ``n_steps`` footsteps."""
        step = n_steps // 2 if self.step is None else self.step
        if step >= n_steps:
            raise InputError("step", step, f"a single support of the plan, 0..{n_steps - 1}")
        return step

    def disturbance(self, case: PushCase, n_steps: int) -> Disturbance:
        """The disturbance of ``case`` on a plan of ``n_steps`` footsteps."""
        return Disturbance(
            dv=case.dv,
            direction=DIRECTIONS[case.direction],
            step=self.pushed_step(n_steps),
            phase=case.phase,
            duration=self.duration,
            frame="walk",
        )

    def disturbances(self, n_steps: int) -> list[Disturbance]:
        """The disturbances of :meth:`cases`, in their order."""
        return [self.disturbance(c, n_steps) for c in self.cases()]


@dataclass(frozen=True)
class ProtocolResult:
    """The walks of a protocol.

    Attributes:
        protocol: what was walked.
        scene_name: the scene's name.
        n_steps: footsteps N of the plan.
        step: the pushed single support.
        mass: the robot's mass [kg] (impulse = mass x dv).
        rows: one dict per case (:data:`COLUMNS`), in the order of :meth:`PushProtocol.cases`.
    """

    protocol: PushProtocol
    scene_name: str
    n_steps: int
    step: int
    mass: float
    rows: list[dict[str, Any]] = field(default_factory=list)


@functools.lru_cache(maxsize=2)
def _plant(
    robot: str,
    controller: str,
    region_aware: str,
    leg_momentum: float | None = None,
    walk_on: int | None = None,
    step_timing: bool | None = None,
) -> Any:
    """The MuJoCo plant of ``robot`` with ``controller``, the MPC's ``region_aware`` mode, the
    ``leg_momentum`` share, the stopping steps it may add (``walk_on``) and its ``step_timing``
    (None: the walker's defaults), one per worker process."""
    from footfall.sim.biped.options import WalkOptions
    from footfall.sim.biped.plans import robot_model
    from footfall.sim.trial import make_plant

    options = WalkOptions(
        controller=controller, region_aware=region_aware, leg_momentum=leg_momentum
    )
    if walk_on is not None:
        options = dataclasses.replace(options, walk_on=walk_on)
    if step_timing is not None:
        options = dataclasses.replace(options, step_timing=step_timing)
    return make_plant(
        "mujoco",
        options=options,
        robot=robot_model(robot),
    )


def _walk_case(
    robot: str,
    controller: str,
    region_aware: str,
    leg_momentum: float | None,
    walk_on: int | None,
    step_timing: bool | None,
    scene: Any,
    plan: Any,
    case: PushCase,
    d: Disturbance,
) -> dict[str, Any]:
    """Walk one case; its row (:data:`COLUMNS`)."""
    from footfall.sim.trial import run_trial, trial_pushes

    plant = _plant(robot, controller, region_aware, leg_momentum, walk_on, step_timing)
    pushes = trial_pushes(plant, plan, d)
    out = run_trial(plant, scene, plan, d)
    reached = bool(out.detail.metrics.reached_goal)
    return {
        "dv_m_s": case.dv,
        "phase": case.phase,
        "direction": case.direction,
        "impulse_Ns": pushes[-1].impulse,
        "step": d.step,
        "push_start_s": pushes[-1].start,
        "fell": bool(out.fell),
        "fall_time_s": float(out.fall_time),
        "reached_goal": reached,
        "success": bool(reached and not out.fell),
    }


def run_protocol(
    protocol: PushProtocol,
    cache_dir: Path | None = None,
    workers: int = 1,
    time_limit: float = 300.0,
    progress: Callable[[dict[str, Any]], None] | None = None,
) -> ProtocolResult:
    """Plan once and walk every case of ``protocol``.

    Args:
        protocol: what to walk.
        cache_dir: the plan cache folder (None: no cache).
        workers: walks at once (worker processes; 1: in this process).
        time_limit: planner time limit per solve [s].
        progress: called with each row as its walk ends (in the order they end).

    Raises:
        InputError: an unknown robot or scene, a pushed step beyond the plan.
        InfeasibleError: the planner found no plan.
    """
    from footfall.planning.plan import check_planner_name
    from footfall.sim.biped.options import CONTROLLERS
    from footfall.sim.biped.plans import plan_for_walk, robot_model
    from footfall.terrain.resolve import resolve_scene

    check_planner_name(protocol.planner)
    if protocol.controller not in CONTROLLERS:
        raise InputError("controller", protocol.controller, f"one of {', '.join(CONTROLLERS)}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError("workers", workers, "an integer >= 1")
    model = robot_model(protocol.robot)
    scene = resolve_scene(protocol.scene)
    plan = plan_for_walk(
        scene, protocol.planner, protocol.steps, time_limit, cache_dir, model=model
    )
    if not plan.has_solution:
        raise InfeasibleError(f"{protocol.planner} found no plan for {scene.name}: {plan.message}")
    step = protocol.pushed_step(plan.n_steps)
    cases = protocol.cases()
    jobs = [(c, protocol.disturbance(c, plan.n_steps)) for c in cases]
    rows: dict[PushCase, dict[str, Any]] = {}
    for case, row in _walks(protocol, scene, plan, jobs, workers):
        rows[case] = row
        if progress is not None:
            progress(row)
    p = protocol
    mass = float(
        _plant(
            p.robot, p.controller, p.region_aware, p.leg_momentum, p.walk_on, p.step_timing
        ).mass(plan)
    )
    return ProtocolResult(
        protocol, scene.name, int(plan.n_steps), step, mass, [rows[c] for c in cases]
    )


def _walks(
    protocol: PushProtocol,
    scene: Any,
    plan: Any,
    jobs: list[tuple[PushCase, Disturbance]],
    workers: int,
) -> Iterator[tuple[PushCase, dict[str, Any]]]:
    p = protocol
    args = (
        p.robot,
        p.controller,
        p.region_aware,
        p.leg_momentum,
        p.walk_on,
        p.step_timing,
        scene,
        plan,
    )
    if workers <= 1 or len(jobs) <= 1:
        for case, d in jobs:
            yield case, _walk_case(*args, case, d)
        return
    from concurrent.futures import FIRST_COMPLETED, Future, wait

    from footfall._process import spawn_pool

    # spawn, as the study runner: each worker dies with this process, even killed
    pool = spawn_pool(min(workers, len(jobs)))
    try:
        running: dict[Future[dict[str, Any]], PushCase] = {
            pool.submit(_walk_case, *args, case, d): case for case, d in jobs
        }
        while running:
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for f in finished:
                yield running.pop(f), f.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


@dataclass(frozen=True)
class LevelSummary:
    """The walks of one velocity change: how many passed and which cases failed."""

    dv: float
    passed: int
    total: int
    failed: tuple[str, ...]

    @property
    def all_pass(self) -> bool:
        """Whether every case of the level passed."""
        return self.passed == self.total


def summarise(rows: Sequence[dict[str, Any]]) -> list[LevelSummary]:
    """Per velocity change (ascending): passes and the failed cases (``direction@phase``)."""
    levels = sorted({float(r["dv_m_s"]) for r in rows})
    out = []
    for v in levels:
        mine = [r for r in rows if float(r["dv_m_s"]) == v]
        failed = tuple(
            PushCase(v, float(r["phase"]), str(r["direction"])).label
            for r in mine
            if not r["success"]
        )
        out.append(LevelSummary(v, len(mine) - len(failed), len(mine), failed))
    return out


def largest_passed(levels: Sequence[LevelSummary]) -> str:
    """The largest velocity change [m/s] at which every case passed: ``none`` when no level
    passed, ``>= MAX`` when no level of the grid failed (the limit lies at or above the grid's
    largest level, not known how far), and the level otherwise (a failed level below it is
    said)."""
    passed = [lv.dv for lv in levels if lv.all_pass]
    if not passed:
        return "none"
    best = max(passed)
    if len(passed) == len(levels):
        return f">= {best:g} m/s (no level of the grid failed)"
    below = [lv.dv for lv in levels if not lv.all_pass and lv.dv < best]
    note = f" (but {', '.join(f'{v:g}' for v in below)} m/s failed)" if below else ""
    return f"{best:g} m/s{note}"


def format_summary(result: ProtocolResult) -> str:
    """The printed summary: the setting, per level k/n and the failed cases, the largest level
    passed."""
    p = result.protocol
    levels = summarise(result.rows)
    lines = [
        f"push protocol: {p.robot} ({result.mass:.3g} kg) on {result.scene_name}, N = "
        f"{result.n_steps}, {p.planner}, {p.controller}, footstep regions {p.region_aware}"
        f"{_legs(p)}; "
        f"pushed single support {result.step}, "
        f"{p.duration:g} s pushes",
    ]
    for lv in levels:
        fails = f"; fail: {', '.join(lv.failed)}" if lv.failed else ""
        lines.append(
            f"dv {lv.dv:g} m/s ({result.mass * lv.dv:.3g} N s): {lv.passed}/{lv.total} pass{fails}"
        )
    lines.append(f"largest dv passed: {largest_passed(levels)}")
    return "\n".join(lines)


def _legs(p: PushProtocol) -> str:
    """The leg-momentum share and the step timing in a summary line (nothing when off)."""
    share = float(p.leg_momentum or 0.0)
    legs = f", legs' momentum {share:g}" if share > 0 else ""
    return legs + (", step timing" if p.step_timing else "")


def format_markdown(result: ProtocolResult) -> str:
    """``protocol.md``: per level a direction x phase table of pass / FAIL, then the largest
    level passed."""
    p = result.protocol
    levels = summarise(result.rows)
    by = {(r["dv_m_s"], r["phase"], r["direction"]): r for r in result.rows}
    out = [
        "# Push-recovery protocol",
        "",
        f"{p.robot} ({result.mass:.3g} kg) on {result.scene_name}, N = {result.n_steps} "
        f"({p.planner}, {p.controller} controller, footstep regions {p.region_aware}{_legs(p)})."
        " One push "
        f"of {p.duration:g} s in single "
        f"support {result.step}, at a share of it (phase), in a direction relative to the stance "
        "foot (inward: toward its side); impulse = mass x dv. A case passes when the robot "
        "reaches the goal without falling.",
        "",
    ]
    for lv in levels:
        out += [
            f"## dv = {lv.dv:g} m/s ({result.mass * lv.dv:.3g} N s): {lv.passed}/{lv.total} pass",
            "",
            "| direction | " + " | ".join(f"{ph:g}" for ph in p.phases) + " |",
            "|---|" + "---|" * len(p.phases),
        ]
        for d in p.directions:
            cells = []
            for ph in p.phases:
                r = by[(lv.dv, ph, d)]
                cells.append("pass" if r["success"] else ("FAIL (fell)" if r["fell"] else "FAIL"))
            out.append(f"| {d} | " + " | ".join(cells) + " |")
        out.append("")
    out.append(f"**Largest dv passed: {largest_passed(levels)}**")
    return "\n".join(out) + "\n"


def rows_csv(rows: Sequence[dict[str, Any]]) -> str:
    """``protocol.csv``: :data:`COLUMNS`, one line per walk."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: r[k] for k in COLUMNS})
    return buf.getvalue()


def plot_protocol(result: ProtocolResult, path: Path) -> Path:
    """``protocol.png``: per level a direction x phase matrix, pass green, fail red."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import ListedColormap

    from footfall._io import save_figure

    p = result.protocol
    levels = summarise(result.rows)
    by = {(r["dv_m_s"], r["phase"], r["direction"]): r for r in result.rows}
    fig, axes = plt.subplots(
        1, len(levels), figsize=(1.2 + 2.6 * len(levels), 0.9 + 0.55 * len(p.directions))
    )
    axes = np.atleast_1d(axes)
    cmap = ListedColormap(["#d62728", "#2ca02c"])
    for ax, lv in zip(axes, levels, strict=True):
        m = np.array(
            [[float(by[(lv.dv, ph, d)]["success"]) for ph in p.phases] for d in p.directions]
        )
        ax.imshow(m, cmap=cmap, vmin=0.0, vmax=1.0)
        for i in range(m.shape[0]):
            for j in range(m.shape[1]):
                ax.text(j, i, "pass" if m[i, j] else "fail", ha="center", va="center", color="w")
        ax.set_xticks(range(len(p.phases)), [f"{ph:g}" for ph in p.phases])
        ax.set_yticks(range(len(p.directions)), list(p.directions))
        ax.set_xlabel("phase of single support")
        ax.set_title(f"dv {lv.dv:g} m/s: {lv.passed}/{lv.total}")
    fig.suptitle(
        f"{p.robot} on {result.scene_name}: largest dv passed {largest_passed(levels)}",
        fontsize=9,
    )
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
