"""What the independent checker reports, not only which kind: the footstep, the amount and the text.

:mod:`tests.planning.test_check_oracle` breaks each check once and asserts the kind; here the
reports are pinned down with values known without the checker: the size of the perturbation, a
distance read off the plan's footsteps by hand, a tolerance edge (just inside vs just outside,
and for the start check the tolerance itself, which is accepted), the exact message fields of
:class:`Violation` and :meth:`CheckReport.summary`, and the geometry helpers on shapes whose
distances and heights are known in closed form.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.models.biped import ReachTrapezoid, Side
from footfall.planning import check_plan
from footfall.planning.check import (
    ANGLE_TOL,
    GEOM_TOL,
    STATE_TOL,
    TORQUE_RTOL,
    CheckReport,
    Violation,
    _inside_polygon,
    _plane_height,
    _simulate_single_support,
)
from footfall.planning.plan import FootstepPlan
from tests.planning.test_check_oracle import (
    NUDGE,
    _alternation,
    _base,
    _goal_position,
    _initial_state,
    _region_outside,
    _region_plane,
    _region_unknown,
    _reset,
    _robot,
    _shifted,
    _start,
)

ALL_CHECKS = ("start", "region", "reach", "heading_rate", "torque", "dynamics", "goal")


def _found(report: CheckReport, kind: str) -> list[tuple[int, float]]:
    """(footstep, amount) of each violation of ``kind``, in report order."""
    return [(v.step, v.amount) for v in report.violations if v.kind == kind]


# --- Violation.describe and CheckReport.summary -------------------------------------------------


def test_describe_names_kind_footstep_amount_and_message() -> None:
    v = Violation("region", 3, 0.0123456, "1.23e-02 m outside stone_a (margin 0 m)")
    assert (
        v.describe()
        == "region at footstep 3 (amount 0.0123): 1.23e-02 m outside stone_a (margin 0 m)"
    )
    assert Violation("start", 0, 0.5, "m").describe() == "start at footstep 0 (amount 0.5): m"
    whole = Violation("dynamics", -1, 2.5e-3, "ALIP states differ")
    assert whole.describe() == "dynamics at the whole plan (amount 0.0025): ALIP states differ"


def test_summary_is_ok_or_one_line_per_violation() -> None:
    assert CheckReport((), 0.0).summary() == "ok"
    a = Violation("goal", 5, 0.01, "footstep 5 is 0.010 m from its goal spot")
    b = Violation("torque", 2, 31.0, "|u| = 31.000 N m")
    report = CheckReport((a, b), 0.0)
    assert report.summary() == (
        "goal at footstep 5 (amount 0.01): footstep 5 is 0.010 m from its goal spot\n"
        "torque at footstep 2 (amount 31): |u| = 31.000 N m"
    )
    assert not report.ok and report.kinds() == {"goal", "torque"}


# --- geometry helpers on known shapes ----------------------------------------------------------

#: a 2 m x 1 m rectangle (edges of different length: distances are not scaled by an edge length)
RECT = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
#: a right triangle, legs 1 m (three corners: the orientation sum has no symmetric partner term)
TRI = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


@pytest.mark.parametrize("order", [1, -1], ids=["ccw", "cw"])
@pytest.mark.parametrize(
    ("shape", "xy", "expected"),
    [
        (RECT, (3.0, 0.5), 1.0),  # 1 m beyond the right edge (length 1)
        (RECT, (1.0, -0.25), 0.25),  # 0.25 m below the bottom edge (length 2)
        (RECT, (1.0, 0.5), -0.5),  # centre: 0.5 m inside the nearest edges
        (RECT, (0.0, 0.5), 0.0),  # on the left edge
        (TRI, (0.25, 0.25), -0.25),
        (TRI, (1.0, 1.0), math.sqrt(0.5)),  # beyond the hypotenuse (length sqrt 2)
        (TRI, (-0.5, 0.5), 0.5),
    ],
)
def test_inside_polygon_signed_distance(
    shape: np.ndarray, xy: tuple[float, float], expected: float, order: int
) -> None:
    corners = shape[::order]
    assert _inside_polygon(np.array(xy), corners, GEOM_TOL) == pytest.approx(expected, abs=1e-12)


def test_plane_height_of_a_tilted_plane() -> None:
    """z = 0.1 + 0.2 x + 0.3 y on a triangle and on a quadrilateral away from the origin."""

    def z(x: float, y: float) -> float:
        return 0.1 + 0.2 * x + 0.3 * y

    xy = [(1.0, 1.0), (3.0, 1.0), (3.0, 2.0), (1.0, 2.0)]
    quad = np.array([[x, y, z(x, y)] for x, y in xy])
    for corners in (quad, quad[:3]):
        for x, y in [(2.0, 1.5), (0.0, 0.0), (-1.0, 4.0)]:
            assert _plane_height(corners, np.array([x, y])) == pytest.approx(z(x, y), abs=1e-12)


def test_plane_height_with_collinear_corners() -> None:
    """A height map's polygon may start with three collinear corners (a vertex on a straight
    edge): the plane through them is undefined, the plane through the polygon is not. Exactly
    collinear corners and ones a round-off off the line give the tilted plane's height."""

    def z(x: float, y: float) -> float:
        return 0.1 + 0.2 * x - 0.15 * y

    for wobble in (0.0, 1e-13):
        xy = [(1.0, 1.0), (2.0, 1.0 + wobble), (3.0, 1.0), (3.0, 2.0), (1.0, 2.0)]
        corners = np.array([[x, y, z(x, y)] for x, y in xy])
        for x, y in [(2.0, 1.5), (1.0, 1.0), (-1.0, 4.0)]:
            assert _plane_height(corners, np.array([x, y])) == pytest.approx(z(x, y), abs=1e-12)


