"""Run a study: plan every (scene, planner, step mode) once, then walk the trials on an executor.

Plans are deterministic, so each is made once and cached in ``DIR/plans``
(:mod:`footfall.planning.cache`). The reactive planner walks to the goal; its N is the "equal N"
of the horizon planners. A horizon planner's smallest-N plan that already has that N serves both
modes (the same walk, one row flagged ``smallest_n`` and ``equal_n``).

Executors: ``local`` (this process for one worker, else a process pool) and ``ray`` (a local
``ray.init`` with ``workers`` CPUs, or an existing cluster at ``address``). Rows are stored as they
arrive (:class:`~footfall.experiments.study.store.TrialStore`); trials already in the folder are
skipped, so an interrupted study resumes where it stopped. A row names the plan it walked
(:func:`~footfall.experiments.study.trials.plan_digest`): when a planner now makes another plan
(its code changed), that planner's trials are walked again and their old rows replaced.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from footfall._process import DeferredSignals, unreachable
from footfall.errors import InputError, MissingExtraError
from footfall.experiments.study.design import StudyDesign
from footfall.experiments.study.store import TrialStore
from footfall.experiments.study.trials import Trial, plan_digest, run_trial, trial_key
from footfall.planning.plan import FootstepPlan
from footfall.planning.run import SearchMonitor
from footfall.sim.disturbance import Disturbance
from footfall.terrain.resolve import resolve_scene
from footfall.terrain.scene import Scene

#: the executors of ``footfall study --executor``
EXECUTORS = ("local", "ray")
#: ``monitor_for(title)``: a context manager yielding the search monitor of one plan (or None)
MonitorFactory = Callable[[str], AbstractContextManager[SearchMonitor | None]]
#: trials in flight per worker (keeps every worker busy without shipping the whole study at once)
IN_FLIGHT = 2
#: longest wait [s] in one call into Ray (signals are handled between calls)
POLL = 0.5


@dataclass(frozen=True)
class PlanEntry:
    """A plan of the study (one per scene, planner and step mode).

    Attributes:
        scene: scene name.
        planner: planner name.
        mode: ``smallest``, ``equal`` or ``goal`` (the reactive planner: it walks to the goal).
        plan: the plan (may have no solution: then its trials are not run).
        plan_time: wall time to get it [s] (cache hits are fast).
    """

    scene: str
    planner: str
    mode: str
    plan: FootstepPlan
    plan_time: float

    def to_dict(self) -> dict[str, Any]:
        """The row of ``plans.json``."""
        return {
            "scene": self.scene,
            "planner": self.planner,
            "mode": self.mode,
            "status": self.plan.status.value,
            "n_steps": int(self.plan.n_steps) if self.plan.has_solution else None,
            "objective": self.plan.objective if self.plan.has_solution else None,
            # relative gap of incumbent and bound (0: proven; None: no bound, e.g. reactive)
            "gap": self.plan.gap if math.isfinite(self.plan.gap) else None,
            "solve_time": self.plan.solve_time,
            "plan_time": self.plan_time,
            "message": self.plan.message,
        }


Planner = Callable[[Scene, str, "int | None", "SearchMonitor | None"], FootstepPlan]


def _planner(design: StudyDesign, folder: Path) -> Planner:
    """``plan(scene, planner, n_steps, monitor)`` for the study's simulator, cached in ``folder``."""
    if design.simulator == "mujoco":
        from footfall.sim.biped.plans import plan_for_walk, robot_model

        model = robot_model(design.robot)

        def plan_mujoco(
            scene: Scene, planner: str, n: int | None, monitor: SearchMonitor | None
        ) -> FootstepPlan:
            # one worker: the plans shipped with the section 5.5 study were made so, and the
            # worker count is part of the plan cache key
            return plan_for_walk(
                scene, planner, n, design.time_limit, folder, model, monitor=monitor, threads=1
            )

        return plan_mujoco
    from footfall.planning.cache import PlanCache, cached_plan
    from footfall.planning.plan import PlannerOptions

    cache, options = PlanCache(folder), PlannerOptions(time_limit=design.time_limit)

    def plan_reduced(
        scene: Scene, planner: str, n: int | None, monitor: SearchMonitor | None
    ) -> FootstepPlan:
        return cached_plan(scene, planner, n, options, cache=cache, monitor=monitor)

    return plan_reduced


def design_scenes(design: StudyDesign) -> dict[str, Scene]:
    """The study's scenes by name: its ``scenes`` (built-in or read from their files), then the
    terrains of its ``families`` (:func:`~footfall.terrain.families.family_terrain`)."""
    from footfall.terrain.families import family_terrain

    scenes: dict[str, Scene] = {}
    generated = (
        family_terrain(f, seed) for f in design.families for seed in design.terrain_seeds()
    )
    for entry in (*(resolve_scene(e) for e in design.scenes), *generated):
        if entry.name in scenes:
            raise InputError(
                "scenes", entry.name, f"scenes with distinct names ({entry.name!r} twice)"
            )
        scenes[entry.name] = entry
    return scenes


