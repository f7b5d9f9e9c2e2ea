"""Scenes: a robot, a terrain, a start and a goal; YAML files, built-ins and a random generator.

The YAML schema is documented in ``SCHEMA.md`` next to this file. Loading validates the file with
pydantic, then builds the frozen dataclasses (which validate the geometry); every error is a
:class:`~footfall.errors.SceneError` whose field names the path in the file and its line, e.g.
``regions[2].vertices (line 31)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

import numpy as np
import yaml
from numpy.typing import ArrayLike
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from footfall._geometry import outward_halfspaces, polygon_distance, rot2
from footfall._io import read_bounded
from footfall._typing import FloatArray
from footfall._validate import finite, finite_vector
from footfall._yaml import UniqueKeyLoader
from footfall.errors import InputError, SceneError
from footfall.models.biped import BipedParams, ReachTrapezoid, Side
from footfall.terrain.region import MAX_NAME, NAME_EXPECTED, Region, valid_name
from footfall.terrain.terrain import MAX_REGIONS, Terrain

#: tolerance [m] for the start feet and the goal to count as on a region (plane and polygon); looser
#: than Region.contains' default because hand-written YAML heights are rounded
SCENE_TOL = 1e-3
#: longest scene description [characters] (a figure's title)
MAX_DESCRIPTION = 2000


# ============================================================================= scene dataclasses
@dataclass(frozen=True, eq=False)
class Start:
    """Initial stance of the robot.

    Attributes:
        left: left foot position (3,) [m].
        right: right foot position (3,) [m].
        heading: heading of both feet theta_0 [rad].
        stance: the foot standing at t = 0 (footstep 0); the other foot moves first.
        alip_state: initial ALIP state ``[x_c, y_c, L_x, L_y]`` (4,) relative to the stance foot
            ([m, m, kg m^2/s, kg m^2/s], eq. 5.12c); zeros (CoM over the stance foot, at rest)
            by default.
    """

    left: FloatArray
    right: FloatArray
    heading: float
    stance: Side
    alip_state: FloatArray = field(default_factory=lambda: np.zeros(4))

    def __post_init__(self) -> None:
        for name in ("left", "right"):
            v = _wrap(f"start.{name}", lambda n=name: finite_vector(n, getattr(self, n), 3))
            v.setflags(write=False)
            object.__setattr__(self, name, v)
        object.__setattr__(
            self, "heading", _wrap("start.heading", lambda: finite("h", self.heading))
        )
        try:
            object.__setattr__(self, "stance", Side(self.stance))
        except ValueError:
            raise SceneError("start.stance", self.stance, "'left' or 'right'") from None
        x0 = _wrap("start.alip_state", lambda: finite_vector("x", self.alip_state, 4))
        x0.setflags(write=False)
        object.__setattr__(self, "alip_state", x0)

    def foot(self, side: Side) -> FloatArray:
        """Position (3,) [m] of the ``side`` foot."""
        return self.left if Side(side) is Side.LEFT else self.right

    @property
    def stance_foot(self) -> FloatArray:
        """Position (3,) [m] of the standing foot (footstep 0)."""
        return self.foot(self.stance)


@dataclass(frozen=True, eq=False)
class Goal:
    """Where the walk ends.

    Attributes:
        position: midpoint between the two final feet (3,) [m], z on the terrain.
        heading: final heading [rad].
    """

    position: FloatArray
    heading: float

    def __post_init__(self) -> None:
        p = _wrap("goal.position", lambda: finite_vector("p", self.position, 3))
        p.setflags(write=False)
        object.__setattr__(self, "position", p)
        object.__setattr__(
            self, "heading", _wrap("goal.heading", lambda: finite("h", self.heading))
        )


@dataclass(frozen=True, eq=False)
class Scene:
    """A footstep-planning problem instance.

    Attributes:
        name: short identifier.
        description: one-line human description.
        robot: the biped.
        terrain: the walkable regions.
        start: initial feet, heading, stance foot and ALIP state.
        goal: final feet midpoint and heading.

    Construction checks that both start feet and the goal lie on some region (within
    ``SCENE_TOL``), naming the offending foot.
    """

    name: str
    description: str
    robot: BipedParams
    terrain: Terrain
    start: Start
    goal: Goal

    def __post_init__(self) -> None:
        if not valid_name(self.name):
            raise SceneError("name", self.name, NAME_EXPECTED)
        if not isinstance(self.description, str) or len(self.description) > MAX_DESCRIPTION:
            raise SceneError(
                "description", self.description, f"at most {MAX_DESCRIPTION} characters"
            )
        for attr, typ in (
            ("robot", BipedParams),
            ("terrain", Terrain),
            ("start", Start),
            ("goal", Goal),
        ):
            if not isinstance(getattr(self, attr), typ):
                raise SceneError(attr, getattr(self, attr), f"a {typ.__name__}")
        for fld, p in (
            ("start.left", self.start.left),
            ("start.right", self.start.right),
            ("goal.position", self.goal.position),
        ):
            if not self.terrain.locate(p, SCENE_TOL):
                name, gap, dz = self.terrain.nearest(p)
                raise SceneError(
                    fld,
                    [round(float(c), 6) for c in p],
                    f"a point on some region within {SCENE_TOL} m (nearest is {name!r}: "
                    f"{gap:.3f} m outside it in plan view, {dz:+.3f} m off its plane)",
                )

    def start_regions(self) -> dict[Side, str]:
        """Name of the (first) region under each start foot."""
        return {s: self.terrain.locate(self.start.foot(s), SCENE_TOL)[0] for s in Side}

    def goal_region(self) -> str:
        """Name of the (first) region containing the goal."""
        return self.terrain.locate(self.goal.position, SCENE_TOL)[0]


def _wrap(fld: str, fn: Any) -> Any:
    """Run ``fn`` and re-raise an InputError as a SceneError naming ``fld``."""
    try:
        return fn()
    except InputError as e:
        raise SceneError(fld, e.value, e.expected) from None


# ============================================================================= YAML schema
Vec2 = Annotated[list[float], Field(min_length=2, max_length=2)]
Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Vec4 = Annotated[list[float], Field(min_length=4, max_length=4)]


class StrictSpec(BaseModel):
    """Base of YAML schemas: no "0.5" strings or booleans for numbers, no NaN/inf, and unknown
    keys are refused (they are usually typos)."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)


