"""Quadruped scenes in YAML: a ground (:mod:`footfall.quadruped.ground`), the gait on it, and the
foot friction. Schema in ``footfall/terrain/SCHEMA.md`` ("Quadruped scenes").

Loading shares the biped scenes' safe YAML reader (no Python objects, bounded size, alias bombs
refused) and their errors, which name the field and its line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field

from footfall.errors import InputError, SceneError
from footfall.quadruped.gait import GaitParams
from footfall.quadruped.ground import PlaneGround, QuadrupedGround, Stairs, VaryingSlope
from footfall.quadruped.zmp_planning import ZmpStrategy
from footfall.terrain.scene import (
    MAX_DESCRIPTION,
    Name,
    StrictSpec,
    YamlLocator,
    packaged_scene_names,
    packaged_scene_text,
    read_yaml,
    validate_yaml,
)

#: most knots of a varying slope
MAX_KNOTS = 1000


class _GroundSpec(StrictSpec):
    kind: Literal["plane", "varying", "stairs"]
    slope_deg: float | None = None
    side_slope_deg: float | None = None
    knots: (
        Annotated[
            list[Annotated[list[float], Field(min_length=2, max_length=2)]],
            Field(min_length=2, max_length=MAX_KNOTS),
        ]
        | None
    ) = None
    rise: float | None = None
    run: float | None = None
    steps: int | None = None
    start: float | None = None
    landing: float | None = None
    edge_margin: float | None = None


class _GaitSpec(StrictSpec):
    body_deg: float | None = None
    body_ratio: float | None = None
    step: float = 0.4
    swing_height: float = 0.1
    swing_period: float = 0.5
    shift_period: float = 1.5
    cycles: int = 6
    strategy: Literal["osp", "incentre", "transverse"] = "osp"
    height: float | None = None
    hold_time: float = 0.5


class _QuadrupedSceneSpec(StrictSpec):
    name: Name
    description: Annotated[str, Field(max_length=MAX_DESCRIPTION)] = ""
    ground: _GroundSpec
    gait: _GaitSpec = Field(default_factory=_GaitSpec)
    friction: float | None = None


#: which keys each ground kind takes
_GROUND_KEYS = {
    "plane": {"slope_deg", "side_slope_deg"},
    "varying": {"knots"},
    "stairs": {"rise", "run", "steps", "start", "landing", "edge_margin"},
}


@dataclass(frozen=True)
class QuadrupedScene:
    """A quadruped scene: the gait (its ground inside) and the foot friction.

    Attributes:
        name: short identifier.
        description: one line for humans.
        params: the gait on the scene's ground.
        friction: sliding friction of the feet, None for the simulator's default.
    """

    name: str
    description: str
    params: GaitParams
    friction: float | None = None

    @property
    def ground(self) -> QuadrupedGround:
        """The scene's ground."""
        return self.params.terrain


def _ground(spec: _GroundSpec, loc: YamlLocator) -> tuple[QuadrupedGround | None, float, float]:
    """The ground (None for a plane), and the plane's slope and side slope [rad]."""
    extra = sorted(spec.model_fields_set - {"kind"} - _GROUND_KEYS[spec.kind])
    if extra:
        key = extra[0]
        raise loc.error(
            ("ground", key),
            getattr(spec, key),
            f"no such field for a {spec.kind} ground (it takes "
            f"{', '.join(sorted(_GROUND_KEYS[spec.kind]))})",
        )
    if spec.kind == "varying" and spec.knots is None:
        raise loc.error(("ground", "knots"), None, "[[x, slope_deg], ...] (>= 2 knots)")
    try:
        if spec.kind == "plane":
            for key in ("slope_deg", "side_slope_deg"):
                deg = getattr(spec, key)
                if deg is not None and not -60.0 <= deg <= 60.0:
                    raise loc.error(("ground", key), deg, "an inclination in [-60, 60] deg")
            slope = math.radians(spec.slope_deg or 0.0)
            side = math.radians(spec.side_slope_deg or 0.0)
            PlaneGround(slope, side)
            return None, slope, side
        if spec.kind == "varying":
            assert spec.knots is not None
            xs = tuple(k[0] for k in spec.knots)
            slopes = tuple(math.radians(k[1]) for k in spec.knots)
            return VaryingSlope(xs, slopes), 0.0, 0.0
        given = {
            key: getattr(spec, key)
            for key in ("rise", "run", "steps", "landing", "edge_margin")
            if getattr(spec, key) is not None
        }
        if spec.start is not None:
            given["start_x"] = spec.start
        return Stairs(**given), 0.0, 0.0
    except SceneError:
        raise
    except InputError as e:
        raise loc.error(_ground_path(e.field), e.value, e.expected) from None


