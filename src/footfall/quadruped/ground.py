"""The ground under the quadruped, beyond document 001's single slope.

Document 001 walks one plane rising along the walking direction (``beta_S``). Its own open
problems include continuously varying slopes; this module describes three grounds the gait
sequencer (:mod:`footfall.quadruped.gait`) plans on, all walked along +x:

- :class:`PlaneGround`: the document's slope, optionally also tilted sideways (a side slope);
- :class:`VaryingSlope`: an inclination that varies continuously (piecewise linearly) along x;
- :class:`Stairs`: a flat floor, a flight of steps and a top landing.

Every ground is described by its **foot-centre surface**: the height of the centre of a resting
spherical foot above the horizontal position (x, y). The world origin lies on it (under the
start), as in document 001's planner; the physical ground is one foot radius below it along its
normal (:mod:`footfall.sim.quadruped.mjcf` builds it that way).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import check_fields, finite, positive
from footfall.errors import InputError

#: steepest inclination a ground may have anywhere (as for the document's slope)
MAX_INCLINATION = math.radians(60.0)
#: most steps of a flight of stairs (each is a MuJoCo box)
MAX_STEPS = 1000
#: Newton iterations for a step of a given chord length on a varying slope
_CHORD_ITERATIONS = 30


def _plane_fit(points: FloatArray) -> tuple[float, float, float]:
    """Least-squares plane ``z = a + b x + c y`` through ``points`` (N >= 3, shape (N, 3))."""
    a = np.column_stack([np.ones(points.shape[0]), points[:, 0], points[:, 1]])
    coef, *_ = np.linalg.lstsq(a, points[:, 2], rcond=None)
    return float(coef[0]), float(coef[1]), float(coef[2])


@dataclass(frozen=True)
class PlaneGround:
    """A plane through the origin rising by ``tan(slope)`` per metre along +x and by
    ``tan(side_slope)`` per metre along +y (document 001's slope when ``side_slope`` is 0).

    Attributes:
        slope: inclination along the walking direction beta_S [rad] (negative: downhill).
        side_slope: inclination across it [rad] (positive: the left side is higher).
    """

    slope: float
    side_slope: float = 0.0

    def __post_init__(self) -> None:
        for name in ("slope", "side_slope"):
            v = finite(name, getattr(self, name))
            if abs(v) > MAX_INCLINATION:
                raise InputError(name, v, f"within +-{MAX_INCLINATION:.3f} rad (60 deg)")
            object.__setattr__(self, name, v)

    def centre_height(self, x: float, y: float) -> float:
        """Height of a resting foot's centre above (x, y) [m]."""
        return x * math.tan(self.slope) + y * math.tan(self.side_slope)

    def normal(self, x: float, y: float) -> FloatArray:
        """Unit normal of the ground at (x, y), shape (3,)."""
        if self.side_slope == 0.0:  # the document's slope: exact sines
            return np.array([-math.sin(self.slope), 0.0, math.cos(self.slope)])
        n = np.array([-math.tan(self.slope), -math.tan(self.side_slope), 1.0])
        return n / np.linalg.norm(n)

    def inclination(self, x: float) -> float:
        """Inclination along +x at x [rad]."""
        return self.slope

    def local_plane(self, points: FloatArray) -> tuple[float, float, float]:
        """The plane ``z = a + b x + c y`` the body keeps its height above: the ground itself."""
        return 0.0, math.tan(self.slope), math.tan(self.side_slope)

    def advance(self, foot: FloatArray, step: float, radius: float) -> FloatArray:
        """Foot centre one ``step`` [m] further along the slope (negative: back), shape (3,)."""
        u = np.array([math.cos(self.slope), 0.0, math.sin(self.slope)])
        return np.asarray(foot + u * step, dtype=float)

    def drop(self, point: FloatArray, direction: FloatArray) -> FloatArray:
        """Where the ray from ``point`` along ``direction`` meets the foot-centre surface."""
        n = self.normal(0.0, 0.0)
        s = -float(n @ point) / float(n @ direction)
        return np.asarray(point + s * direction, dtype=float)

    def clearance(self, centres: FloatArray, radius: float) -> FloatArray:
        """Height of foot centres (N, 3) above the foot-centre surface [m], shape (N,)."""
        return np.asarray(
            centres[:, 2]
            - centres[:, 0] * math.tan(self.slope)
            - centres[:, 1] * math.tan(self.side_slope)
        )


@dataclass(frozen=True)
class VaryingSlope:
    """A ground whose inclination along +x varies continuously: linear between knots, constant
    before the first and after the last. Uniform across y.

    The foot-centre surface is ``z(x) = integral_0^x tan(beta(s)) ds`` (closed form per segment),
    so it passes through the origin; the ground is its offset by one foot radius along the normal.

    Attributes:
        knots_x: increasing knot positions [m], at least two.
        knots_slope: inclination beta at each knot [rad].
    """

    knots_x: tuple[float, ...]
    knots_slope: tuple[float, ...]

    def __post_init__(self) -> None:
        xs = tuple(float(finite(f"knots_x[{i}]", v)) for i, v in enumerate(self.knots_x))
        bs = tuple(float(finite(f"knots_slope[{i}]", v)) for i, v in enumerate(self.knots_slope))
        if len(xs) < 2:
            raise InputError("knots_x", list(xs), "at least two knots")
        if len(bs) != len(xs):
            raise InputError("knots_slope", list(bs), f"{len(xs)} slopes, one per knot")
        for i in range(1, len(xs)):
            if not xs[i] > xs[i - 1]:
                raise InputError(f"knots_x[{i}]", xs[i], f"greater than knots_x[{i - 1}]")
        for i, b in enumerate(bs):
            if abs(b) > MAX_INCLINATION:
                raise InputError(f"knots_slope[{i}]", b, "within +-60 deg")
        object.__setattr__(self, "knots_x", xs)
        object.__setattr__(self, "knots_slope", bs)

    def inclination(self, x: float) -> float:
        """Inclination beta(x) along +x [rad]."""
        return float(np.interp(x, self.knots_x, self.knots_slope))

    def _integral(self, x0: float, x1: float) -> float:
        """Integral of tan(beta) from x0 to x1 (x0 <= x1) within one linear piece."""
        if x1 <= x0:
            return 0.0
        b0, b1 = self.inclination(x0), self.inclination(x1)
        if abs(b1 - b0) < 1e-12:
            return (x1 - x0) * math.tan(b0)
        k = (b1 - b0) / (x1 - x0)
        return (math.log(math.cos(b0)) - math.log(math.cos(b1))) / k

    def centre_height(self, x: float, y: float = 0.0) -> float:
        """Height of a resting foot's centre above x [m] (independent of y)."""
        lo, hi = (0.0, x) if x >= 0.0 else (x, 0.0)
        cuts = [lo, *(k for k in self.knots_x if lo < k < hi), hi]
        total = sum(self._integral(a, b) for a, b in itertools.pairwise(cuts))
        return total if x >= 0.0 else -total

    def normal(self, x: float, y: float = 0.0) -> FloatArray:
        """Unit normal at x, shape (3,)."""
        b = self.inclination(x)
        return np.array([-math.sin(b), 0.0, math.cos(b)])

    def local_plane(self, points: FloatArray) -> tuple[float, float, float]:
        """Least-squares plane through ``points`` (the feet): the local plane the body follows."""
        return _plane_fit(points)

    def advance(self, foot: FloatArray, step: float, radius: float) -> FloatArray:
        """Foot centre whose chord from ``foot`` on the surface has length ``step`` (signed)."""
        x0, y0 = float(foot[0]), float(foot[1])
        z0 = self.centre_height(x0)
        x = x0 + step * math.cos(self.inclination(x0))
        for _ in range(_CHORD_ITERATIONS):  # Newton on |chord|^2 = step^2 along x
            dz = self.centre_height(x) - z0
            dx = x - x0
            f = dx * dx + dz * dz - step * step
            df = 2.0 * dx + 2.0 * dz * math.tan(self.inclination(x))
            if abs(f) < 1e-18 or df == 0.0:
                break
            x -= f / df
        return np.array([x, y0, self.centre_height(x)])

    def drop(self, point: FloatArray, direction: FloatArray) -> FloatArray:
        """The foot-centre surface point straight below ``point`` (legs vertical)."""
        return np.array([point[0], point[1], self.centre_height(float(point[0]))])

    def clearance(self, centres: FloatArray, radius: float) -> FloatArray:
        """Height of foot centres (N, 3) above the foot-centre surface [m], shape (N,)."""
        return np.array([c[2] - self.centre_height(float(c[0])) for c in centres])


@dataclass(frozen=True)
class Stairs:
    """A flat floor, ``steps`` steps of ``rise`` every ``run`` metres from ``start_x``, and a top
    landing (the last tread) ``landing`` metres long. Uniform across y.

    Feet land on treads only: a foothold is moved (the least) out of the band around each step
    edge where the foot would touch the riser or the nosing (:meth:`advance`).

    Attributes:
        rise: riser height [m].
        run: tread depth [m].
        steps: number of steps.
        start_x: x of the first riser [m] (> 0: the robot starts on the floor).
        landing: length of the top landing beyond the last riser [m].
        edge_margin: clearance of a foothold from a riser face and from a nosing [m].
    """

    rise: float = 0.1
    run: float = 0.4
    steps: int = 6
    start_x: float = 0.8
    landing: float = 3.0
    edge_margin: float = 0.04

    def __post_init__(self) -> None:
        check_fields(self, positive, ("rise", "run", "start_x", "landing", "edge_margin"))
        steps = self.steps
        if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
            raise InputError("steps", steps, f"an integer in 1..{MAX_STEPS}")
        if math.atan2(self.rise, self.run) > MAX_INCLINATION:
            raise InputError("rise", self.rise, f"at most run * tan(60 deg) = {self.run:.3f} m")

    @property
    def edges(self) -> FloatArray:
        """x of every riser [m], shape (steps,)."""
        return np.asarray(self.start_x + self.run * np.arange(self.steps), dtype=float)

    def treads(self, x: float) -> int:
        """Number of treads below a point above x (0 on the floor, ``steps`` on the landing)."""
        return int(np.clip(math.floor((x - self.start_x) / self.run) + 1, 0, self.steps))

    def centre_height(self, x: float, y: float = 0.0) -> float:
        """Height of a resting foot's centre above x [m] (away from the edges)."""
        return self.treads(x) * self.rise

    def normal(self, x: float, y: float = 0.0) -> FloatArray:
        """Unit normal of the treads, shape (3,)."""
        return np.array([0.0, 0.0, 1.0])

    def inclination(self, x: float) -> float:
        """Inclination of the flight (rise over run) where it is, 0 on the floor and landing."""
        inside = self.start_x <= x < self.start_x + (self.steps - 1) * self.run
        return math.atan2(self.rise, self.run) if inside else 0.0

    def local_plane(self, points: FloatArray) -> tuple[float, float, float]:
        """Least-squares plane through ``points`` (the feet): the flight's local plane."""
        return _plane_fit(points)

    def safe(self, x: float, radius: float) -> bool:
        """Whether a foot centred above x rests on one tread away from every edge."""
        e = self.edges
        return bool(np.all((x <= e - radius - self.edge_margin) | (x >= e + self.edge_margin)))

    def advance(self, foot: FloatArray, step: float, radius: float) -> FloatArray:
        """Foot centre ``step`` [m] further along x, moved the least onto a safe foothold."""
        x = float(foot[0]) + step
        if not self.safe(x, radius):
            e = self.edges
            near = int(np.argmin(np.abs(e - x)))
            below, above = e[near] - radius - self.edge_margin, e[near] + self.edge_margin
            options = [v for v in (below, above) if self.safe(v, radius)]
            if not options:
                raise InputError("run", self.run, "treads deep enough for a foot between edges")
            x = min(options, key=lambda v: abs(v - x))
        return np.array([x, float(foot[1]), self.centre_height(x)])

    def drop(self, point: FloatArray, direction: FloatArray) -> FloatArray:
        """The foot-centre surface point straight below ``point`` (legs vertical)."""
        return np.array([point[0], point[1], self.centre_height(float(point[0]))])

    def clearance(self, centres: FloatArray, radius: float) -> FloatArray:
        """Height of foot centres (N, 3) above the highest foot-centre surface within one foot
        radius of them horizontally [m], shape (N,): negative when a foot would cut an edge."""
        out = np.empty(centres.shape[0])
        for i, c in enumerate(centres):
            top = max(self.treads(float(c[0]) - radius), self.treads(float(c[0]) + radius))
            out[i] = c[2] - top * self.rise
        return out


#: the grounds the gait sequencer plans on
QuadrupedGround: TypeAlias = PlaneGround | VaryingSlope | Stairs

__all__ = ["MAX_INCLINATION", "PlaneGround", "QuadrupedGround", "Stairs", "VaryingSlope"]