ModelT = TypeVar("ModelT", bound=StrictSpec)


class _RobotSpec(StrictSpec):
    mass: float | None = None
    com_height: float | None = None
    t_ss: float | None = None
    t_ds: float | None = None
    n_nodes: int | None = None
    u_max: float | None = None
    reach: Annotated[list[Vec2], Field(min_length=4, max_length=4)] | None = None
    theta_max: float | None = None
    theta_max_deg: float | None = None
    stance_width: float | None = None
    step_height_max: float | None = None
    foot_length: float | None = None
    foot_width: float | None = None
    g: float | None = None


class _StartSpec(StrictSpec):
    left: Vec3
    right: Vec3
    heading: float | None = None
    heading_deg: float | None = None
    stance: Literal["left", "right"]
    alip_state: Vec4 | None = None


class _GoalSpec(StrictSpec):
    position: Vec3
    heading: float | None = None
    heading_deg: float | None = None


Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME)]


class _RegionSpec(StrictSpec):
    name: Name
    vertices: Annotated[list[list[float]], Field(min_length=3)]
    normal: Vec3 | None = None
    offset: float | None = None
    height: float | None = None


class _SceneSpec(StrictSpec):
    name: Name
    description: Annotated[str, Field(max_length=MAX_DESCRIPTION)] = ""
    robot: _RobotSpec = Field(default_factory=_RobotSpec)
    start: _StartSpec
    goal: _GoalSpec
    regions: Annotated[list[_RegionSpec], Field(min_length=1)]


