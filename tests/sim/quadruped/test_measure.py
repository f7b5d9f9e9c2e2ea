"""The compiled measurement of a control sample (sim/quadruped/_measure.py) gives the numbers of
the Python and numpy code it replaced, bit for bit: the contacts against ``mj_contactForce``
(elliptic and pyramidal cones), the centre of pressure and margin against
:mod:`footfall.quadruped.stability` (any number of points, inside and outside their polygon), the
sums against numpy's, and a walk's trace on a plane and on stairs against the reference
measurement below (the recorder's before the compilation)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall._geometry import cross3  # noqa: E402
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait  # noqa: E402
from footfall.quadruped.scene import builtin_quadruped_scene  # noqa: E402
from footfall.quadruped.stability import (  # noqa: E402
    _GEOM_EPS,
    centre_of_pressure,
    stability_margin,
    support_polygon,
)
from footfall.sim.quadruped import sim as quad_sim  # noqa: E402
from footfall.sim.quadruped._measure import _sum, measure_sample  # noqa: E402
from footfall.sim.quadruped.sim import QuadrupedSim, simulate  # noqa: E402

ROBOT = QuadrupedRobot()
SLOPE = math.radians(15.0)


def _bits(x: object) -> bytes:
    return np.ascontiguousarray(x, dtype=float).tobytes()


@pytest.mark.parametrize("n", [0, 1, 7, 8, 9, 16, 127, 128, 129, 300, 1000, 5000])
def test_sum_is_numpys_pairwise_sum(n: int) -> None:
    rng = np.random.default_rng(n)
    a = rng.standard_normal(n) * 10.0 ** rng.integers(-6, 6, n)
    assert _bits(_sum(a)) == _bits(a.sum())
    assert _bits(_sum(np.full(n, -0.0))) == _bits(np.full(n, -0.0).sum())


def _reference_contacts(sim: QuadrupedSim) -> tuple[np.ndarray, np.ndarray, list[int], bool]:
    """The feet's contacts one ``mj_contactForce`` call at a time."""
    d, m = sim.data, sim.model
    force = np.zeros(6)
    pts, frc, idx, trunk_hit = [], [], [], False
    for i in range(d.ncon):
        c = d.contact[i]
        g1, g2 = int(c.geom[0]), int(c.geom[1])
        if sim.trunk_geom in (g1, g2):
            trunk_hit = True
            continue
        if g1 in sim.foot_geoms:
            foot, sign = sim.foot_geoms.index(g1), -1.0
        elif g2 in sim.foot_geoms:
            foot, sign = sim.foot_geoms.index(g2), 1.0
        else:
            continue
        mujoco.mj_contactForce(m, d, i, force)
        frc.append(sign * (c.frame.reshape(3, 3).T @ force[:3]))
        pts.append(np.array(c.pos))
        idx.append(foot)
    return np.array(pts), np.array(frc), idx, trunk_hit


@pytest.mark.parametrize("cone", ["elliptic", "pyramidal"])
def test_foot_contacts_are_mj_contact_force(cone: str) -> None:
    plan = plan_gait(ROBOT, GaitParams(SLOPE, math.radians(10.0), cycles=1))
    sim = QuadrupedSim(ROBOT, SLOPE)
    if cone == "pyramidal":
        sim.model.opt.cone = mujoco.mjtCone.mjCONE_PYRAMIDAL
    ref = plan.sample(0.01, with_zmp=False)
    sim.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    checked = 0
    for step in range(300):
        mujoco.mj_step(sim.model, sim.data)
        if step % 20 == 0:
            pts, frc, idx, trunk_hit = sim.contacts()
            r_pts, r_frc, r_idx, r_hit = _reference_contacts(sim)
            assert idx.tolist() == r_idx and trunk_hit == r_hit
            if r_idx:
                assert _bits(pts) == _bits(r_pts) and _bits(frc) == _bits(r_frc)
                checked += len(r_idx)
    assert checked > 0


def _reference_margin(points: np.ndarray, forces: np.ndarray) -> tuple[np.ndarray, float]:
    cop, _ = centre_of_pressure(points, forces, float(points[:, 2].mean()))
    return cop, stability_margin(cop, support_polygon(points))