def test_single_support_simulation_matches_the_closed_form() -> None:
    """c(t) = p + (c0 - p) cosh(w t) + v0 / w sinh(w t) about the CoP p of a constant torque."""
    robot = _base("stones")[0].robot
    mzh = robot.mass * robot.com_height
    w = math.sqrt(robot.g / robot.com_height)
    x0 = np.array([0.03, -0.02, 0.4 * mzh, 0.3 * mzh])  # v = (L_y, -L_x) / (m z_H) = (0.3, -0.4)
    torque = np.array([2.0, -3.0])
    t = 0.3
    cop = np.array([-torque[1], torque[0]]) / (robot.mass * robot.g)
    c0, v0 = x0[:2], np.array([x0[3], -x0[2]]) / mzh
    c = cop + (c0 - cop) * math.cosh(w * t) + v0 / w * math.sinh(w * t)
    v = (c0 - cop) * w * math.sinh(w * t) + v0 * math.cosh(w * t)
    expected = np.array([c[0], c[1], -mzh * v[1], mzh * v[0]])
    sim = _simulate_single_support(robot, x0, torque, t)
    np.testing.assert_allclose(sim, expected, rtol=0, atol=1e-9)


# --- check_plan's arguments and report fields --------------------------------------------------


@pytest.mark.parametrize(
    ("which", "field", "expected"),
    [
        ("plan", "plan", "a FootstepPlan (make_plan, load_plan)"),
        ("scene", "scene", "a Scene (footfall.terrain.resolve_scene)"),
        ("robot", "robot", "a BipedParams or None"),
    ],
)
def test_check_plan_rejects_wrong_argument_types(which: str, field: str, expected: str) -> None:
    plan, sc = _base("stones")
    args = {"plan": plan, "scene": sc, "robot": None, which: "not it"}
    with pytest.raises(InputError) as err:
        check_plan(args["plan"], args["scene"], args["robot"])  # type: ignore[arg-type]
    assert (err.value.field, err.value.value, err.value.expected) == (field, "not it", expected)


def test_report_of_a_valid_plan_lists_the_checks_and_a_small_dynamics_error() -> None:
    plan, sc = _base("stones")
    report = check_plan(plan, sc)
    assert report.checked == ALL_CHECKS
    assert isinstance(report.dynamics_error, float) and 0.0 <= report.dynamics_error < STATE_TOL
    swing = check_plan(replace(plan, swing_max=1.0), sc)
    assert swing.ok and swing.checked == ("start", "region", "reach", "swing", *ALL_CHECKS[3:])


def test_report_without_a_solution() -> None:
    plan, sc = _base("stones")
    empty = FootstepPlan.empty("miqcqp", plan.status, plan.robot, "no plan")
    report = check_plan(empty, sc)
    assert report.violations == (Violation("no_solution", 0, math.inf, "no plan"),)
    assert report.dynamics_error == math.inf and report.checked == ()


def test_swing_violations_do_not_hide_the_earlier_checks() -> None:
    plan, sc = _base("stones")
    report = check_plan(replace(plan, region_margin=NUDGE, swing_max=0.1), sc)
    assert report.kinds() == {"region", "swing"}, report.summary()


