"""Terrain: convex planar regions (document 000, eq. 5.15-5.18), scenes, YAML files, built-ins.

The scene file schema is in ``SCHEMA.md`` next to this file. Scenes from a robot's height map:
:mod:`footfall.terrain.heightmap` (needs the ``terrain`` extra).
"""

from footfall.terrain.edges import inset_riser_edges, riser_edge_insets
from footfall.terrain.region import Region
from footfall.terrain.scene import (
    Goal,
    Scene,
    Start,
    builtin_scene,
    builtin_scene_names,
    load_scene,
    random_stepping_stones,
    scene_to_yaml,
)
from footfall.terrain.terrain import Terrain

__all__ = [
    "Goal",
    "Region",
    "Scene",
    "Start",
    "Terrain",
    "builtin_scene",
    "builtin_scene_names",
    "inset_riser_edges",
    "load_scene",
    "random_stepping_stones",
    "riser_edge_insets",
    "scene_to_yaml",
]
