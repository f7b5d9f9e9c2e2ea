"""Public functions given an argument of the wrong type raise InputError naming that argument
(not an AttributeError or TypeError from deep inside)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning import (
    FootstepPlan,
    build_footstep_problem,
    check_plan,
    lip_walk,
    make_plan,
    plan_footsteps,
)
from footfall.sim import simulate
from footfall.solvers import SolveStatus
from footfall.terrain import builtin_scene, load_scene

EMPTY_PLAN = FootstepPlan.empty("miqcqp", SolveStatus.INFEASIBLE, BipedParams(), "none")
FLAT = builtin_scene("flat")

CASES: list[tuple[str, Callable[[], object], str]] = [
    ("check_plan(None, scene)", lambda: check_plan(None, FLAT), "plan"),  # type: ignore[arg-type]
    ("check_plan(plan, None)", lambda: check_plan(EMPTY_PLAN, None), "scene"),  # type: ignore[arg-type]
    ("check_plan(plan, scene, 3)", lambda: check_plan(EMPTY_PLAN, FLAT, 3), "robot"),  # type: ignore[arg-type]
    ("make_plan(None)", lambda: make_plan(None, "miqcqp", 4), "scene"),  # type: ignore[arg-type]
    ("make_plan(robot='g1')", lambda: make_plan(FLAT, "miqcqp", 4, robot="g1"), "robot"),  # type: ignore[arg-type]
    ("make_plan(options={})", lambda: make_plan(FLAT, "miqcqp", 4, options={}), "options"),  # type: ignore[arg-type]
    ("plan_footsteps(None)", lambda: plan_footsteps(None, n_steps=4), "scene"),  # type: ignore[arg-type]
    ("simulate(None)", lambda: simulate(None), "plan"),  # type: ignore[arg-type]
    ("lip_walk(None)", lambda: lip_walk(None), "params"),  # type: ignore[arg-type]
    ("load_scene(123)", lambda: load_scene(123), "path_or_text"),  # type: ignore[arg-type]
    ("build_footstep_problem(None)", lambda: build_footstep_problem(None), "scene"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "fn", "argument"), CASES, ids=[c[0] for c in CASES])
def test_a_wrong_argument_type_raises_input_error_naming_it(
    call: str, fn: Callable[[], object], argument: str
) -> None:
    with pytest.raises(InputError) as info:
        fn()
    assert info.value.field == argument, f"{call}: {info.value}"
