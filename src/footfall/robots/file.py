"""Robot files: a humanoid described as data (YAML), its model a URDF or MJCF.

A robot file names the model and, where they cannot be derived from it, the few facts footfall
needs; everything else (mass, CoM height, nominal posture, sole, limits, reach, timing) is derived
from the model (:mod:`footfall.robots.derive`). The schema, every key optional but ``name`` and
``model``::

    name: g1
    model:                       # a file inside an installed distribution ...
      package: example-robot-data
      path: cmeel.prefix/share/example-robot-data/robots/g1_description/urdf/g1_29dof_rev_1_0.urdf
    # model: robots/my_robot.urdf   # ... or a path, relative to this file (.urdf, .xml or .mjcf)
    base: pelvis                 # the floating base link [default: the model's root link]
    torso: torso_link            # the body held upright [default: the base]
    legs:                        # per side, footfall's six joints in order: hip yaw, hip roll,
      left: [left_hip_yaw_joint, left_hip_roll_joint, left_hip_pitch_joint,   # hip pitch, knee,
             left_knee_joint, left_ankle_pitch_joint, left_ankle_roll_joint]  # ankle pitch, roll
      right: [...]               # [default: found: the chains from the base to the two lowest links]
    sole:                        # contact rectangle in the foot (ankle roll link) frame [m]
      x: [-0.05, 0.12]           # heel, toe
      y: [-0.025, 0.025]         # right, left edge
      z: -0.035                  # the sole plane
      radius: 0.005              # contact spheres at its corners
                                 # [default: from the foot's collision geometry]
    pelvis_height: 0.72          # base origin above the soles in the walking posture [m]
                                 # [default: the height with the largest joint margins]
    stance_width: 0.20           # lateral distance of the sole centres [m] [default: 0.20]
    reach: [[-0.2, 0.12], [0.3, 0.12], [0.2, 0.34], [-0.1, 0.34]]   # next footstep from a right
                                 # stance foot (eq. 5.12f) [m] [default: derived by IK]
    step_height_max: 0.12        # largest step up or down [m] [default: derived by IK]
    physics: {friction: 1.0}     # servo and contact settings (:class:`Physics`)

``footfall robot inspect`` writes a complete file, the derived values filled in.

Files are read with the safe YAML loader, bounded in size, and every bad value names its field and
line; nothing in a file runs code.
"""

from __future__ import annotations

import importlib.metadata
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field

from footfall._validate import check_fields, non_negative, positive
from footfall.errors import InputError, MissingExtraError
from footfall.models.biped import Side
from footfall.terrain.scene import StrictSpec, read_yaml, validate_yaml

#: footfall's leg joints in order from the base to the foot
LEG_JOINT_ROLES = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
#: model file endings and the format each means
MODEL_FORMATS = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf"}


@dataclass(frozen=True)
class LegJoints:
    """The six leg joints of each side, in ``LEG_JOINT_ROLES`` order (model names).

    Attributes:
        left: the left leg's joints.
        right: the right leg's joints.
    """

    left: tuple[str, ...]
    right: tuple[str, ...]

    def __post_init__(self) -> None:
        for side in Side:
            joints = self.of(side)
            if len(joints) != len(LEG_JOINT_ROLES) or not all(
                isinstance(j, str) and j for j in joints
            ):
                raise InputError(
                    f"legs.{side.value}",
                    list(joints),
                    f"{len(LEG_JOINT_ROLES)} joint names: {', '.join(LEG_JOINT_ROLES)}",
                )
        names = [*self.left, *self.right]
        if len(set(names)) != len(names):
            raise InputError("legs", names, "twelve different joints")

    def of(self, side: Side) -> tuple[str, ...]:
        """The ``side`` leg's joints."""
        return self.left if Side(side) is Side.LEFT else self.right


@dataclass(frozen=True)
class Sole:
    """The contact rectangle of a foot, in the foot frame (x forward, y left) [m].

    Attributes:
        x: (heel, toe) [m].
        y: (right edge, left edge) [m].
        z: height of the sole plane [m].
        radius: radius of the contact spheres at the corners [m].
    """

    x: tuple[float, float]
    y: tuple[float, float]
    z: float
    radius: float = 0.005

    def __post_init__(self) -> None:
        for name in ("x", "y"):
            lo, hi = (float(v) for v in getattr(self, name))
            if not hi - lo > 2.0 * self.radius:
                raise InputError(
                    f"sole.{name}", [lo, hi], "lower < upper, more than two radii apart [m]"
                )
            object.__setattr__(self, name, (lo, hi))
        object.__setattr__(self, "radius", positive("sole.radius", self.radius))

    @property
    def length(self) -> float:
        """Heel to toe [m]."""
        return self.x[1] - self.x[0]

    @property
    def width(self) -> float:
        """Right to left edge [m]."""
        return self.y[1] - self.y[0]

    @property
    def centre(self) -> tuple[float, float]:
        """Centre (x, y) of the rectangle in the foot frame [m]."""
        return (0.5 * (self.x[0] + self.x[1]), 0.5 * (self.y[0] + self.y[1]))