def terrain_family(design: StudyDesign) -> dict[str, str]:
    """The family of each of the study's generated terrains, by scene name."""
    from footfall.terrain.families import terrain_name

    return {terrain_name(f, s): f for f in design.families for s in design.terrain_seeds()}


def design_families(design: StudyDesign) -> dict[str, list[str]]:
    """The scene names of the study's generated terrains, by family."""
    names = terrain_family(design)
    return {f: [t for t, g in names.items() if g == f] for f in design.families}


#: where a study keeps the scene file of each generated terrain (``DIR/terrains/NAME.yaml``)
TERRAIN_FOLDER = "terrains"


def write_terrains(design: StudyDesign, folder: Path) -> int:
    """Write the scene file of every generated terrain of ``design`` into ``folder/terrains`` (so
    any trial can be replayed with ``footfall walk``); a file that already says the same is left
    as it is. Returns the number of files written."""
    from footfall._io import write_text
    from footfall.terrain.scene import scene_to_yaml

    names = terrain_family(design)
    if not names:
        return 0
    where = Path(folder) / TERRAIN_FOLDER
    where.mkdir(parents=True, exist_ok=True)
    written = 0
    scenes = design_scenes(design)
    for name in names:
        text = scene_to_yaml(scenes[name])
        path = where / f"{name}.yaml"
        if path.is_file() and path.read_text() == text:
            continue
        write_text(path, text)
        written += 1
    return written


def _scene_plans(
    design: StudyDesign,
    folder: Path,
    scene: Scene,
    say: Callable[[str], None] | None = None,
    monitor_for: MonitorFactory | None = None,
) -> list[PlanEntry]:
    """The plans of one scene: the reactive walk (its N is the equal N), then each horizon
    planner at its smallest N and at the equal N (the smallest-N plan serves both when its N is
    the equal N)."""
    plan = _planner(design, folder)
    out: list[PlanEntry] = []

    def timed(planner: str, n: int | None, mode: str) -> PlanEntry:
        title = f"{scene.name} / {planner} ({mode} N{'' if n is None else f' = {n}'})"
        if say:
            say(f"planning {title}")
        t0 = time.perf_counter()
        with monitor_for(title) if monitor_for else nullcontext() as monitor:
            p = plan(scene, planner, n, monitor)
        entry = PlanEntry(scene.name, planner, mode, p, time.perf_counter() - t0)
        if say:
            n_txt = p.n_steps if p.has_solution else "-"
            say(f"  {p.status.value}, N = {n_txt}, {entry.plan_time:.1f} s")
        return entry

    name = scene.name
    reactive = None
    if "reactive" in design.planners or "equal" in design.steps:
        reactive = timed("reactive", None, "goal")
        if "reactive" in design.planners:
            out.append(reactive)
    n_equal = reactive.plan.n_steps if reactive and reactive.plan.has_solution else None
    for planner in design.planners:
        if planner == "reactive":
            continue
        smallest = None
        if "smallest" in design.steps:
            smallest = timed(planner, None, "smallest")
            out.append(smallest)
        if "equal" in design.steps:
            if n_equal is None:  # no reactive walk, no equal N: the report says so
                if say:
                    say(f"  {name} / {planner}: no equal-N plan (the reactive planner failed)")
            elif smallest and smallest.plan.has_solution and smallest.plan.n_steps == n_equal:
                out.append(PlanEntry(name, planner, "equal", smallest.plan, 0.0))
            else:
                out.append(timed(planner, n_equal, "equal"))
    return out


def make_plans(
    design: StudyDesign,
    folder: Path,
    say: Callable[[str], None] | None = None,
    monitor_for: MonitorFactory | None = None,
    workers: int = 1,
) -> list[PlanEntry]:
    """Every plan the study walks (see the module docstring), planned or read from the cache.

    ``say`` hears one line per plan; ``monitor_for(title)`` gives the monitor of a smallest-N
    search (``footfall plan``'s progress lines). With ``workers > 1`` the scenes are planned in
    that many processes (each plan on one thread, so the plans and their cache keys are those of
    one worker); ``say`` then hears a line per plan as its scene finishes, and no monitor."""
    scenes = list(design_scenes(design).values())
    if workers <= 1 or len(scenes) <= 1:
        return [e for sc in scenes for e in _scene_plans(design, folder, sc, say, monitor_for)]
    from footfall._process import spawn_pool

    by_scene: list[list[PlanEntry]] = []
    with spawn_pool(min(workers, len(scenes))) as pool:
        n = len(scenes)
        # in a worker: no progress lines, no monitor (say and monitor_for keep their None)
        for entries in pool.map(_scene_plans, [design] * n, [folder] * n, scenes):
            by_scene.append(entries)
            for e in entries:
                if say:
                    n_txt = e.plan.n_steps if e.plan.has_solution else "-"
                    say(
                        f"planned {e.scene} / {e.planner} ({e.mode} N): {e.plan.status.value}, "
                        f"N = {n_txt}, {e.plan_time:.1f} s"
                    )
    return [e for entries in by_scene for e in entries]