# --- start and alternation ---------------------------------------------------------------------


def test_start_foot_amount_and_its_tolerance() -> None:
    plan, sc = _base("stones")
    right = sc.start.right
    report = check_plan(plan, _start(sc, right=_shifted(right, (0,), NUDGE)))
    (v,) = report.violations
    assert (v.kind, v.step, v.message) == ("start", 0, "footstep 0 is not the given stance foot")
    assert v.amount == pytest.approx(NUDGE, abs=1e-12)
    # footstep 0 stands exactly on the scene's foot: a shift of the tolerance itself is accepted
    assert plan.footsteps[0, 0] == right[0] == 0.0
    assert check_plan(plan, _start(sc, right=_shifted(right, (0,), GEOM_TOL))).ok
    assert not check_plan(plan, _start(sc, right=_shifted(right, (0,), 2 * GEOM_TOL))).ok


def test_start_heading_amount_and_its_tolerance() -> None:
    plan, sc = _base("turn")  # headings 0 then 0.39 rad: the amount is of heading 0
    report = check_plan(plan, _start(sc, heading=sc.start.heading + NUDGE))
    (v,) = report.violations
    assert (v.kind, v.step, v.message) == ("start", 0, "heading 0 differs")
    assert v.amount == pytest.approx(NUDGE, abs=1e-12)
    assert plan.headings[0] == sc.start.heading == 0.0
    assert check_plan(plan, _start(sc, heading=ANGLE_TOL)).ok
    assert "start" in check_plan(plan, _start(sc, heading=2 * ANGLE_TOL)).kinds()


def test_start_heading_is_compared_not_added() -> None:
    """Plan and scene both turned by -1 mrad: the start heading agrees (their sum would not)."""
    plan, sc = _base("stones")
    turned = replace(plan, headings=_shifted(plan.headings, (0,), -1e-3))
    report = check_plan(turned, _start(sc, heading=sc.start.heading - 1e-3))
    assert "start" not in report.kinds(), report.summary()
    report = check_plan(turned, _start(sc, heading=sc.start.heading - 1e-3 + NUDGE))
    assert _found(report, "start") == [(0, pytest.approx(NUDGE, abs=1e-12))], report.summary()


def test_alternation_steps_and_amounts() -> None:
    plan, sc = _base("stones")
    report = check_plan(*_alternation(plan, sc))  # sides R L R L R R: footstep 5 repeats
    assert _found(report, "alternation") == [(5, 1.0)]
    (v,) = [v for v in report.violations if v.kind == "alternation"]
    assert v.message == "two consecutive steps with the same foot"
    first = replace(plan, sides=(plan.sides[0], plan.sides[0], *plan.sides[2:]))  # R R R L R L
    assert _found(check_plan(first, sc), "alternation") == [(1, 1.0), (2, 1.0)]


# --- regions ----------------------------------------------------------------------------------


def test_region_amounts_and_footsteps() -> None:
    plan, sc = _base("stones")
    # footstep 1 stands on stone_a's back edge x = 0.25; the edge moved to x = 0.3
    assert _found(check_plan(*_region_outside(plan, sc)), "region") == [
        (1, pytest.approx(0.3 - plan.footsteps[1, 0], abs=1e-12))
    ]
    assert _found(check_plan(*_region_plane(plan, sc)), "region") == [
        (2, pytest.approx(NUDGE, abs=1e-9))
    ]
    assert _found(check_plan(*_region_unknown(plan, sc)), "region") == [(2, math.inf)]


def test_an_unknown_region_does_not_stop_the_region_check() -> None:
    plan, sc = _base("stones")
    p, _ = _region_unknown(plan, sc)
    p = replace(p, footsteps=_shifted(p.footsteps, (4, 2), NUDGE))
    found = _found(check_plan(p, sc), "region")
    assert found == [(2, math.inf), (4, pytest.approx(NUDGE, abs=1e-9))]


def test_footstep_zero_is_checked_by_the_start_not_the_regions() -> None:
    plan, sc = _base("stones")
    assert check_plan(replace(plan, regions=("nowhere", *plan.regions[1:])), sc).ok


# --- reach and step height --------------------------------------------------------------------

#: a rectangle x in [-0.2, 0.2], y in [0.1, 0.35] (right stance; mirrored for a left one)
RECT_REACH = ReachTrapezoid(np.array([[-0.2, 0.1], [0.2, 0.1], [0.2, 0.35], [-0.2, 0.35]]))


