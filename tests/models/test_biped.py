"""BipedParams and the reach trapezoid (document 000, eq. 5.12f)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.path import Path as MplPath

from footfall.errors import InputError
from footfall.models.biped import BipedParams, ReachTrapezoid, Side


def shoelace(v: np.ndarray) -> float:
    return 0.5 * sum(
        v[i, 0] * v[(i + 1) % len(v), 1] - v[(i + 1) % len(v), 0] * v[i, 1] for i in range(len(v))
    )


def test_side_other_and_sign() -> None:
    assert Side.LEFT.other is Side.RIGHT and Side.RIGHT.other is Side.LEFT
    assert Side.LEFT.sign == 1 and Side.RIGHT.sign == -1
    assert Side("left") is Side.LEFT


def test_default_reach_is_ccw_and_left_of_right_stance() -> None:
    reach = ReachTrapezoid()
    right = reach.for_stance(Side.RIGHT)
    left = reach.for_stance(Side.LEFT)
    assert shoelace(right) > 0 and shoelace(left) > 0
    assert np.all(right[:, 1] > 0) and np.all(left[:, 1] < 0)
    # Mirroring about x maps the set of vertices onto itself with y negated.
    assert sorted(map(tuple, left * [1, -1])) == sorted(map(tuple, right))


@pytest.mark.parametrize("stance", list(Side))
def test_reach_halfspaces_agree_with_matplotlib_path(stance: Side) -> None:
    reach = ReachTrapezoid()
    g, h = reach.halfspaces(stance)
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0)
    path = MplPath(reach.for_stance(stance))
    rng = np.random.default_rng(0)
    pts = rng.uniform([-0.4, -0.5], [0.5, 0.5], size=(2000, 2))
    inside_hs = np.all(pts @ g.T - h <= 0, axis=1)
    inside_mpl = path.contains_points(pts)
    # Points within 1 mm of an edge are ambiguous between the two tests.
    margin = np.min(np.abs(pts @ g.T - h), axis=1) > 1e-3
    assert np.array_equal(inside_hs[margin], inside_mpl[margin])
    assert inside_hs.sum() > 50  # the sample really probes the inside


def test_reach_clockwise_input_reversed_and_invalid_rejected() -> None:
    cw = np.array([(-0.12, 0.32), (0.25, 0.32), (0.35, 0.12), (-0.20, 0.12)])
    r = ReachTrapezoid(cw)
    assert shoelace(r.vertices) > 0
    with pytest.raises(InputError, match="reach"):
        ReachTrapezoid(np.array([(-0.2, -0.1), (0.3, -0.1), (0.3, 0.3), (-0.2, 0.3)]))  # y < 0
    with pytest.raises(InputError, match="convex"):
        ReachTrapezoid(np.array([(0.0, 0.1), (0.4, 0.1), (0.1, 0.15), (0.0, 0.4)]))
    with pytest.raises(InputError, match="reach"):
        ReachTrapezoid(np.zeros((3, 2)))


def test_biped_defaults_and_alip() -> None:
    p = BipedParams()
    assert p.theta_max == pytest.approx(math.radians(30))
    assert p.node_dt == pytest.approx(p.t_ss / (p.n_nodes - 1))
    alip = p.alip()
    assert alip.mass == p.mass and alip.com_height == p.com_height
    assert alip.omega == pytest.approx(math.sqrt(9.81 / 0.6))


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("mass", -1.0),
        ("com_height", 0.0),
        ("t_ss", float("nan")),
        ("n_nodes", 1),
        ("n_nodes", 2.5),
        ("u_max", True),
        ("theta_max", 4.0),
        ("stance_width", 0.5),  # outside the reach trapezoid beside the foot
        ("foot_length", "long"),
    ],
)
def test_biped_validation_names_field(field: str, value: object) -> None:
    with pytest.raises(InputError) as exc:
        BipedParams(**{field: value})  # type: ignore[arg-type]
    assert exc.value.field == field


def test_biped_accepts_reach_array() -> None:
    p = BipedParams(reach=np.array([(-0.1, 0.1), (0.3, 0.1), (0.2, 0.3), (-0.1, 0.3)]))  # type: ignore[arg-type]
    assert isinstance(p.reach, ReachTrapezoid)
