"""The independent checker fails where it should: one test per check of :func:`check_plan`.

``check_plan`` is the oracle of every planner test, so each of its checks is exercised here on its
own: a valid plan (the direct MIQCQP on a small scene, checked ok first) is perturbed to break
exactly one check, and the report must name that check's kind, with the sub-check's message, and
no other kind. Most perturbations change the plan (``dataclasses.replace`` on the
:class:`FootstepPlan`, including the robot the plan claims it was made for); where every field of
the plan feeds more than one check, the scene given to the checker is perturbed instead (the
start pose, the start ALIP state, the goal, a region's polygon).

Alternation cannot be broken alone: every side feeds either the reach trapezoid's mirror image
(sides 0..N-1) or the goal spot (side N), so flipping the last side also moves its goal spot.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pytest

from footfall.models.biped import BipedParams, ReachTrapezoid, Side
from footfall.planning import PlannerOptions, check_plan, plan_footsteps
from footfall.planning.plan import FootstepPlan
from footfall.solvers import SolveStatus
from footfall.terrain import Scene
from tests.planning.scenes import SHORT_TURN, TWO_STONES, scene

OPTS = PlannerOptions(time_limit=60.0, gap=1e-6)
#: a perturbation well beyond the checker's tolerances (GEOM_TOL 1e-5 m, STATE_TOL 1e-4)
NUDGE = 0.01
#: the base scenes and their horizons: stones (steps up and down, a slope, three regions) and a
#: 60 degree turn (heading changes at the rate bound's scale)
BASES = {"stones": (TWO_STONES, 5), "turn": (SHORT_TURN, 5)}


@functools.cache
def _base(name: str) -> tuple[FootstepPlan, Scene]:
    text, n = BASES[name]
    sc = scene(text)
    plan = plan_footsteps(sc, n_steps=n, options=OPTS)
    assert plan.status is SolveStatus.OPTIMAL
    report = check_plan(plan, sc)
    assert report.ok, report.summary()
    return plan, sc


Perturb = Callable[[FootstepPlan, Scene], tuple[FootstepPlan, Scene]]


@dataclass(frozen=True)
class Case:
    """One perturbation: the base plan, what is changed, the kinds expected and a message part."""

    base: str
    perturb: Perturb
    kinds: frozenset[str]
    message: str


def _robot(plan: FootstepPlan, **changes: object) -> FootstepPlan:
    """The plan claiming it was made for a robot with ``changes``."""
    return replace(plan, robot=replace(plan.robot, **changes))


def _start(sc: Scene, **changes: object) -> Scene:
    return replace(sc, start=replace(sc.start, **changes))


def _shifted(arr: np.ndarray, index: tuple[int, ...], by: float) -> np.ndarray:
    out = np.array(arr, dtype=float)
    out[index] += by
    return out


def _start_foot(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return p, _start(sc, right=_shifted(sc.start.right, (0,), NUDGE))


def _start_side(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # the feet swap names: footstep 0 is still where the scene's stance foot stands, but that
    # foot is now the left one while the plan says right
    return p, _start(sc, left=sc.start.right, right=sc.start.left, stance=Side.LEFT)


def _start_heading(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return p, _start(sc, heading=sc.start.heading + NUDGE)


def _alternation(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return replace(p, sides=(*p.sides[:-1], p.sides[-2])), sc


def _region_unknown(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return replace(p, regions=(*p.regions[:2], "nowhere", *p.regions[3:])), sc


def _region_outside(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # stone_a (same height) moved forward past footstep 1, which stands on its back edge
    text = TWO_STONES.replace(
        "[[0.25, 0.0], [0.5, 0.0], [0.5, 0.3], [0.25, 0.3]]",
        "[[0.3, 0.0], [0.5, 0.0], [0.5, 0.3], [0.3, 0.3]]",
    )
    assert text != TWO_STONES
    return p, scene(text)


def _region_margin(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return replace(p, region_margin=NUDGE), sc


def _region_plane(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # z feeds only the plane and the step height (well below its bound here)
    return replace(p, footsteps=_shifted(p.footsteps, (2, 2), NUDGE)), sc


def _step_height(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # the plan steps down 0.12 m from stone_b to the slope
    return _robot(p, step_height_max=0.1), sc


def _reach(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # half the fore-aft range: the 0.34 m steps between the stones leave it
    narrow = np.array(p.robot.reach.vertices) * np.array([0.5, 1.0])
    return _robot(p, reach=ReachTrapezoid(narrow)), sc


def _reach_landing(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # the document's turning plan moves the trailing foot beside the new stance foot
    return replace(p, reach_both_frames=True), sc


def _swing(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    start = sc.start.foot(p.sides[1])[None, :2]
    prev = np.vstack([start, p.footsteps[:-2, :2]])
    longest = float(np.linalg.norm(p.footsteps[1:, :2] - prev, axis=1).max())
    return replace(p, swing_max=longest - NUDGE), sc


def _heading_rate(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    rate = float(np.abs(np.diff(p.headings)).max())
    return _robot(p, theta_max=rate - NUDGE), sc


def _torque(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    largest = float(np.linalg.norm(p.torques, axis=-1).max())
    return _robot(p, u_max=0.9 * largest), sc


def _initial_state(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return p, _start(sc, alip_state=_shifted(sc.start.alip_state, (0,), NUDGE))


def _node_state(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    return replace(p, states=_shifted(p.states, (2, 1, 3), 0.5)), sc


def _node_torque(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # a torque well inside the bound that the states do not follow
    torques = np.array(p.torques)
    torques[1, 0] *= 0.5
    return replace(p, torques=torques), sc


def _reset(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # the final state feeds only the last double-support reset
    return replace(p, final_state=_shifted(p.final_state, (0,), NUDGE)), sc


def _goal_position(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # sideways: the slope's height does not change along y, so the goal stays on the terrain
    goal = replace(sc.goal, position=_shifted(sc.goal.position, (1,), NUDGE))
    return p, replace(sc, goal=goal)


def _goal_heading(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    # the last heading feeds the goal and the (loose) last heading rate only
    return replace(p, headings=_shifted(p.headings, (-1,), NUDGE)), sc


def _no_solution(p: FootstepPlan, sc: Scene) -> tuple[FootstepPlan, Scene]:
    empty = FootstepPlan.empty("miqcqp", SolveStatus.INFEASIBLE, p.robot, "no plan")
    return empty, sc


def _one(kind: str) -> frozenset[str]:
    return frozenset({kind})


CASES = {
    "start_foot": Case("stones", _start_foot, _one("start"), "not the given stance foot"),
    "start_side": Case("stones", _start_side, _one("start"), "not the given stance foot"),
    "start_heading": Case("stones", _start_heading, _one("start"), "heading 0 differs"),
    "alternation": Case("stones", _alternation, frozenset({"alternation", "goal"}), "same foot"),
    "region_unknown": Case("stones", _region_unknown, _one("region"), "unknown region"),
    "region_outside": Case("stones", _region_outside, _one("region"), "outside stone_a"),
    "region_margin": Case("stones", _region_margin, _one("region"), "margin 0.01"),
    "region_plane": Case("stones", _region_plane, _one("region"), "off the plane of stone_b"),
    "step_height": Case("stones", _step_height, _one("step_height"), "step height 0.120"),
    "reach": Case("stones", _reach, _one("reach"), "outside the reach set"),
    "reach_landing_frame": Case("turn", _reach_landing, _one("reach"), "landing foot's frame"),
    "swing": Case("stones", _swing, _one("swing"), "longer than"),
    "heading_rate": Case("turn", _heading_rate, _one("heading_rate"), "heading change"),
    "torque": Case("stones", _torque, _one("torque"), "|u| ="),
    "initial_state": Case("stones", _initial_state, _one("dynamics"), "initial state"),
    "node_state": Case("stones", _node_state, _one("dynamics"), "differ from simulation"),
    "node_torque": Case("stones", _node_torque, _one("dynamics"), "differ from simulation"),
    "reset": Case("stones", _reset, _one("dynamics"), "differ from simulation"),
    "goal_position": Case("stones", _goal_position, _one("goal"), "from its goal spot"),
    "goal_heading": Case("stones", _goal_heading, _one("goal"), "heading off"),
    "no_solution": Case("stones", _no_solution, _one("no_solution"), "no plan"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_each_check_flags_its_own_violation(name: str) -> None:
    case = CASES[name]
    plan, sc = case.perturb(*_base(case.base))
    report = check_plan(plan, sc)
    assert report.kinds() == case.kinds, report.summary()
    assert any(case.message in v.message for v in report.violations), report.summary()


def test_robot_argument_overrides_the_plans_robot() -> None:
    """The robot given to the checker, not the plan's, sets the bounds."""
    plan, sc = _base("stones")
    largest = float(np.linalg.norm(plan.torques, axis=-1).max())
    weak: BipedParams = replace(plan.robot, u_max=0.9 * largest)
    assert check_plan(plan, sc, weak).kinds() == {"torque"}
    assert check_plan(_robot(plan, u_max=0.9 * largest), sc, plan.robot).ok


def test_violation_amounts_measure_the_perturbation() -> None:
    """Amounts are in the kind's unit and equal the size of the break."""
    plan, sc = _base("stones")
    report = check_plan(*_region_plane(plan, sc))
    assert [v.amount for v in report.violations] == [pytest.approx(NUDGE, abs=1e-9)]
    report = check_plan(*_goal_heading(plan, sc))
    (heading,) = report.violations
    assert heading.step == plan.n_steps and heading.amount == pytest.approx(NUDGE, abs=1e-6)
    report = check_plan(*_step_height(plan, sc))
    (high,) = report.violations
    assert high.amount == pytest.approx(0.12, abs=1e-6) and math.isfinite(high.amount)