# ============================================================================= YAML loading
Path_ = tuple[str | int, ...]


class _Missing:
    def __repr__(self) -> str:
        return "nothing (the field is missing)"


class YamlLocator:
    """Maps a path in the document (keys and list indices) to a 1-based line number."""

    def __init__(self, root: yaml.Node | None, source: str | None) -> None:
        self.root = root
        self.source = source

    def line(self, path: Path_) -> int | None:
        node = self.root
        if node is None:
            return None
        line = node.start_mark.line + 1
        for key in path:
            nxt: yaml.Node | None = None
            if isinstance(node, yaml.MappingNode) and isinstance(key, str):
                for k, v in node.value:
                    if isinstance(k, yaml.ScalarNode) and k.value == key:
                        # The key's line, not the value's: a block list starts on the next line.
                        line, nxt = k.start_mark.line + 1, v
                        break
            elif isinstance(node, yaml.SequenceNode) and isinstance(key, int):
                if 0 <= key < len(node.value):
                    nxt = node.value[key]
                    line = nxt.start_mark.line + 1
            if nxt is None:
                # The path goes deeper than the document (a missing field): report its parent.
                break
            node = nxt
        return line

    def field(self, path: Path_) -> str:
        text = ""
        for key in path:
            text += f"[{key}]" if isinstance(key, int) else (f".{key}" if text else key)
        text = text or "<document>"
        line = self.line(path)
        if line is None:
            return text
        where = f"line {line}" + (f" of {self.source}" if self.source else "")
        return f"{text} ({where})"

    def error(self, path: Path_, value: object, expected: str) -> SceneError:
        return SceneError(self.field(path), value, expected)


def _split_field(fld: str) -> Path_:
    """``"start.left"`` -> ``("start", "left")``; ``"reach"`` -> ``("reach",)``."""
    return tuple(fld.split("."))


def _angle(loc: YamlLocator, path: Path_, rad: float | None, deg: float | None, name: str) -> float:
    if rad is not None and deg is not None:
        raise loc.error(
            (*path, f"{name}_deg"), deg, f"only one of {name} [rad] or {name}_deg [deg]"
        )
    if rad is None and deg is None:
        raise loc.error(path, _Missing(), f"{name} [rad] or {name}_deg [deg]")
    return float(rad) if rad is not None else math.radians(float(deg))  # type: ignore[arg-type]


def _build_robot(spec: _RobotSpec, loc: YamlLocator) -> BipedParams:
    kw: dict[str, Any] = {}
    for name in spec.model_fields_set:
        value = getattr(spec, name)
        if value is not None and name not in ("reach", "theta_max", "theta_max_deg"):
            kw[name] = value
    if spec.theta_max is not None or spec.theta_max_deg is not None:
        kw["theta_max"] = _angle(loc, ("robot",), spec.theta_max, spec.theta_max_deg, "theta_max")
    if spec.reach is not None:
        try:
            kw["reach"] = ReachTrapezoid(np.array(spec.reach, dtype=float))
        except InputError as e:
            raise loc.error(("robot", "reach"), e.value, e.expected) from None
    try:
        return BipedParams(**kw)
    except InputError as e:
        path: Path_ = (
            "robot",
            "theta_max_deg"
            if e.field == "theta_max" and spec.theta_max_deg is not None
            else e.field,
        )
        raise loc.error(path, e.value, e.expected) from None