@pytest.mark.parametrize("seed", range(40))
def test_cop_and_margin_are_the_stability_functions(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 7))
    pts = rng.uniform(-0.3, 0.3, (n, 3))
    if seed % 4 == 1:  # collinear points: a segment
        pts[:, 1] = 0.5 * pts[:, 0]
    if seed % 4 == 2 and n > 1:  # a repeated point
        pts[-1] = pts[0]
    frc = np.column_stack([rng.normal(0.0, 5.0, (n, 2)), rng.uniform(1.0, 100.0, n)])
    if seed % 5 == 3:  # one point carries nearly everything: the CoP near a vertex or outside
        frc[:, 2] = 1.0
        frc[0, 2] = 1e4
        frc[0, :2] = rng.normal(0.0, 5e3, 2)
    idx = np.arange(n) % 4
    cop, margin = np.full((1, 2), np.nan), np.full(1, np.nan)
    measure_sample(
        0,
        pts,
        frc,
        idx,
        0.5,
        _GEOM_EPS,
        np.zeros(4, dtype=bool),
        np.zeros((4, 3)),
        np.zeros((4, 3)),
        np.arange(4),
        np.zeros((4, 6)),
        np.tile([0.0, 0.0, 1.0], (n + 4, 1)),
        cop,
        margin,
        np.zeros(1, dtype=np.int64),
        np.zeros((1, 4, 3)),
    )
    r_cop, r_margin = _reference_margin(pts, frc)
    assert _bits(cop[0]) == _bits(r_cop) and _bits(margin[0]) == _bits(r_margin)


def _reference_measure(self: quad_sim._Recorder, k: int) -> None:
    """The recorder's measurement before it was compiled (numpy and Python floats)."""
    sim, d, tr = self.sim, self.sim.data, self.trace
    tr.trunk_pos[k] = d.xpos[sim.trunk]
    tr.trunk_pitch[k] = quad_sim._pitch_of(d.xmat[sim.trunk])
    tr.feet[k] = d.site_xpos[sim.foot_sites]
    pts, frc, idx_list, trunk_hit = _reference_contacts(sim)
    idx = np.array(idx_list, dtype=int)
    pts, frc = pts.reshape(-1, 3), frc.reshape(-1, 3)
    loaded = frc[:, 2] > quad_sim.CONTACT_FORCE_FRACTION * self.weight
    tr.n_contacts[k] = np.unique(idx[loaded]).size
    if loaded.any():
        tr.cop[k], tr.margin[k] = _reference_margin(pts[loaded], frc[loaded])
    vel = np.zeros(6)

    def slip(foot: int, point: np.ndarray) -> np.ndarray:
        g = sim.foot_geoms[foot]
        normal = self.ground.normal(float(point[0]), float(point[1]))
        mujoco.mj_objectVelocity(sim.model, d, mujoco.mjtObj.mjOBJ_GEOM, g, vel, 0)
        vp = vel[3:] + cross3(vel[:3], point - d.geom_xpos[g])
        return np.asarray(vp - (vp @ normal) * normal)

    for j in range(idx.size):
        tr.slip_vel[k, idx[j]] = slip(int(idx[j]), pts[j])
    stance = tr.planned.contact[k]
    for leg in range(4):
        if stance[leg] and not np.any(idx == leg):
            tr.slip_vel[k, leg] = slip(leg, tr.feet[k, leg])
    if math.isnan(tr.fallen_at) and (trunk_hit or self._fallen(k)):
        tr.fallen_at = float(tr.t[k])


@pytest.mark.parametrize("ground", ["plane", "stairs"])
@pytest.mark.parametrize("controller", ["servo", "wbc"])
def test_walk_trace_is_the_reference_measurements(
    ground: str, controller: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    params = GaitParams(SLOPE, math.radians(10.0), cycles=1)
    if ground == "stairs":  # the ground's normal per point (not one plane's)
        params = dataclasses.replace(builtin_quadruped_scene("stairs_10cm").params, cycles=2)
    plan = plan_gait(ROBOT, params)
    fast = simulate(plan, controller=controller).trace
    monkeypatch.setattr(quad_sim._Recorder, "measure", _reference_measure)
    slow = simulate(plan, controller=controller).trace
    for f in ("trunk_pos", "trunk_pitch", "cop", "margin", "feet", "slip_vel"):
        assert _bits(getattr(fast, f)) == _bits(getattr(slow, f)), f
    assert np.array_equal(fast.n_contacts, slow.n_contacts)
    assert _bits(fast.fallen_at) == _bits(slow.fallen_at)
