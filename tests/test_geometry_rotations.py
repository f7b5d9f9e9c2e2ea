"""rotation_log / rotation_exp (_geometry.py) and blend_rot (sim/biped/references.py) against
scipy's Rotation and Slerp: random rotations, near the identity, near and at a half turn."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from footfall._geometry import rotation_exp, rotation_log
from footfall.sim.biped.references import blend_rot

#: rotation vectors and matrices vs scipy, generic angles
ROT_TOL = 1e-10
#: near a half turn [rad]: within 1e-6 of it the axis comes from (R + I) / 2, whose error is of
#: the order of the gap itself; scipy is at 1e-15 everywhere
HALF_TURN_TOL = 1e-6

RNG_SEED = 19


def random_rotvecs(n: int, max_angle: float = math.pi - 1e-3) -> np.ndarray:
    rng = np.random.default_rng(RNG_SEED)
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return axes * rng.uniform(0.0, max_angle, size=(n, 1))


def test_log_matches_scipy_on_random_rotations() -> None:
    for v in random_rotvecs(200):
        r = Rotation.from_rotvec(v).as_matrix()
        np.testing.assert_allclose(
            rotation_log(r), Rotation.from_matrix(r).as_rotvec(), atol=ROT_TOL
        )


def test_exp_matches_scipy_and_round_trips() -> None:
    for v in random_rotvecs(200):
        r = rotation_exp(v)
        np.testing.assert_allclose(r, Rotation.from_rotvec(v).as_matrix(), atol=ROT_TOL)
        np.testing.assert_allclose(rotation_log(r), v, atol=ROT_TOL)


@pytest.mark.parametrize("angle", [0.0, 1e-14, 1e-10, 1e-8, 1e-6, 1e-4])
def test_near_identity(angle: float) -> None:
    v = angle * np.array([0.6, -0.0, 0.8])
    r = Rotation.from_rotvec(v).as_matrix()
    np.testing.assert_allclose(rotation_log(r), v, atol=1e-15 + 1e-9 * angle)
    np.testing.assert_allclose(rotation_exp(v), r, atol=1e-15)


@pytest.mark.parametrize("gap", [0.0, 1e-12, 1e-9, 5e-7, 1.01e-6, 2e-6, 1e-5, 1e-4])
@pytest.mark.parametrize("axis", [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.3, -0.5, 0.81), (-1, -1, 1)])
def test_near_a_half_turn(gap: float, axis: tuple[float, float, float]) -> None:
    """pi - gap about ``axis``: the log's angle is pi - gap and exp(log R) = R; off the exact half
    turn the axis has a sign (scipy's vector); at pi, +-axis are the same rotation.

    Just outside the half-turn branch (gap 1.01e-6, 2e-6) the angle from acos carries an error
    ~eps/gap that the division by sin(angle) ~ gap amplifies: 2.4e-4 rad wrong at 1.01e-6."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    v = (math.pi - gap) * a
    r = Rotation.from_rotvec(v).as_matrix()
    w = rotation_log(r)
    assert np.linalg.norm(w) == pytest.approx(math.pi - gap, abs=HALF_TURN_TOL)
    np.testing.assert_allclose(rotation_exp(w), r, atol=HALF_TURN_TOL)
    if gap > 0.0:
        np.testing.assert_allclose(w, v, atol=HALF_TURN_TOL)
    else:
        assert min(np.linalg.norm(w - v), np.linalg.norm(w + v)) < HALF_TURN_TOL


def test_log_of_a_product_is_the_relative_rotation() -> None:
    """rotation_log(Ra Rb^T) is the world-axes vector turning Rb into Ra (what the WBC's
    orientation error uses), checked with scipy's composition."""
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(50):
        ra, rb = Rotation.random(2, random_state=rng)
        expected = (ra * rb.inv()).as_rotvec()
        got = rotation_log(ra.as_matrix() @ rb.as_matrix().T)
        np.testing.assert_allclose(got, expected, atol=1e-9)


def test_blend_rot_is_slerp() -> None:
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(100):
        pair = Rotation.random(2, random_state=rng)
        if (pair[0].inv() * pair[1]).magnitude() > math.pi - 1e-3:
            continue  # the geodesic is not unique at a half turn
        slerp = Slerp([0.0, 1.0], pair)
        r0, r1 = pair.as_matrix()
        for s in (*rng.uniform(0.0, 1.0, 3), 0.0, 1.0):
            np.testing.assert_allclose(
                blend_rot(r0, r1, float(s)), slerp([s]).as_matrix()[0], atol=ROT_TOL
            )