def make_trials(design: StudyDesign, plans: list[PlanEntry]) -> list[Trial]:
    """The study's walks, one per distinct (scene, planner, N, impulse, seed), in a fixed order:
    seed by seed (every cell of seed ``s`` before any of ``s + 1``), so a study stopped early
    holds the same seeds in every cell it reached, paired and balanced.

    A walk that serves both step modes is one trial with both flags."""
    scenes = design_scenes(design)
    flags: dict[str, list[bool]] = {}
    spec: dict[str, tuple[PlanEntry, float, int]] = {}
    for entry in plans:
        if not entry.plan.has_solution or entry.plan.states.shape[0] != entry.plan.n_steps:
            continue
        for impulse in design.impulses():
            for seed in design.seeds_at(impulse, entry.mode):
                key = trial_key(entry.scene, entry.planner, entry.plan.n_steps, impulse, seed)
                f = flags.setdefault(key, [False, False])
                f[0] |= entry.mode in ("smallest", "goal")
                f[1] |= entry.mode in ("equal", "goal")
                spec.setdefault(key, (entry, impulse, seed))
    trials = []
    for key, (entry, impulse, seed) in sorted(spec.items(), key=lambda kv: kv[1][2]):
        trials.append(
            Trial(
                key=key,
                scene=scenes[entry.scene],
                planner=entry.planner,
                plan=entry.plan,
                smallest_n=flags[key][0],
                equal_n=flags[key][1],
                disturbance=Disturbance.of_seed(
                    seed,
                    impulse=impulse,
                    duration=design.push_duration,
                    initial_impulse=design.initial_impulse,
                ),
                design=design,
            )
        )
    return trials


def _local(trials: list[Trial], workers: int) -> Iterator[dict[str, Any]]:
    if not trials:
        return
    # The first trial runs here: it compiles (or loads) the numba kernels once and leaves them in
    # numba's disk cache, so the workers load them instead of each compiling them at once.
    yield run_trial(trials[0])
    if workers <= 1:
        for t in trials[1:]:
            yield run_trial(t)
        return
    from concurrent.futures import FIRST_COMPLETED, Future, wait

    from footfall._process import spawn_pool

    # spawn: children import numpy afresh (single-threaded BLAS from the environment); each dies
    # with this process, even killed (kill -9 leaves no clean-up to run)
    pool = spawn_pool(workers)
    try:
        todo = iter(trials[1:])
        running: set[Future[dict[str, Any]]] = set()
        while True:
            while len(running) < IN_FLIGHT * workers:
                nxt = next(todo, None)
                if nxt is None:
                    break
                running.add(pool.submit(run_trial, nxt))
            if not running:
                break
            finished, running = wait(running, return_when=FIRST_COMPLETED)
            for f in finished:
                yield f.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _ray(trials: list[Trial], workers: int, address: str | None) -> Iterator[dict[str, Any]]:
    """The rows from Ray. Checked when called (before any planning, see :func:`run_study`):
    Ray is installed and a cluster ``address`` accepts connections (Ray itself retries an
    unreachable one for minutes, deaf to SIGTERM)."""
    try:
        import ray
    except ImportError:
        raise MissingExtraError(
            "the ray executor needs Ray: pip install 'footfall[study]'"
        ) from None
    if address is not None and address != "auto" and not ray.is_initialized():
        why = unreachable(address)
        if why is not None:
            raise InputError("--address", address, f"a reachable Ray cluster, host:port ({why})")
    return _ray_rows(ray, trials, workers, address)


