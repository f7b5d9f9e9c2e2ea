"""Infeasibility messages claim what was proven: infeasible for the planner's conservative model."""

from __future__ import annotations

from dataclasses import replace

import pytest

from footfall.models.biped import BipedParams
from footfall.planning import PlannerOptions, make_plan
from footfall.planning.diagnose import linear_reach_forward
from footfall.solvers import SolveStatus
from tests.planning.scenes import SHORT_FLAT, scene

#: heading segments so few that the linear reach rows leave too little of the polygon for 3 steps
COARSE = 4
#: how close the linear rows come to the polygon with the most segments allowed [m]
FINE_GAP = 1e-3


def test_linear_reach_is_conservative_and_tightens_with_more_segments() -> None:
    robot = BipedParams()
    forward = [linear_reach_forward(robot, n)[0] for n in (4, 8, 16, 64, 1024)]
    polygon = linear_reach_forward(robot, 16)[1]
    assert polygon == pytest.approx(max(robot.reach.vertices[:, 0]))
    assert all(f < polygon for f in forward)
    assert forward == sorted(forward)
    assert polygon - forward[-1] < FINE_GAP


def test_miqcqp_infeasibility_is_stated_for_its_model_with_the_option_to_relax() -> None:
    sc = scene(SHORT_FLAT)
    coarse = make_plan(sc, "miqcqp", 3, PlannerOptions(heading_segments=COARSE))
    assert coarse.status is SolveStatus.INFEASIBLE
    linear, polygon = linear_reach_forward(sc.robot, COARSE)
    msg = coarse.message
    assert "within the planner's model" in msg and "conservative" in msg
    assert f"{linear:.3f} m" in msg and f"{polygon:.3f} m" in msg
    assert "heading_segments" in msg and "--heading-segments" in msg
    assert "not ruled out" in msg
    # the claim is honest: the default (finer) model has a plan with the same N
    fine = make_plan(sc, "miqcqp", 3, PlannerOptions())
    assert fine.reaches_goal


def test_kinematic_infeasibility_cites_no_torque_bound() -> None:
    sc = scene(SHORT_FLAT)
    plan = make_plan(sc, "kinematic", 3, PlannerOptions(heading_segments=COARSE))
    assert plan.status is SolveStatus.INFEASIBLE
    assert "torque" not in plan.message and "U_max" not in plan.message
    assert "heading_segments" in plan.message


def test_kinematic_torque_excess_is_information_not_a_reason() -> None:
    sc = scene(SHORT_FLAT)
    weak = replace(sc, robot=replace(sc.robot, u_max=2.0))
    plan = make_plan(weak, "kinematic", 3)
    assert plan.reaches_goal
    assert "does not enforce" in plan.message and "U_max = 2 N m" in plan.message
