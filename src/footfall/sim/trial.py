"""One trial pipeline for every plant: ``run_trial(plant, scene, plan, disturbance) -> Outcome``.

A plant walks a plan over a scene and measures it. Every plant (the reduced-order ALIP loop, the
MuJoCo biped with our robot or another humanoid, the MuJoCo quadruped) implements :class:`Plant`,
is one line of :data:`PLANTS` and returns the same :class:`~footfall.results.outcome.Outcome`, so
a study, a benchmark or a command runs any of them the same way, with the same
:class:`~footfall.sim.disturbance.Disturbance` turned into the same pushes on the plant's own
clock.

The registry names what each plant needs installed; asking for one whose extra is missing is a
:class:`~footfall.errors.SolverUnavailableError` that says what to install (the registry and the
lazy imports follow mujoco_playground's ``locomotion/__init__.py`` and qpsolvers' backend table).
"""

from __future__ import annotations

import functools
import importlib
import importlib.util
import time
from collections.abc import Hashable
from dataclasses import dataclass, replace
from typing import Any, Protocol

from footfall._validate import instance_of
from footfall.errors import InputError, SolverUnavailableError
from footfall.results.outcome import Outcome
from footfall.sim.disturbance import Disturbance, Push, SupportTimeline


class Plant(Hashable, Protocol):
    """A simulator that walks a plan and says how it went.

    ``name`` is its key in :data:`PLANTS`. Plants are frozen dataclasses of their settings (so a
    study can ship them to worker processes and compare them); what a plant builds once and
    reuses between walks (the reduced plant's condensed MPC) lives in the plant object.
    """

    @property
    def name(self) -> str:
        """Registry name."""
        ...

    def timeline(self, plan: Any) -> SupportTimeline:
        """When the single supports of ``plan`` happen on this plant's clock."""
        ...

    def mass(self, plan: Any) -> float:
        """The robot's mass [kg] (a push given as a velocity change needs it)."""
        ...

    def run(self, scene: Any, plan: Any, pushes: tuple[Push, ...], seed: int) -> Outcome:
        """Walk ``plan`` over ``scene`` with ``pushes``; ``seed`` seeds the plant's own random
        draws (estimate noise, placement errors). Falls are outcomes, never raised."""
        ...


@dataclass(frozen=True)
class PlantEntry:
    """A row of the plant registry.

    Attributes:
        module: the module that defines the plant class (imported on first use).
        cls: the class name.
        extra: the optional dependency group it needs (``pip install 'footfall[EXTRA]'``), or
            None.
        needs: a module whose import tells whether the extra is installed.
        what: one line for help texts.
    """

    module: str
    cls: str
    extra: str | None
    needs: str | None
    what: str


#: every plant by name
PLANTS: dict[str, PlantEntry] = {
    "reduced": PlantEntry(
        "footfall.sim.reduced.trial",
        "ReducedPlant",
        None,
        None,
        "ALIP closed loop with a rectangular sole (document 000, sections 5.4-5.5)",
    ),
    "mujoco": PlantEntry(
        "footfall.sim.biped.trial",
        "MujocoBipedPlant",
        "sim",
        "mujoco",
        "a humanoid (ours or a robot file's) in MuJoCo with the whole-body controller",
    ),
    "quadruped": PlantEntry(
        "footfall.sim.quadruped.trial",
        "QuadrupedPlant",
        "sim",
        "mujoco",
        "the document-001 quadruped gait in MuJoCo",
    ),
}


def check_settings(options: Any, cls: type, expected: str) -> None:
    """A plant's loop options: an instance of ``cls`` without pushes of its own (a trial's pushes
    come from its :class:`~footfall.sim.disturbance.Disturbance`)."""
    instance_of("options", options, cls, expected)
    if options.pushes:
        raise InputError(
            "options.pushes", len(options.pushes), "none: pushes come from a Disturbance"
        )


def plant_class(name: str) -> type[Any]:
    """The plant class registered as ``name``.

    Raises:
        InputError: for an unknown name.
        SolverUnavailableError: when its extra is not installed (naming it).
    """
    entry = PLANTS.get(name)
    if entry is None:
        raise InputError("plant", name, f"one of {', '.join(PLANTS)}")
    if entry.needs is not None and importlib.util.find_spec(entry.needs) is None:
        raise SolverUnavailableError(
            f"the {name} plant needs the package {entry.needs!r}: "
            f"pip install 'footfall[{entry.extra}]'"
        )
    cls: type[Any] = getattr(importlib.import_module(entry.module), entry.cls)
    return cls


def make_plant(name: str, **settings: Any) -> Plant:
    """A plant ``name`` of :data:`PLANTS` with ``settings`` (its dataclass fields)."""
    plant: Plant = plant_class(name)(**settings)
    return plant


@functools.lru_cache(maxsize=4)
def shared_plant(plant: Plant) -> Plant:
    """The plant equal to ``plant`` that this process already made, or ``plant`` itself: worker
    processes walk many trials of one plant, and a plant keeps what it builds once (the reduced
    plant's condensed MPC) between walks."""
    return plant


def trial_pushes(plant: Plant, plan: Any, disturbance: Disturbance | None) -> tuple[Push, ...]:
    """The pushes ``disturbance`` makes on ``plant``'s walk of ``plan``: on the plant's own
    timeline (:meth:`Plant.timeline`), with the robot's mass for a push given as a velocity
    change (none without a disturbance)."""
    if disturbance is None:
        return ()
    return disturbance.pushes(plant.timeline(plan), plant.mass(plan))


def run_trial(
    plant: Plant, scene: Any, plan: Any, disturbance: Disturbance | None = None
) -> Outcome:
    """Walk ``plan`` over ``scene`` on ``plant`` under ``disturbance`` (None: undisturbed).

    The disturbance becomes pushes (:func:`trial_pushes`); its seed (0 without one) seeds the
    plant's own random draws. The outcome's ``wall_time`` is the whole trial's.
    """
    t0 = time.perf_counter()
    pushes = trial_pushes(plant, plan, disturbance)
    seed = disturbance.seed if disturbance is not None and disturbance.seed is not None else 0
    outcome = plant.run(scene, plan, pushes, seed)
    return replace(outcome, wall_time=time.perf_counter() - t0)