def _ray_rows(
    ray: Any, trials: list[Trial], workers: int, address: str | None
) -> Iterator[dict[str, Any]]:
    # a signal handler that raises inside Ray's core worker (it calls back into Python while it
    # waits) comes out as a SystemError or a crash: signals are recorded and handed to the
    # command's handlers between two Ray calls, which wait at most POLL seconds
    with DeferredSignals() as signals:
        started = not ray.is_initialized()
        if started:
            kw: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
            if address is None:
                kw["num_cpus"] = workers
            with signals.blocked():  # ray.init installs SIGTERM handlers of its own
                ray.init(address=address, **kw)
        running: list[Any] = []
        try:
            signals.check()
            remote = ray.remote(num_cpus=1, max_retries=2)(run_trial)
            todo = iter(trials)
            cap = IN_FLIGHT * max(1, int(ray.cluster_resources().get("CPU", workers)))
            while True:
                while len(running) < cap:
                    t = next(todo, None)
                    if t is None:
                        break
                    running.append(remote.remote(t))
                if not running:
                    break
                finished, running = ray.wait(running, num_returns=1, timeout=POLL)
                signals.check()
                for ref in finished:
                    row = ray.get(ref)
                    signals.check()
                    yield row
        finally:
            for ref in running:
                ray.cancel(ref, force=True)
            if started:
                with signals.blocked():
                    ray.shutdown()


def execute(
    trials: list[Trial], executor: str = "local", workers: int = 1, address: str | None = None
) -> Iterable[dict[str, Any]]:
    """The rows of ``trials`` in the order they finish, from ``executor``."""
    if executor not in EXECUTORS:
        raise InputError("--executor", executor, f"one of {', '.join(EXECUTORS)}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError("--workers", workers, "an integer >= 1")
    if address is not None and executor != "ray":
        raise InputError("--address", address, "only with --executor ray")
    if executor == "ray":
        return _ray(trials, workers, address)
    return _local(trials, workers)


@dataclass(frozen=True)
class StudyRun:
    """What :func:`run_study` did.

    Attributes:
        rows: every row of the folder's table that belongs to this study, sorted by key.
        plans: the plans walked.
        trials: walks the study declares.
        ran: walks run now (the others were in the folder already).
        wall_time: time of the walks run now [s].
    """

    rows: list[dict[str, Any]]
    plans: list[PlanEntry]
    trials: int
    ran: int
    wall_time: float


def run_study(
    design: StudyDesign,
    out: Path,
    executor: str = "local",
    workers: int = 1,
    address: str | None = None,
    say: Callable[[str], None] | None = None,
    progress: Callable[[int, int, dict[str, Any]], None] | None = None,
    limit: int | None = None,
    monitor_for: MonitorFactory | None = None,
    plan_workers: int = 1,
) -> StudyRun:
    """Plan, then walk every trial of ``design`` not yet in ``out`` (resumable, see above).

    Args:
        design: the study.
        out: its folder (``trials.parquet``, ``plans/``, ``study.json``).
        executor, workers, address: where the walks run (:func:`execute`).
        say: called with a line of text (planning progress).
        progress: called after each walk with (walks done, walks in the study, the row).
        limit: run at most this many new walks (then stop as if interrupted; for tests and
            for spreading a study over several sessions).
        monitor_for: progress of the smallest-N searches (:func:`make_plans`).
        plan_workers: processes that make the plans (:func:`make_plans`), on this machine.
    """
    execute([], executor, workers, address)  # validates the arguments before any planning
    out = Path(out)
    store = TrialStore(out, design)
    write_terrains(design, out)
    plans = make_plans(design, out / "plans", say, monitor_for, plan_workers)
    trials = make_trials(design, plans)
    digests: dict[int, str] = {}  # one digest per plan object, not per trial
    for t in trials:
        digests.setdefault(id(t.plan), plan_digest(t.plan))

    def done_(t: Trial) -> bool:
        return store.done(t.key, digests[id(t.plan)])

    for t in trials:  # a walk run by an earlier study may serve a step mode added since
        r = store.rows.get(t.key)
        if (
            r is not None
            and done_(t)
            and (t.smallest_n > r["smallest_n"] or t.equal_n > r["equal_n"])
        ):
            smallest, equal = r["smallest_n"] or t.smallest_n, r["equal_n"] or t.equal_n
            store.add(r | {"smallest_n": smallest, "equal_n": equal})
    pending = [t for t in trials if not done_(t)]
    stale = sum(1 for t in pending if t.key in store.rows)
    if stale and say:
        say(f"{stale} walk(s) in the table walked another plan than today's: walking them again")
    todo = pending if limit is None else pending[:limit]
    done = len(trials) - len(pending)
    t0 = time.perf_counter()
    ran = 0
    try:
        for row in execute(todo, executor, workers, address):
            store.add(row)
            ran += 1
            if progress:
                progress(done + ran, len(trials), row)
    finally:
        store.close()
    # rows of this study's trials that walked today's plans (a stale row waits for its rerun)
    keys = {t.key for t in trials if done_(t)}
    rows = [store.rows[k] for k in sorted(store.rows) if k in keys]
    return StudyRun(rows, plans, len(trials), ran, time.perf_counter() - t0)
