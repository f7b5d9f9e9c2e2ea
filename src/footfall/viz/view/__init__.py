"""``footfall view``: an interactive 3-D page of a scene, a plan, a walk, a quadruped walk or a
study, served locally and drawn with WebGL in any browser (or headless, for a picture).

Layers: :mod:`.load` reads footfall's files into plain frozen dataclasses (one loader per kind,
:func:`load_view` picks it), :mod:`.replay` turns a walk's recorded joint positions into body
poses and meshes, :mod:`.build` makes the scene's nodes and the camera with pure functions,
:mod:`.payload` packs them into the page's one JSON document, :mod:`.serve` is the HTTP server
(standard library), :mod:`.page` joins them, ``static/`` holds the page (an HTML file and its
WebGL2 script, no dependencies) and :mod:`.browser` drives a headless Chromium. Needs the
``view`` extra (``pip install 'footfall[view]'``: trimesh, playwright) and, for a walk's robot,
MuJoCo (``sim``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from footfall.viz.view.load import ViewData, load_view

__all__ = ["ViewData", "load_view"]


def __getattr__(name: str) -> Any:
    # the loaders import the planner and the terrain: only when asked for, so that
    # footfall.viz.view.serve can start the page's server first
    if name in __all__:
        from footfall.viz.view import load

        return getattr(load, name)
    raise AttributeError(name)