@dataclass(frozen=True)
class Physics:
    """Servo and contact settings of a robot built from its file (the model's own are kept for
    masses, inertias and joint limits).

    Attributes:
        servo_saturation: joint error at which a leg servo reaches its torque limit [rad]
            (``kp = effort / servo_saturation``; the servo controller's).
        servo_damping_time: ``kv / kp`` of the leg servos [s].
        armature: rotor inertia added to each leg joint [kg m^2].
        joint_damping: viscous damping of each leg joint [N m s / rad].
        timestep: physics step [s].
        friction: sliding friction between the soles and the ground.
        impratio: frictional to normal constraint impedance ratio (elliptic cone).
    """

    servo_saturation: float = 0.05
    servo_damping_time: float = 0.02
    armature: float = 0.02
    joint_damping: float = 0.5
    timestep: float = 0.002
    friction: float = 1.0
    impratio: float = 10.0

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive,
            (
                "servo_saturation",
                "servo_damping_time",
                "timestep",
                "friction",
                "impratio",
            ),
            prefix="physics.",
        )
        check_fields(self, non_negative, ("armature", "joint_damping"), prefix="physics.")


@dataclass(frozen=True)
class RobotFile:
    """A humanoid described by a robot file (see the module docstring).

    Attributes:
        name: short name (plan cache files, messages).
        model: the URDF or MJCF file (resolved: an existing path).
        base: the floating base link, None: the model's root link.
        torso: the body held upright, None: the base.
        legs: per side the six leg joints in ``LEG_JOINT_ROLES`` order, None: found.
        sole: the contact rectangle, None: from the foot's collision geometry.
        pelvis_height: base origin above the soles in the walking posture [m], None: derived.
        stance_width: lateral distance of the sole centres [m].
        reach: the reach trapezoid (4 (x, y) corners) [m], None: derived.
        step_height_max: the largest step up or down [m], None: derived.
        physics: servo and contact settings.
        source: where the file came from (messages).
        package: ``(distribution, path)`` when the model is a file of an installed distribution.
    """

    name: str
    model: Path
    base: str | None = None
    torso: str | None = None
    legs: LegJoints | None = None
    sole: Sole | None = None
    pelvis_height: float | None = None
    stance_width: float = 0.20
    reach: tuple[tuple[float, float], ...] | None = None
    step_height_max: float | None = None
    physics: Physics = field(default_factory=Physics)
    source: str = "robot"
    package: tuple[str, str] | None = None

    def __post_init__(self) -> None:
        if (
            not isinstance(self.name, str)
            or not self.name.strip()
            or len(self.name) > 64
            or not self.name.isprintable()  # one line: it titles figures and heads the file
        ):
            raise InputError(
                "name", self.name, "a short non-empty line (at most 64 printable characters)"
            )
        if Path(self.model).suffix.lower() not in MODEL_FORMATS:
            raise InputError("model", str(self.model), "a .urdf, .xml or .mjcf file")
        if self.pelvis_height is not None:
            object.__setattr__(self, "pelvis_height", positive("pelvis_height", self.pelvis_height))
        object.__setattr__(self, "stance_width", positive("stance_width", self.stance_width))
        if self.step_height_max is not None:
            object.__setattr__(
                self, "step_height_max", positive("step_height_max", self.step_height_max)
            )
        if self.reach is not None:
            from footfall.models.biped import ReachTrapezoid

            v = ReachTrapezoid(np.array(self.reach, dtype=float)).vertices  # the planner's checks
            object.__setattr__(self, "reach", tuple((float(x), float(y)) for x, y in v))

    @property
    def format(self) -> str:
        """``urdf`` or ``mjcf``."""
        return MODEL_FORMATS[Path(self.model).suffix.lower()]


# ----------------------------------------------------------------------------------- the schema
class PackageFileSpec(StrictSpec):
    """A file inside an installed distribution (a robot file's ``model``)."""

    package: str = Field(min_length=1, max_length=200)
    path: str = Field(min_length=1, max_length=1000)


class _Legs(StrictSpec):
    left: list[str] = Field(min_length=6, max_length=6)
    right: list[str] = Field(min_length=6, max_length=6)


class _Sole(StrictSpec):
    x: list[float] = Field(min_length=2, max_length=2)
    y: list[float] = Field(min_length=2, max_length=2)
    z: float
    radius: float = 0.005


class _Physics(StrictSpec):
    # the defaults are Physics' own (one place); Physics checks the values
    servo_saturation: float = Physics.servo_saturation
    servo_damping_time: float = Physics.servo_damping_time
    armature: float = Physics.armature
    joint_damping: float = Physics.joint_damping
    timestep: float = Physics.timestep
    friction: float = Physics.friction
    impratio: float = Physics.impratio


class _RobotFileSpec(StrictSpec):
    name: str = Field(min_length=1, max_length=64)
    model: str | PackageFileSpec
    base: str | None = Field(default=None, max_length=200)
    torso: str | None = Field(default=None, max_length=200)
    legs: _Legs | None = None
    sole: _Sole | None = None
    pelvis_height: float | None = None
    stance_width: float = 0.20
    reach: list[list[float]] | None = None
    step_height_max: float | None = None
    physics: _Physics | None = None


