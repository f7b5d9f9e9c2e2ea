"""The walk gait on grounds beyond document 001's plane: side slope, varying slope, stairs.

References are independent of the planner: stance feet checked against the ground written out
again, the body pitch against a least-squares fit of the feet (numpy.polyfit), swing clearance
against the exact distance of the foot sphere from the stair boxes.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
from footfall.quadruped.gait import PhaseKind
from footfall.quadruped.ground import Stairs, VaryingSlope
from footfall.quadruped.posture import BodyPosture

ROBOT = QuadrupedRobot()
R = ROBOT.foot_radius
HILL = VaryingSlope((0.5, 2.0, 3.5), (0.0, math.radians(15.0), 0.0))
STAIRS = Stairs(rise=0.1, run=0.4, steps=3, start_x=0.8, landing=2.0)


def _params(ground: object, **kw: object) -> GaitParams:
    return GaitParams(slope=0.0, body_pitch=0.0, ground=ground, **kw)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def stairs_plan():  # type: ignore[no-untyped-def]
    return plan_gait(ROBOT, _params(STAIRS, swing_height=0.15, cycles=7))


@pytest.fixture(scope="module")
def hill_plan():  # type: ignore[no-untyped-def]
    return plan_gait(ROBOT, _params(HILL, cycles=11))


def _tread_height(x: float) -> float:
    edges = [0.8, 1.2, 1.6]
    return 0.1 * sum(x >= e for e in edges)


def test_stairs_feet_rest_on_treads_clear_of_edges(stairs_plan) -> None:  # type: ignore[no-untyped-def]
    edges = np.array([0.8, 1.2, 1.6])
    for ph in stairs_plan.phases:
        for foot in ph.feet_start:
            assert foot[2] == pytest.approx(_tread_height(float(foot[0])), abs=1e-12)
            gaps = foot[0] - edges
            assert np.all((gaps <= -(R + 0.04) + 1e-9) | (gaps >= 0.04 - 1e-9))
    # the walk climbs the whole flight: every foot ends on the landing
    assert np.all(stairs_plan.phases[-1].feet_start[:, 2] == pytest.approx(0.3))


def test_stairs_swings_clear_the_step_boxes(stairs_plan) -> None:  # type: ignore[no-untyped-def]
    ref = stairs_plan.sample(0.005, with_zmp=False)
    # each step k is a box from its riser onwards whose top is k * rise below the foot-centre
    # level: the foot sphere must not enter any of them (distance from a point to a box corner)
    worst = np.inf
    for i in range(4):
        for c in ref.feet[~ref.contact[:, i], i]:
            for k, e in enumerate([0.8, 1.2, 1.6]):
                top = 0.1 * (k + 1) - R  # the box's top face height
                if c[0] >= e:  # above the box (or inside it: negative)
                    dist = c[2] - top
                else:  # beside it: distance to its riser face or its nosing
                    dist = math.hypot(e - c[0], max(c[2] - top, 0.0))
                worst = min(worst, dist - R)
    assert worst >= -1e-6


def test_stairs_swing_too_low_is_refused() -> None:
    with pytest.raises(InputError) as err:
        plan_gait(ROBOT, _params(STAIRS, swing_height=0.03, cycles=4))
    assert err.value.field == "swing_height"
    assert "too low" in err.value.expected


def test_hill_feet_rest_on_the_curve(hill_plan) -> None:  # type: ignore[no-untyped-def]
    from scipy.integrate import quad

    def height(x: float) -> float:
        beta = lambda s: float(np.interp(s, [0.5, 2.0, 3.5], [0.0, math.radians(15.0), 0.0]))  # noqa: E731
        return quad(lambda s: math.tan(beta(s)), 0.0, x, points=[0.5, 2.0, 3.5])[0]

    feet = np.concatenate([ph.feet_start for ph in hill_plan.phases[::5]])
    for foot in feet:
        assert foot[2] == pytest.approx(height(float(foot[0])), abs=1e-8)


def test_body_pitch_follows_the_local_plane_of_the_feet(hill_plan) -> None:  # type: ignore[no-untyped-def]
    pitches = []
    for k, ph in enumerate(hill_plan.phases[:-2]):
        if ph.kind is not PhaseKind.SHIFT:
            continue
        # the feet before and after the group of swings that follows this shift
        after = hill_plan.phases[k + 1].feet_start.copy()
        for sw in hill_plan.phases[k + 1 :]:
            if sw.kind is not PhaseKind.SWING:
                break
            after[sw.leg.idx] = sw.foot_end  # type: ignore[union-attr]
        pts = np.vstack([ph.feet_start, after])
        design = np.column_stack([np.ones(8), pts[:, 0], pts[:, 1]])
        b = np.linalg.lstsq(design, pts[:, 2], rcond=None)[0][1]
        assert ph.pitch_end == pytest.approx((2.0 / 3.0) * math.atan(b), abs=1e-9)
        pitches.append(ph.pitch_end)
    # up the hill the nose rises, then it comes back level
    assert max(pitches) > math.radians(6.0)
    assert abs(pitches[-1]) < math.radians(1.0)


def test_pitch_changes_only_in_shifts_and_continuously(hill_plan) -> None:  # type: ignore[no-untyped-def]
    for a, b in zip(hill_plan.phases[:-1], hill_plan.phases[1:], strict=True):
        assert b.pitch_start == a.pitch_end
        if a.kind is not PhaseKind.SHIFT:
            assert a.pitch_start == a.pitch_end
    ref = hill_plan.sample(0.01, with_zmp=False)
    assert np.max(np.abs(np.diff(ref.body_pitch))) < math.radians(0.2)


@pytest.mark.parametrize("which", ["hill", "stairs"])
def test_planned_zmp_stays_inside_the_support_triangles(which, hill_plan, stairs_plan) -> None:  # type: ignore[no-untyped-def]
    plan = hill_plan if which == "hill" else stairs_plan
    ref = plan.sample(0.01)
    three = ref.contact.sum(axis=1) == 3
    assert ref.margin[three].min() > 0.05


def test_side_slope_keeps_the_body_level_across() -> None:
    side = math.radians(15.0)
    plan = plan_gait(
        ROBOT,
        GaitParams(slope=math.radians(10), body_pitch=math.radians(6), side_slope=side, cycles=2),
    )
    for ph in plan.phases:
        for foot in ph.feet_start:
            z = foot[0] * math.tan(math.radians(10)) + foot[1] * math.tan(side)
            assert foot[2] == pytest.approx(z, abs=1e-12)
    ref = plan.sample(0.01)
    # body 0.6 m above the plane at its own position, pitched 6 deg
    body = ref.body_pos
    plane = body[:, 0] * math.tan(math.radians(10)) + body[:, 1] * math.tan(side)
    np.testing.assert_allclose(body[:, 2] - plane, ROBOT.stance_height, atol=1e-9)
    np.testing.assert_allclose(ref.body_pitch, math.radians(6))
    three = ref.contact.sum(axis=1) == 3
    assert ref.margin[three].min() > 0.05


def test_steeper_side_slope_than_the_legs_reach_is_refused() -> None:
    with pytest.raises(InputError) as err:
        plan_gait(ROBOT, GaitParams(slope=0.0, body_pitch=0.0, side_slope=math.radians(55)))
    assert err.value.field == "side_slope"


@pytest.mark.parametrize(
    ("kw", "field"),
    [
        ({"slope": 0.1}, "slope"),
        ({"side_slope": 0.1}, "side_slope"),
        ({"posture": BodyPosture.PARALLEL}, "posture"),
        ({"body_ratio": 1.5}, "body_ratio"),
        ({"ground": "stairs"}, "ground"),
    ],
)
def test_bad_ground_params_name_the_field(kw: dict[str, object], field: str) -> None:
    base = {"slope": 0.0, "body_pitch": 0.0, "ground": HILL}
    with pytest.raises(InputError) as err:
        GaitParams(**{**base, **kw})  # type: ignore[arg-type]
    assert err.value.field == field


def test_horizontal_posture_keeps_the_body_level_on_the_hill() -> None:
    plan = plan_gait(ROBOT, replace(_params(HILL, cycles=4), posture=BodyPosture.HORIZONTAL))
    assert all(ph.pitch_end == 0.0 for ph in plan.phases)