def _build_region(i: int, spec: _RegionSpec, loc: YamlLocator) -> Region:
    here: Path_ = ("regions", i)
    dims = 2 if (spec.normal is not None or spec.height is not None) else 3
    form = {2: "[x, y] (with normal/offset or height)", 3: "[x, y, z] (no normal or height)"}[dims]
    for j, v in enumerate(spec.vertices):
        if len(v) != dims:
            raise loc.error((*here, "vertices", j), v, f"a vertex {form}")
    if spec.normal is not None and spec.height is not None:
        raise loc.error(
            (*here, "height"), spec.height, "either normal + offset or height, not both"
        )
    if spec.normal is not None and spec.offset is None:
        raise loc.error(
            (*here, "offset"), _Missing(), "an offset d [m] with the normal (n.p + d = 0)"
        )
    if spec.offset is not None and spec.normal is None:
        raise loc.error((*here, "normal"), _Missing(), "a normal [a, b, c] with the offset")
    try:
        if spec.normal is not None:
            return Region.from_plane(
                spec.name, spec.normal, float(spec.offset or 0.0), spec.vertices
            )
        if spec.height is not None:
            return Region.from_height(spec.name, spec.height, spec.vertices)
        return Region.from_3d(spec.name, spec.vertices)
    except SceneError as e:
        attr = e.field.rsplit(" ", 1)[-1]
        path = (*here, attr) if attr in spec.model_fields_set else here
        raise loc.error(path, e.value, f"{e.expected} [region {spec.name!r}]") from None


def _build_scene(spec: _SceneSpec, loc: YamlLocator) -> Scene:
    robot = _build_robot(spec.robot, loc)
    names: dict[str, int] = {}
    for i, r in enumerate(spec.regions):
        if r.name in names:
            raise loc.error(
                ("regions", i, "name"), r.name, f"a unique name (regions[{names[r.name]}] has it)"
            )
        names[r.name] = i
    regions = tuple(_build_region(i, r, loc) for i, r in enumerate(spec.regions))
    st, gl = spec.start, spec.goal
    try:
        start = Start(
            left=np.array(st.left),
            right=np.array(st.right),
            heading=_angle(loc, ("start", "heading"), st.heading, st.heading_deg, "heading"),
            stance=Side(st.stance),
            alip_state=np.zeros(4) if st.alip_state is None else np.array(st.alip_state),
        )
        goal = Goal(
            position=np.array(gl.position),
            heading=_angle(loc, ("goal", "heading"), gl.heading, gl.heading_deg, "heading"),
        )
        return Scene(spec.name, spec.description, robot, Terrain(regions), start, goal)
    except SceneError as e:
        if "(line" in e.field:  # already located
            raise
        raise loc.error(_split_field(e.field), e.value, e.expected) from None


def _pydantic_error(err: ValidationError, loc: YamlLocator) -> SceneError:
    errors = err.errors()
    first = errors[0]
    path: Path_ = tuple(k for k in first["loc"] if isinstance(k, str | int))
    more = f" (and {len(errors) - 1} more problem(s))" if len(errors) > 1 else ""
    if first["type"] == "missing":
        return loc.error(path, _Missing(), f"this required field{more}")
    if first["type"] == "extra_forbidden":
        return loc.error(path, first["input"], f"no such field (unknown key){more}")
    return loc.error(path, first.get("input"), f"{first['msg'].lower()}{more}")


#: YAML's safe loader (no Python objects from tags, libyaml's C parser when installed) that
#: refuses a repeated key
_SAFE_LOADER: Any = UniqueKeyLoader
#: largest scene file or text accepted [bytes]; the largest built-in scene is a few kB
MAX_SCENE_BYTES = 4_000_000
#: most YAML nodes a scene may expand to, aliases counted at every use (a ~1 kB "billion laughs"
#: alias bomb expands to ~10^9 nodes, which validation or an error message would materialise)
MAX_SCENE_NODES = 1_000_000


def _read_scene_file(path: Path) -> str:
    """The text of a scene file: a regular file (not a device or a pipe) of bounded size."""
    return read_bounded(path, "scene file", MAX_SCENE_BYTES, "YAML file", SceneError)


