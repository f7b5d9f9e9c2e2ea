"""Small scenes that the direct MIQCQP solves in seconds, for tests."""

from __future__ import annotations

from footfall.terrain import Scene, load_scene

SHORT_FLAT = """
name: short_flat
description: flat ground, goal 0.6 m ahead
robot: {n_nodes: 4}
start: {left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}
goal: {position: [0.6, 0, 0], heading: 0}
regions:
  - {name: ground, height: 0.0, vertices: [[-1, -1], [2, -1], [2, 1], [-1, 1]]}
"""

TWO_STONES = """
name: two_stones
description: start pad, two stones at different heights, a slope with the goal
robot: {n_nodes: 4}
start: {left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}
goal: {position: [1.1, 0, 0.038462], heading: 0}
regions:
  - {name: pad, height: 0.0, vertices: [[-0.4, -0.4], [0.15, -0.4], [0.15, 0.4], [-0.4, 0.4]]}
  - {name: stone_a, height: 0.08, vertices: [[0.25, 0.0], [0.5, 0.0], [0.5, 0.3], [0.25, 0.3]]}
  - {name: stone_b, height: 0.12, vertices: [[0.45, -0.35], [0.75, -0.35], [0.75, -0.02], [0.45, -0.02]]}
  - {name: slope, vertices: [[0.85, -0.4, 0.0], [1.5, -0.4, 0.1], [1.5, 0.4, 0.1], [0.85, 0.4, 0.0]]}
"""

SHORT_TURN = """
name: short_turn
description: turn 60 degrees left on the spot area
robot: {n_nodes: 4}
start: {left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}
goal: {position: [0.3, 0.3, 0], heading_deg: 60}
regions:
  - {name: ground, height: 0.0, vertices: [[-1, -1], [2, -1], [2, 2], [-1, 2]]}
"""


def scene(text: str) -> Scene:
    return load_scene(text)