def test_reach_amounts_are_the_overshoot_of_each_step() -> None:
    """Every step of the stones plan but the last goes further forward than 0.2 m: the amount is
    its forward length minus 0.2 (headings are 0 within 1e-5 rad), on both feet."""
    plan, sc = _base("stones")
    report = check_plan(_robot(plan, reach=RECT_REACH), sc)
    fwd = np.diff(plan.footsteps[:, 0])
    assert fwd[-1] < 0.2 and all(fwd[:-1] > 0.2)
    want = [(i + 1, pytest.approx(fwd[i] - 0.2, abs=1e-5)) for i in range(4)]
    assert _found(report, "reach") == want, report.summary()
    msgs = [v.message for v in report.violations if v.kind == "reach"]
    assert msgs == [f"{a:.2e} m outside the reach set" for _, a in _found(report, "reach")]


def test_reach_in_both_frames_reports_each_frame() -> None:
    """Headings 0: the landing foot's frame is the stance foot's, so each step is flagged twice."""
    plan, sc = _base("stones")
    report = check_plan(replace(_robot(plan, reach=RECT_REACH), reach_both_frames=True), sc)
    reach = [v for v in report.violations if v.kind == "reach"]
    assert [v.step for v in reach] == [1, 1, 2, 2, 3, 3, 4, 4]
    for own, landing in zip(reach[::2], reach[1::2], strict=True):
        assert own.message == f"{own.amount:.2e} m outside the reach set"
        assert (
            landing.message
            == f"{landing.amount:.2e} m outside the reach set in the landing foot's frame"
        )


def test_reach_in_the_landing_foots_frame_uses_the_landing_heading() -> None:
    """The turn: rotated by the heading of the footstep it lands on, steps 1 and 3 (right stance
    foot) come closer to it sideways than the trapezoid's inner edge y = 0.12 m allows; the amount
    is 0.12 m minus that sideways distance (mirrored for a left stance foot)."""
    plan, sc = _base("turn")
    assert np.allclose(plan.robot.reach.vertices[:2, 1], 0.12)
    report = check_plan(replace(plan, reach_both_frames=True), sc)
    want = []
    for i in range(plan.n_steps):
        dx, dy = plan.footsteps[i + 1, :2] - plan.footsteps[i, :2]
        th = plan.headings[i + 1]
        side = 1.0 if plan.sides[i] is Side.RIGHT else -1.0
        gap = 0.12 - side * (-math.sin(th) * dx + math.cos(th) * dy)
        if gap > GEOM_TOL:
            want.append((i + 1, pytest.approx(gap, abs=1e-12)))
    assert [s for s, _ in want] == [1, 3]
    assert _found(report, "reach") == want, report.summary()


def test_step_height_footstep_amount_and_tolerance_edge() -> None:
    """The plan steps down 0.12 m from stone_b (footstep 2) to the slope (footstep 3)."""
    plan, sc = _base("stones")
    dz = abs(plan.footsteps[3, 2] - plan.footsteps[2, 2])
    assert dz == pytest.approx(0.12, abs=1e-9)
    assert check_plan(_robot(plan, step_height_max=dz - 0.5 * GEOM_TOL), sc).ok
    report = check_plan(_robot(plan, step_height_max=dz - 2 * GEOM_TOL), sc)
    assert _found(report, "step_height") == [(3, dz)]
    assert report.violations[0].message == f"step height {dz:.3f} m"


# --- swing --------------------------------------------------------------------------------------


def test_swing_lengths_from_each_feet_previous_foothold() -> None:
    """Swing i runs from footstep i - 2 (the scene's left foot for footstep 1)."""
    plan, sc = _base("stones")
    f = plan.footsteps[:, :2]
    prev = [sc.start.left[:2], f[0], f[1], f[2], f[3]]
    lengths = [float(np.hypot(*(f[i + 1] - prev[i]))) for i in range(5)]
    report = check_plan(replace(plan, swing_max=0.0), sc)
    assert _found(report, "swing") == [
        (i + 1, pytest.approx(x, abs=1e-12)) for i, x in enumerate(lengths)
    ]
    longest = max(lengths)
    at = lengths.index(longest) + 1
    assert check_plan(replace(plan, swing_max=longest - 0.5 * GEOM_TOL), sc).ok
    edge = check_plan(replace(plan, swing_max=longest - 2 * GEOM_TOL), sc)
    assert _found(edge, "swing") == [(at, pytest.approx(2 * GEOM_TOL, abs=1e-12))]