def package_file(package: str, path: str) -> Path:
    """The file ``path`` inside the installed distribution ``package``.

    Raises:
        MissingExtraError: the distribution is not installed (footfall's robots extra installs
            example-robot-data).
        InputError: it has no such file.
    """
    try:
        dist = importlib.metadata.distribution(package)
    except importlib.metadata.PackageNotFoundError:
        extra = " (pip install 'footfall[robots]')" if package == "example-robot-data" else ""
        raise MissingExtraError(f"the robot model needs the package {package!r}{extra}") from None
    found = Path(str(dist.locate_file(path)))
    if not found.is_file():
        raise InputError("model.path", path, f"a file of {package} {dist.version}")
    return found


def package_of(path: Path) -> tuple[str, str] | None:
    """``(distribution, path)`` of the installed distribution that ships the file ``path``
    (its RECORD lists it), or None: a robot file then names the model the way
    :func:`package_file` finds it on any machine, not by this machine's install path."""
    target = path.resolve()
    for dist in importlib.metadata.distributions():
        root = Path(str(dist.locate_file(""))).resolve()
        if not target.is_relative_to(root):
            continue
        rel = target.relative_to(root).as_posix()
        # the RECORD's lines are "path,hash,size": a text search, not thousands of path objects
        if f"\n{rel}," in "\n" + (dist.read_text("RECORD") or ""):
            return dist.metadata["Name"], rel
    return None


def resolve_model(
    model: str | PackageFileSpec, base: Path | None
) -> tuple[Path, tuple[str, str] | None]:
    """A robot file's ``model`` entry as a path and, for a file of an installed distribution,
    ``(distribution, path)`` (a relative path is relative to ``base``)."""
    if isinstance(model, str):
        path = Path(model)
        if not path.is_absolute() and base is not None:
            path = base / path
        if not path.is_file():
            raise InputError("model", model, "an existing URDF or MJCF file")
        return path, None
    return package_file(model.package, model.path), (model.package, model.path)


def model_entry(model: Path, package: tuple[str, str] | None, base: Path | None) -> Any:
    """The ``model`` entry a written robot file gives: ``package``/``path`` for a file of an
    installed distribution, else the path (relative to ``base`` when inside it)."""
    if package is not None:
        return {"package": package[0], "path": package[1]}
    if base is not None and model.resolve().is_relative_to(base.resolve()):
        return str(model.resolve().relative_to(base.resolve()))
    return str(model)


def inspect_input_is_file(model: Path, config: Path | None) -> bool:
    """``footfall robot inspect``'s MODEL checked: True when it is a robot file (then no
    ``--config`` beside it); else a model file of a known format that exists."""
    if model.suffix.lower() in (".yaml", ".yml"):
        if config is not None:
            raise InputError("--config", str(config), "no config with a robot file as MODEL")
        return True
    if model.suffix.lower() not in MODEL_FORMATS:
        raise InputError("MODEL", str(model), "a .urdf, .xml or .mjcf model, or a robot file")
    if not model.is_file():
        raise InputError("MODEL", str(model), "an existing file")
    return False


def robot_file_yaml(kind: str, name: str, derived: str, data: dict[str, Any]) -> str:
    """The text ``footfall robot inspect`` writes: a header saying which values were derived
    from the model, then ``data`` as YAML."""
    import yaml

    head = (
        f"# footfall {kind} of {name}, completed by `footfall robot inspect`: {derived} were\n"
        "# derived from the model (edit to override; delete a derived key to derive it again).\n"
    )
    return head + yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=100)


def parse_robot_file(text: str | Path, source: str, base: Path | None) -> RobotFile:
    """A :class:`RobotFile` from YAML text or a file path (``base``: the folder of relative model
    paths)."""
    data, loc = read_yaml(text)
    spec = validate_yaml(_RobotFileSpec, data, loc)
    model, package = resolve_model(spec.model, base)
    legs = None
    if spec.legs is not None:
        legs = LegJoints(tuple(spec.legs.left), tuple(spec.legs.right))
    sole = None
    if spec.sole is not None:
        sole = Sole(
            (spec.sole.x[0], spec.sole.x[1]),
            (spec.sole.y[0], spec.sole.y[1]),
            spec.sole.z,
            spec.sole.radius,
        )
    physics = Physics(**spec.physics.model_dump()) if spec.physics is not None else Physics()
    return RobotFile(
        name=spec.name,
        model=model,
        base=spec.base,
        torso=spec.torso,
        legs=legs,
        sole=sole,
        pelvis_height=spec.pelvis_height,
        stance_width=spec.stance_width,
        reach=None if spec.reach is None else tuple(tuple(v) for v in spec.reach),  # type: ignore[misc]
        step_height_max=spec.step_height_max,
        physics=physics,
        source=source,
        package=package,
    )


def load_robot_file(path: str | Path) -> RobotFile:
    """Read and validate a robot file (YAML); relative model paths are relative to its folder."""
    path = Path(path)
    return parse_robot_file(path, str(path), path.parent)