def _check_expanded_size(root: yaml.Node | None, source: str | None) -> None:
    """Refuse a YAML document whose aliases expand it beyond :data:`MAX_SCENE_NODES` nodes.

    Counts the expanded size on the composed node graph, where an alias is one shared node: each
    node's size is computed once (memoised), so a bomb is measured without being expanded."""
    sizes: dict[int, int] = {}

    def size(node: yaml.Node, depth: int) -> int:
        if depth > 100:
            raise SceneError(
                "yaml" + (f" ({source})" if source else ""), "nesting", "at most 100 levels"
            )
        if id(node) in sizes:
            return sizes[id(node)]
        total = 1
        if isinstance(node, yaml.SequenceNode):
            total += sum(size(child, depth + 1) for child in node.value)
        elif isinstance(node, yaml.MappingNode):
            total += sum(size(k, depth + 1) + size(v, depth + 1) for k, v in node.value)
        sizes[id(node)] = total
        return total

    if root is not None:
        n = size(root, 0)
        if n > MAX_SCENE_NODES:
            raise SceneError(
                "yaml" + (f" ({source})" if source else ""),
                f"{n} nodes once aliases are expanded",
                f"at most {MAX_SCENE_NODES} (an alias bomb?)",
            )


def read_yaml(path_or_text: str | Path) -> tuple[Any, YamlLocator]:
    """Parse a YAML file path or YAML text safely (no Python objects, bounded size and alias
    expansion): the data and a locator naming fields with their lines.

    A ``str`` is a path when it has no newline and names an existing file or ends in ``.yaml`` /
    ``.yml``; otherwise it is YAML text.

    Raises:
        SceneError: for an unreadable or oversized file, or invalid YAML (with its line).
    """
    if not isinstance(path_or_text, str | Path):
        raise SceneError(
            "path_or_text", type(path_or_text).__name__, "a YAML file path (str or Path) or text"
        )
    source: str | None = None
    if isinstance(path_or_text, Path) or (
        "\n" not in path_or_text
        and (path_or_text.endswith((".yaml", ".yml")) or Path(path_or_text).is_file())
    ):
        p = Path(path_or_text)
        text = _read_scene_file(p)
        source = p.name
    else:
        text = path_or_text
    if len(text) > MAX_SCENE_BYTES:
        raise SceneError("scene", f"{len(text)} characters", f"at most {MAX_SCENE_BYTES}")
    try:
        root = yaml.compose(text, Loader=_SAFE_LOADER)
        _check_expanded_size(root, source)
        # constructed from the checked node graph: the text is parsed once
        data = None if root is None else _SAFE_LOADER("").construct_document(root)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" (line {mark.line + 1}" + (f" of {source})" if source else ")") if mark else ""
        problem = getattr(e, "problem", None) or str(e)
        lines = text.splitlines()
        shown = lines[mark.line] if mark and mark.line < len(lines) else None  # past the end: EOF
        raise SceneError(f"yaml{where}", shown, f"valid YAML ({problem})") from None
    return data, YamlLocator(root, source)


def validate_yaml(spec: type[ModelT], data: Any, loc: YamlLocator) -> ModelT:
    """``data`` validated against the strict schema ``spec`` (errors name the field and line)."""
    try:
        return spec.model_validate(data)
    except ValidationError as e:
        raise _pydantic_error(e, loc) from None


def load_scene(path_or_text: str | Path) -> Scene:
    """Load and validate a scene from a YAML file path or YAML text.

    A ``str`` is a path when it has no newline and names an existing file or ends in ``.yaml`` /
    ``.yml``; otherwise it is YAML text.

    Raises:
        SceneError: naming the field path and the line, e.g. ``start.left (line 12 of a.yaml)``.
    """
    data, loc = read_yaml(path_or_text)
    if not isinstance(data, dict):
        raise loc.error((), type(data).__name__, "a mapping with name, start, goal and regions")
    regions = data.get("regions")
    # refused before any work per region
    if isinstance(regions, list) and len(regions) > MAX_REGIONS:
        raise loc.error(("regions",), f"{len(regions)} regions", f"1..{MAX_REGIONS} regions")
    return _build_scene(validate_yaml(_SceneSpec, data, loc), loc)