# --- heading rate and torque ------------------------------------------------------------------


def test_heading_rate_footstep_amount_and_tolerance_edge() -> None:
    plan, sc = _base("turn")
    rates = np.abs(np.diff(plan.headings))
    top = float(rates.max())
    at = int(np.argmax(rates)) + 1  # the change into footstep `at`
    assert at == 1  # the turn starts with its largest change
    assert check_plan(_robot(plan, theta_max=top - 0.5 * ANGLE_TOL), sc).ok
    report = check_plan(_robot(plan, theta_max=top - 2 * ANGLE_TOL), sc)
    assert _found(report, "heading_rate") == [(at, top)]
    assert report.violations[0].message == f"heading change {top:.4f} rad"


def test_torque_phase_amount_and_tolerance_edge() -> None:
    plan, sc = _base("stones")
    torques = np.array(plan.torques)
    torques[2] *= 100.0  # phase 2 now has the largest torque (the dynamics break too)
    big = replace(plan, torques=torques)
    largest = 100.0 * float(np.linalg.norm(plan.torques[2], axis=-1).max())
    report = check_plan(big, sc)
    assert _found(report, "torque") == [(2, pytest.approx(largest, rel=1e-12))]
    # the largest torque of the unchanged plan is in phase 0
    top = float(np.linalg.norm(plan.torques, axis=-1).max())
    assert check_plan(_robot(plan, u_max=top / (1 + 0.5 * TORQUE_RTOL)), sc).ok
    edge = check_plan(_robot(plan, u_max=top / (1 + 2 * TORQUE_RTOL)), sc)
    assert _found(edge, "torque") == [(0, top)]


# --- dynamics ---------------------------------------------------------------------------------


def test_dynamics_amounts_and_footsteps() -> None:
    plan, sc = _base("stones")
    report = check_plan(*_initial_state(plan, sc))
    assert _found(report, "dynamics") == [(0, pytest.approx(NUDGE, abs=1e-12))]
    assert report.violations[0].message == "initial state differs from the scene's"
    report = check_plan(*_reset(plan, sc))
    assert _found(report, "dynamics") == [(-1, pytest.approx(NUDGE, abs=1e-6))]
    assert report.dynamics_error == pytest.approx(NUDGE, abs=1e-6)


def test_initial_state_is_compared_not_added() -> None:
    """Plan and scene start from the same non-zero state: no initial-state violation."""
    plan, sc = _base("stones")
    x0 = np.array([0.01, 0.0, 0.0, 0.0])
    states = np.array(plan.states)
    states[0, 0] = x0
    report = check_plan(replace(plan, states=states), _start(sc, alip_state=x0))
    assert 0 not in [v.step for v in report.violations if v.kind == "dynamics"], report.summary()


def test_the_last_interval_of_each_phase_is_simulated() -> None:
    """A torque changed on the last interval of phase 0 only: its end node disagrees."""
    plan, sc = _base("stones")
    torques = np.array(plan.torques)
    torques[0, -1] *= 0.5
    report = check_plan(replace(plan, torques=torques), sc)
    assert report.kinds() == {"dynamics"} and report.dynamics_error > STATE_TOL


# --- goal -------------------------------------------------------------------------------------


def test_goal_amounts_and_footsteps() -> None:
    plan, sc = _base("stones")
    report = check_plan(*_goal_position(plan, sc))
    n = plan.n_steps
    assert _found(report, "goal") == [
        (n - 1, pytest.approx(NUDGE, abs=1e-5)),
        (n, pytest.approx(NUDGE, abs=1e-5)),
    ]


def test_goal_heading_tolerance_edge_and_wrap() -> None:
    """The goal heading is held to 10 ANGLE_TOL, modulo a full turn."""
    plan, sc = _base("turn")
    tol = 10 * ANGLE_TOL
    for off, flagged in [(0.5 * tol, False), (1.05 * tol, True)]:
        report = check_plan(replace(plan, headings=_shifted(plan.headings, (-1,), off)), sc)
        assert ("goal" in report.kinds()) is flagged, (off, report.summary())
    for turn in (2 * math.pi, -2 * math.pi):
        report = check_plan(replace(plan, headings=_shifted(plan.headings, (-1,), turn)), sc)
        assert "goal" not in report.kinds(), report.summary()
