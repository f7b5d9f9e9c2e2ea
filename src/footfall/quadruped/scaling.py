"""Document 001's gait on another robot: the gait and ground given for the document's 0.6 m
robot, scaled to this robot's size (beyond document 001, which plans for one robot).

The rule, with ``k = h / 0.6`` (``h`` the robot's stance height, :attr:`QuadrupedRobot.stance_height`):

- lengths scale by ``k``: step length, swing height, and a ground's lengths (stairs: rise, run,
  start, landing, edge margin, the margin at least ``EDGE_RADII`` foot radii; a varying slope: its
  knots' positions, not its inclinations);
- times scale by ``sqrt(k)`` (the same Froude number ``v^2 / (g h)``): swing and shift periods,
  hold time;
- angles stay: slope, body angle, side slope;
- the step is then at most ``STEP_MARGIN`` of the largest step the robot's leg workspace allows on
  that ground (:func:`~footfall.quadruped.gait.largest_step`): a short-legged robot takes
  shorter steps;
- the feet stand under vertical legs; where the legs then reach less than ``MIN_STEP_SHARE`` of
  the scaled step (a wide stance needs large body shifts over its support triangles: Solo-12 and
  ANYmal C on the side slope, ANYmal on stairs), the stance narrows, each foot standing out of its
  ab/ad axis by half the leg's lateral offset (``GaitParams.lateral_share``); a ground neither
  width fits is refused. (3/4 was tried too and dropped: ANYmal's feet slid 0.4 m at its start
  of the stairs scene with it, while 1/2 walks them.)

The optimal stability point, the posture (eq. 9) and the swing (eq. 10-13) are unchanged: they
are computed from the robot's own geometry.
"""

from __future__ import annotations

import math
from dataclasses import replace

from footfall.errors import InputError
from footfall.quadruped.gait import GaitParams, largest_step
from footfall.quadruped.ground import QuadrupedGround, Stairs, VaryingSlope
from footfall.quadruped.robot import QuadrupedRobot

#: document 001's stance height [m]: the unit of the scale
DOCUMENT_STANCE = 0.6
#: the scaled step is at most this share of the largest feasible step
STEP_MARGIN = 0.9
#: a ground whose largest feasible step is below this share of the scaled step is refused (the
#: walk would barely move)
MIN_STEP_SHARE = 0.25
#: a stair foothold keeps at least this many foot radii from the edge (document 001's stairs:
#: 4 cm for its 3 cm foot)
EDGE_RADII = 1.5
#: stance widths tried in order, as the share of each leg's lateral offset its foot stands out
LATERAL_SHARES = (1.0, 0.5)


def gait_scale(robot: QuadrupedRobot) -> float:
    """The robot's size against document 001's: its stance height over 0.6 m."""
    return robot.stance_height / DOCUMENT_STANCE


def scale_ground(ground: QuadrupedGround | None, k: float) -> QuadrupedGround | None:
    """``ground`` with its lengths scaled by ``k`` (inclinations kept)."""
    if isinstance(ground, Stairs):
        return replace(
            ground,
            rise=k * ground.rise,
            run=k * ground.run,
            start_x=k * ground.start_x,
            landing=k * ground.landing,
            edge_margin=k * ground.edge_margin,
        )
    if isinstance(ground, VaryingSlope):
        return replace(ground, knots_x=tuple(k * x for x in ground.knots_x))
    return ground


def scale_gait(robot: QuadrupedRobot, params: GaitParams) -> GaitParams:
    """``params`` (for document 001's robot) scaled to ``robot`` (module docstring); the
    document's robot gets them unchanged.

    Raises:
        InputError: the posture does not fit the robot's legs on this ground (named as
            :func:`~footfall.quadruped.gait.check_reachability` names it).
    """
    if robot.legs is None:
        return params
    k = gait_scale(robot)
    t = math.sqrt(k)
    scaled = replace(
        params,
        step=k * params.step,
        swing_height=k * params.swing_height,
        swing_period=t * params.swing_period,
        shift_period=t * params.shift_period,
        hold_time=t * params.hold_time,
        height=None if params.height is None else k * params.height,
        ground=scale_ground(params.ground, k),
    )
    edge = EDGE_RADII * robot.foot_radius
    if isinstance(scaled.ground, Stairs) and scaled.ground.edge_margin < edge:
        scaled = replace(scaled, ground=replace(scaled.ground, edge_margin=edge))
    first: InputError | None = None
    for share in LATERAL_SHARES:
        trial = replace(scaled, lateral_share=share)
        try:
            most = largest_step(robot, trial)
        except InputError as e:  # the neutral stance itself out of reach at this width
            first = first or e
            most = 0.0
        if most >= MIN_STEP_SHARE * scaled.step:
            return trial if most >= trial.step else replace(trial, step=STEP_MARGIN * most)
    if first is not None and first.field != "step":
        raise first
    raise InputError(
        "step",
        f"{scaled.step:.3f} m",
        f"a step the legs of {robot.name} reach on this ground (at every stance width tried, "
        f"feet {', '.join(f'{s:g}' for s in LATERAL_SHARES)} of the lateral offset out: at most "
        f"{most:.3f} m at the narrowest, less than {MIN_STEP_SHARE:g} of the scaled step)",
    )


__all__ = [
    "DOCUMENT_STANCE",
    "EDGE_RADII",
    "LATERAL_SHARES",
    "MIN_STEP_SHARE",
    "STEP_MARGIN",
    "gait_scale",
    "scale_gait",
    "scale_ground",
]
