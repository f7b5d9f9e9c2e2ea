"""Footstep and walking-pattern planners."""

from footfall.planning.lip_examples import example as lip_example
from footfall.planning.lip_walk import LipWalk, LipWalkParams, lip_walk, optimal_foothold

__all__ = ["LipWalk", "LipWalkParams", "lip_example", "lip_walk", "optimal_foothold"]