def _ground_path(fld: str) -> tuple[str | int, ...]:
    """The YAML path of a ground's field: ``knots_x[2]`` is ``ground.knots[2]``."""
    if fld.startswith("knots"):
        index = fld[fld.index("[") + 1 : -1] if "[" in fld else None
        return ("ground", "knots") if index is None else ("ground", "knots", int(index))
    yaml_name = {"start_x": "start", "slope": "slope_deg", "side_slope": "side_slope_deg"}
    return ("ground", yaml_name.get(fld, fld))


def _params(spec: _QuadrupedSceneSpec, loc: YamlLocator) -> GaitParams:
    ground, slope, side = _ground(spec.ground, loc)
    g = spec.gait
    if ground is None and g.body_ratio is not None:
        raise loc.error(("gait", "body_ratio"), g.body_ratio, "body_deg on a plane")
    if ground is not None and g.body_deg is not None:
        raise loc.error(("gait", "body_deg"), g.body_deg, "body_ratio on this ground")
    body = math.radians(g.body_deg) if g.body_deg is not None else (2.0 / 3.0) * slope
    try:
        return GaitParams(
            slope=slope,
            body_pitch=body if ground is None else 0.0,
            step=g.step,
            swing_height=g.swing_height,
            swing_period=g.swing_period,
            shift_period=g.shift_period,
            cycles=g.cycles,
            strategy=ZmpStrategy(g.strategy),
            height=g.height,
            hold_time=g.hold_time,
            side_slope=side,
            ground=ground,
            body_ratio=g.body_ratio if g.body_ratio is not None else 2.0 / 3.0,
        )
    except InputError as e:
        section = "ground" if e.field in ("slope", "side_slope") else "gait"
        fld = {"body_pitch": "body_deg", "slope": "slope_deg", "side_slope": "side_slope_deg"}
        value = g.body_deg if e.field == "body_pitch" else e.value
        expected = e.expected
        if e.field == "body_pitch":
            expected = f"a body angle in degrees between 0 and the slope ({e.expected})"
        raise loc.error((section, fld.get(e.field, e.field)), value, expected) from None


def load_quadruped_scene(path_or_text: str | Path) -> QuadrupedScene:
    """Load and validate a quadruped scene from a YAML file path or YAML text.

    Raises:
        SceneError: naming the field path and its line, e.g. ``ground.rise (line 5 of a.yaml)``.
    """
    data, loc = read_yaml(path_or_text)
    if not isinstance(data, dict):
        raise loc.error((), type(data).__name__, "a mapping with name, ground and gait")
    spec = validate_yaml(_QuadrupedSceneSpec, data, loc)
    if spec.friction is not None and not spec.friction > 0.0:
        raise loc.error(("friction",), spec.friction, "a positive friction coefficient")
    return QuadrupedScene(spec.name, spec.description, _params(spec, loc), spec.friction)


def builtin_quadruped_scene_names() -> list[str]:
    """Names of the scenes shipped in ``footfall/quadruped/scenes/*.yaml``, sorted."""
    return packaged_scene_names("footfall.quadruped")


def builtin_quadruped_scene(name: str) -> QuadrupedScene:
    """Load the built-in quadruped scene ``name`` (see :func:`builtin_quadruped_scene_names`)."""
    return load_quadruped_scene(packaged_scene_text("footfall.quadruped", name))


def resolve_quadruped_scene(name_or_path: str) -> QuadrupedScene:
    """A built-in scene by name, else a YAML file."""
    if name_or_path in builtin_quadruped_scene_names():
        return builtin_quadruped_scene(name_or_path)
    return load_quadruped_scene(Path(name_or_path))


__all__ = [
    "QuadrupedScene",
    "builtin_quadruped_scene",
    "builtin_quadruped_scene_names",
    "load_quadruped_scene",
    "resolve_quadruped_scene",
]