# ============================================================================= YAML writing
def _floats(a: ArrayLike) -> Any:
    """Nested lists of Python floats (YAML writes their repr, so they round-trip exactly)."""
    return (np.asarray(a, dtype=float) + 0.0).tolist()  # + 0.0 turns -0.0 into 0.0


def robot_to_dict(r: BipedParams) -> dict[str, Any]:
    """The robot as plain data following the scene YAML schema's ``robot:`` (every field)."""
    return {
        "mass": r.mass,
        "com_height": r.com_height,
        "t_ss": r.t_ss,
        "t_ds": r.t_ds,
        "n_nodes": r.n_nodes,
        "u_max": r.u_max,
        "reach": _floats(r.reach.vertices),
        "theta_max": r.theta_max,
        "stance_width": r.stance_width,
        "step_height_max": r.step_height_max,
        "foot_length": r.foot_length,
        "foot_width": r.foot_width,
        "g": r.g,
    }


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The scene as plain data following the YAML schema (every robot field written out)."""
    regions: list[dict[str, Any]] = []
    for reg in scene.terrain:
        entry: dict[str, Any] = {"name": reg.name}
        if reg.is_flat:
            entry["height"] = -reg.offset + 0.0  # + 0.0 turns -0.0 into 0.0
        else:
            entry["normal"] = _floats(reg.normal)
            entry["offset"] = reg.offset
        entry["vertices"] = _floats(reg.vertices)
        regions.append(entry)
    return {
        "name": scene.name,
        "description": scene.description,
        "robot": robot_to_dict(scene.robot),
        "start": {
            "left": _floats(scene.start.left),
            "right": _floats(scene.start.right),
            "heading": scene.start.heading,
            "stance": scene.start.stance.value,
            "alip_state": _floats(scene.start.alip_state),
        },
        "goal": {"position": _floats(scene.goal.position), "heading": scene.goal.heading},
        "regions": regions,
    }


def scene_to_yaml(scene: Scene) -> str:
    """The scene as YAML text that :func:`load_scene` reads back to an equal scene."""
    return yaml.safe_dump(scene_to_dict(scene), sort_keys=False, default_flow_style=None, width=100)


# ============================================================================= built-in scenes
def packaged_scene_names(package: str) -> list[str]:
    """Names of the YAML files shipped in ``<package>/scenes/``, sorted."""
    folder = resources.files(package).joinpath("scenes")
    return sorted(p.name[: -len(".yaml")] for p in folder.iterdir() if p.name.endswith(".yaml"))


def packaged_scene_text(package: str, name: str) -> str:
    """The text of ``<package>/scenes/<name>.yaml`` (an error listing the names otherwise)."""
    names = packaged_scene_names(package)
    if name not in names:
        raise SceneError("scene", name, f"one of {', '.join(names)}")
    return resources.files(package).joinpath("scenes", f"{name}.yaml").read_text()


def builtin_scene_names() -> list[str]:
    """Names of the scenes shipped in ``footfall/terrain/scenes/*.yaml``, sorted."""
    return packaged_scene_names("footfall.terrain")


def builtin_scene(name: str) -> Scene:
    """Load the built-in scene ``name`` (see :func:`builtin_scene_names`)."""
    text = packaged_scene_text("footfall.terrain", name)
    try:
        return load_scene(text)
    except SceneError as e:  # pragma: no cover - the shipped files are tested
        raise SceneError(f"{name}.yaml: {e.field}", e.value, e.expected) from None


# ============================================================================= random stones
def _rect(centre: FloatArray, length: float, width: float, yaw: float) -> FloatArray:
    """CCW rectangle (4, 2) [m] of size length x width centred at ``centre``, rotated by ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float) * [length / 2, width / 2]
    return centre + local @ np.array([[c, s], [-s, c]])


def _sample_reach(
    rng: np.random.Generator, reach: ReachTrapezoid, stance: Side, forward_min: float, margin: float
) -> FloatArray:
    """Uniform sample of the reach set (heading frame) at least ``margin`` inside its edges."""
    verts = reach.for_stance(stance)
    a, b = outward_halfspaces(verts)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    for _ in range(10_000):
        q = rng.uniform(lo, hi)
        if q[0] >= forward_min and np.all(a @ q - b <= -margin):
            return q
    raise InputError("robot.reach", verts.tolist(), f"room for steps >= {forward_min} m forward")


def _check_stones(
    seed: object, n_regions: object, robot: BipedParams | None, max_turn: float, max_rise: float
) -> BipedParams:
    """Checked arguments of :func:`random_stepping_stones`; the robot (default ``BipedParams()``)."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise InputError("seed", seed, "an integer")
    if isinstance(n_regions, bool) or not isinstance(n_regions, int | np.integer) or n_regions < 2:
        raise InputError("n_regions", n_regions, "an integer >= 2 (start pad + goal pad + stones)")
    robot = BipedParams() if robot is None else robot
    if not 0.0 <= max_turn <= robot.theta_max:
        raise InputError(
            "max_turn", max_turn, f"an angle in [0, theta_max = {robot.theta_max:.3f}]"
        )
    if not 0.0 <= max_rise <= robot.step_height_max:
        raise InputError("max_rise", max_rise, f"a height in [0, {robot.step_height_max}] m")
    return robot


def _place_region(
    rng: np.random.Generator,
    robot: BipedParams,
    regions: list[Region],
    point: FloatArray,
    side: Side,
    psi: float,
    last: bool,
    stone_length: tuple[float, float],
    stone_width: tuple[float, float],
    max_turn: float,
    forward_min: float,
    margin: float,
    min_gap: float,
) -> tuple[FloatArray, float, FloatArray, FloatArray] | None:
    """The next region of :func:`random_stepping_stones` after the stone reached at ``point``
    with heading ``psi``: a step drawn in the reach trapezoid of ``side`` (eq. 5.12f), a stone
    (or the goal pad when ``last``) around it, resampled until ``min_gap`` from ``regions``.

    Returns:
        ``(reached centre (2,), heading, polygon, goal pad centre (2,))`` or None after 2000 tries.
    """
    for _ in range(2_000):
        q = _sample_reach(rng, robot.reach, side, forward_min, margin)
        new_psi = psi + float(rng.uniform(-max_turn, max_turn))
        centre = point + rot2(psi) @ q  # reach is in the stance foot's frame (eq. 5.12f)
        pad_centre = centre
        if last:
            # Goal pad: big enough for both feet, the reached point 0.2 m behind its centre.
            pad_centre = centre + rot2(new_psi) @ np.array([0.2, 0.0])
            poly = _rect(pad_centre, 0.6, 0.7, new_psi)
        else:
            length = float(rng.uniform(*stone_length))
            width = float(rng.uniform(*stone_width))
            poly = _rect(centre, length, width, new_psi)
        if all(polygon_distance(poly, r.vertices) >= min_gap for r in regions):
            return centre, new_psi, poly, pad_centre
    return None


def random_stepping_stones(
    seed: int,
    n_regions: int = 8,
    *,
    robot: BipedParams | None = None,
    stone_length: tuple[float, float] = (0.25, 0.35),
    stone_width: tuple[float, float] = (0.20, 0.28),
    max_turn: float = math.radians(10.0),
    max_rise: float = 0.10,
    min_gap: float = 0.03,
    forward_min: float = 0.10,
    margin: float = 0.02,
    pad_ahead: float = 0.05,
) -> Scene:
    """Seeded random stepping-stone scene, reachable by construction (for benchmarks).

    A start pad holds both feet; then ``n_regions - 2`` rectangular stones and a goal pad follow
    as a chain. Stone ``k+1``'s centre is the centre of stone ``k`` plus ``Rot(psi_k) q`` with ``q``
    drawn inside the reach trapezoid of the alternating stance side (eq. 5.12f), at least
    ``margin`` from its edges; the stone heading ``psi`` changes by at most ``max_turn`` and its
    height by at most ``max_rise`` per stone. So stepping from centre to centre is a feasible
    footstep sequence. Stones are kept ``min_gap`` from all earlier regions (else resampled).

    Args:
        seed: random seed; equal arguments give an identical scene.
        n_regions: total number of regions including both pads, >= 2.
        robot: robot parameters (defaults to ``BipedParams()``).
        stone_length: range of stone sizes along the walking direction [m].
        stone_width: range of stone sizes across it [m].
        max_turn: heading change bound per stone [rad], <= robot.theta_max.
        max_rise: height change bound per stone [m], <= robot.step_height_max.
        min_gap: smallest distance between non-overlapping regions [m].
        forward_min: smallest forward component of a step [m] (keeps the chain moving on).
        margin: distance of the sampled step from the trapezoid edges [m].
        pad_ahead: how far the start pad reaches ahead of the start feet [m]. The default
            0.05 m keeps the first stone within one step for the planner's benchmarks, but
            leaves the front of a 0.2 m sole over the edge: a walker standing on its soles
            needs at least half its sole length (:func:`footfall.sim.biped.options.
            check_start_soles`).
    """
    robot = _check_stones(seed, n_regions, robot, max_turn, max_rise)
    if not (math.isfinite(pad_ahead) and 0.0 < pad_ahead <= 0.5):
        raise InputError("pad_ahead", pad_ahead, "a distance in (0, 0.5] m")
    rng = np.random.default_rng(int(seed))
    half_w = robot.stance_width / 2
    left, right = np.array([0.0, half_w, 0.0]), np.array([0.0, -half_w, 0.0])
    # The pad ends just ahead of the feet (pad_ahead) so that the first stone can be within one
    # step; its back edge stays at x = -0.45 (written so that the default's numbers are exact)
    grow = pad_ahead - 0.05
    pad = _rect(np.array([-0.2 + grow / 2, 0.0]), 0.5 + grow, 0.7, 0.0)
    regions = [Region.from_height("start", 0.0, pad)]
    point, side, psi, z = right[:2].copy(), Side.RIGHT, 0.0, 0.0
    goal: Goal | None = None
    for k in range(int(n_regions) - 1):
        last = k == int(n_regions) - 2
        placed = _place_region(
            rng, robot, regions, point, side, psi, last, stone_length, stone_width,
            max_turn, forward_min, margin, min_gap,
        )  # fmt: skip
        if placed is None:
            raise InputError(
                "n_regions",
                n_regions,
                f"fewer regions (no room for region {k + 1} after 2000 tries)",
            )
        centre, new_psi, poly, pad_centre = placed
        z = z + float(rng.uniform(-max_rise, max_rise))
        if last:
            regions.append(Region.from_height("goal", z, poly))
            goal = Goal(np.array([pad_centre[0], pad_centre[1], z]), new_psi)
        else:
            regions.append(Region.from_height(f"stone{k + 1}", z, poly))
        point, side, psi = centre, side.other, new_psi
    assert goal is not None
    return Scene(
        name=f"random_stones_s{seed}_n{n_regions}",
        description=f"Random stepping stones (seed {seed}, {n_regions} regions), reachable",
        robot=robot,
        terrain=Terrain(tuple(regions)),
        start=Start(left=left, right=right, heading=0.0, stance=Side.RIGHT),
        goal=goal,
    )
