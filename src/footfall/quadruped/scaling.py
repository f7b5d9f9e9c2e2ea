"""Document 001's gait on another robot: the gait and ground given for the document's 0.6 m
robot, scaled to this robot's size (beyond document 001, which plans for one robot).

The rule, with ``k = h / 0.6`` (``h`` the robot's stance height, :attr:`QuadrupedRobot.stance_height`):

- lengths scale by ``k``: step length, swing height, and a ground's lengths (stairs: rise, run,
  start, landing, edge margin, the margin at least the foot's radius; a varying slope: its
  knots' positions, not its inclinations);
- times scale by ``sqrt(k)`` (the same Froude number ``v^2 / (g h)``): swing and shift periods,
  hold time;
- angles stay: slope, body angle, side slope;
- the step is then at most ``STEP_MARGIN`` of the largest step the robot's leg workspace allows on
  that ground (:func:`~footfall.quadruped.gait.largest_step`): a short-legged robot takes
  shorter steps; below ``MIN_STEP_SHARE`` of the scaled step the ground is refused.

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
    if isinstance(scaled.ground, Stairs) and scaled.ground.edge_margin < robot.foot_radius:
        scaled = replace(scaled, ground=replace(scaled.ground, edge_margin=robot.foot_radius))
    most = largest_step(robot, scaled)
    if most < MIN_STEP_SHARE * scaled.step:
        raise InputError(
            "step",
            f"{scaled.step:.3f} m",
            f"a step the legs of {robot.name} reach on this ground: at most {most:.3f} m, less "
            f"than {MIN_STEP_SHARE:g} of the scaled step",
        )
    if most < scaled.step:
        scaled = replace(scaled, step=STEP_MARGIN * most)
    return scaled


__all__ = [
    "DOCUMENT_STANCE",
    "MIN_STEP_SHARE",
    "STEP_MARGIN",
    "gait_scale",
    "scale_gait",
    "scale_ground",
]
