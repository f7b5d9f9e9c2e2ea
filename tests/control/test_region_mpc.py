"""Region-aware MPC (issue 23): the footstep the MPC chooses stays in its foothold region inset by
the sole, is the optimum of the sparse reference SOCP with the region rows, and a sideways push
that sends the document's unconstrained footstep off the stone keeps it on (or moves it to a named
neighbour). Independent references: the sparse Clarabel problem of test_mpc, Clarabel on the 2-D
QP, and shapely for "the whole sole is on the region"."""

from __future__ import annotations

import math

import clarabel
import numpy as np
import pytest
from scipy import sparse
from shapely.geometry import Polygon

from footfall.control import MPC, MPCWeights, build_mpc
from footfall.control.region_mpc import (
    RegionMPC,
    RegionRows,
    RegionSolution,
    choose_region,
    sole_inset_offsets,
    solve_polygon_qp,
)
from footfall.errors import InputError
from footfall.terrain.region import Region
from tests.control.test_mpc import RATE_DT, ROBOT, random_theta, reference_solve

#: optimal cost vs the reference interior-point solve (relative), as in test_mpc
OPTIMALITY_RTOL = 1e-6
#: region rows at the solution [m]: the QP's own tolerance
ROW_TOL = 1e-9
#: shapely's covers() on the sole rectangle: rounding of the corner coordinates [m]
COVER_TOL = 1e-9
#: 2-D QP minimiser vs Clarabel's [m]
QP2_ATOL = 1e-7

LIM = (ROBOT.u_max, 2.0 * ROBOT.u_max)


@pytest.fixture(scope="module")
def model():  # type: ignore[no-untyped-def]
    return build_mpc(ROBOT, MPCWeights(), RATE_DT, torque_limits=LIM)


def _clarabel_qp2(m: np.ndarray, lin: np.ndarray, g: np.ndarray, h: np.ndarray) -> np.ndarray:
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-12
    res = clarabel.DefaultSolver(
        sparse.triu(sparse.csc_matrix(m)).tocsc(),
        lin,
        sparse.csc_matrix(g),
        h,
        [clarabel.NonnegativeConeT(g.shape[0])],
        settings,
    ).solve()
    assert str(res.status) == "Solved"
    return np.asarray(res.x)


@pytest.mark.parametrize("seed", range(12))
def test_polygon_qp_is_clarabels_optimum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(2, 2))
    m = a @ a.T + 0.1 * np.eye(2)
    lin = rng.normal(size=2) * 3.0
    ang = np.sort(rng.uniform(0, 2 * math.pi, int(rng.integers(3, 9))))
    verts = np.stack([np.cos(ang), np.sin(ang)], 1) * 0.3 + rng.normal(size=2) * 0.2
    region = Region.from_height("r", 0.0, verts)
    g, h = region.halfspaces()
    res = solve_polygon_qp(m, lin, g, h)
    assert res is not None
    d, active = res
    np.testing.assert_allclose(d, _clarabel_qp2(m, lin, g, h), atol=QP2_ATOL)
    assert np.all(g @ d <= h + ROW_TOL)
    for i in active:
        assert g[i] @ d == pytest.approx(h[i], abs=1e-9)


def test_polygon_qp_reports_an_empty_polygon() -> None:
    g = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0]])
    h = np.array([-0.1, -0.1, 1.0])  # x <= -0.1 and x >= 0.1
    assert solve_polygon_qp(np.eye(2), np.zeros(2), g, h) is None


@pytest.mark.parametrize("heading_deg", [0.0, 17.0, 90.0, -135.0])
def test_sole_inset_keeps_the_whole_sole_on_the_region(heading_deg: float) -> None:
    """Footsteps at the corners of the inset polygon: their sole rectangles lie in the region and
    touch its boundary (the inset is exact, not conservative)."""
    verts = np.array([[0.0, 0.0], [0.4, -0.05], [0.5, 0.3], [0.1, 0.35]])
    region = Region.from_height("stone", 0.0, verts)
    a, b = region.halfspaces()
    hd = math.radians(heading_deg)
    L, W = ROBOT.foot_length, ROBOT.foot_width
    h = sole_inset_offsets(a, b, hd, L, W)
    poly = Polygon(verts)
    t = np.array([math.cos(hd), math.sin(hd)])
    s = np.array([-t[1], t[0]])
    for target in (np.array([5.0, 0.0]), np.array([-5.0, 2.0]), np.array([0.3, -5.0])):
        res = solve_polygon_qp(np.eye(2), -target, a, h)  # nearest inset point to target
        assert res is not None
        p = res[0]
        corners = [p + sx * L / 2 * t + sy * W / 2 * s for sx in (1, -1) for sy in (1, -1)]
        sole = Polygon([corners[0], corners[1], corners[3], corners[2]])
        assert poly.buffer(COVER_TOL).covers(sole)
        assert poly.exterior.distance(sole) < 1e-9  # on the boundary: exact inset


@pytest.mark.parametrize("seed", range(10))
def test_region_solution_is_the_sparse_references_optimum(model, seed: int) -> None:  # type: ignore[no-untyped-def]
    """Random small regions near the free footstep: the solution satisfies the rows (checked
    with the region's own geometry) and has the reference optimum's cost; the three stages of the
    solver are all exercised."""
    rng = np.random.default_rng(seed)
    theta = random_theta(rng, scale=[0.3, 1.5, 3.0][seed % 3])
    k_s = int(rng.integers(0, model.n_ticks))
    stance = np.array([0.3, -0.2, 0.05])
    ref = np.array([stance[0] + theta[4], stance[1] + theta[5], 0.1])
    free = MPC(model).solve(k_s, theta[:4], stance, ref, theta[6:])
    c = free.next_footstep[:2] + rng.normal(0, 0.05, 2)
    verts = c + np.array([[-0.02, -0.03], [0.02, -0.03], [0.02, 0.03], [-0.02, 0.03]])
    region = Region.from_height("r", 0.0, verts)
    a, b = region.halfspaces()
    rows = RegionRows("r", a, b - a @ stance[:2])
    rs = RegionMPC(MPC(model)).solve(k_s, theta, stance, ref, [rows], 0.1)
    assert rs.region == "r" and rs.reason == "planned"
    p = rs.solution.next_footstep
    assert float(region.signed_distance(p[:2])) <= ROW_TOL
    v = rs.solution.torques / np.array(LIM)
    assert np.all(np.hypot(v[:, 0], v[:, 1]) <= 1.0 + 1e-9)
    z = np.concatenate([rs.solution.torques.ravel(), p[:2] - stance[:2]])
    ref_cost, _ = reference_solve(model, k_s, theta, LIM, (rows.g, rows.h))
    assert model.cost(k_s, z, theta) <= ref_cost * (1 + OPTIMALITY_RTOL) + 1e-9
    assert rs.cost == pytest.approx(model.cost(k_s, z, theta), rel=1e-12)


def test_every_stage_of_the_solver_is_used(model) -> None:  # type: ignore[no-untyped-def]
    methods = set()
    for seed in range(10):
        rng = np.random.default_rng(seed)
        theta = random_theta(rng, scale=[0.3, 1.5, 3.0][seed % 3])
        k_s = int(rng.integers(0, model.n_ticks))
        stance = np.array([0.3, -0.2, 0.05])
        ref = np.array([stance[0] + theta[4], stance[1] + theta[5], 0.1])
        free = MPC(model).solve(k_s, theta[:4], stance, ref, theta[6:])
        c = free.next_footstep[:2] - stance[:2] + rng.normal(0, 0.05, 2)
        g = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
        h = np.array([c[0] + 0.02, 0.02 - c[0], c[1] + 0.03, 0.03 - c[1]])
        rs = RegionMPC(MPC(model)).solve(k_s, theta, stance, ref, [RegionRows("r", g, h)], 0.1)
        methods.add(rs.method)
    assert methods == {"unconstrained", "polygon_qp", "active_set"}


def _stones() -> dict[str, Region]:
    """Stance stone at the origin; the planned stone ahead-left; a wider neighbour further left."""
    return {
        "stance": Region.from_height(
            "stance", 0.0, [[-0.15, -0.12], [0.15, -0.12], [0.15, 0.12], [-0.15, 0.12]]
        ),
        "planned": Region.from_height(
            "planned", 0.0, [[0.15, 0.08], [0.4, 0.08], [0.4, 0.3], [0.15, 0.3]]
        ),
        "left": Region.from_height(
            "left", 0.0, [[0.15, 0.34], [0.45, 0.34], [0.45, 0.7], [0.15, 0.7]]
        ),
    }


def _pushed_case():  # type: ignore[no-untyped-def]
    """A robot on the stance stone (right foot) pushed hard to the left mid-step."""
    robot = ROBOT
    mdl = build_mpc(robot, MPCWeights(), RATE_DT)
    mzh = robot.mass * robot.com_height
    stance = np.array([0.0, 0.0, 0.0])
    ref = np.array([0.275, 0.19, 0.0])
    # CoM over the foot, moving forward 0.3 m/s and left 0.9 m/s: L = m z_H (-v_y, v_x)
    x = np.array([0.0, 0.02, -mzh * 0.9, mzh * 0.3])
    x_next = np.array([-0.1, -0.1, mzh * 0.1, mzh * 0.3])
    theta = np.concatenate([x, ref[:2] - stance[:2], x_next])
    return mdl, theta, stance, ref


def _rows(region: Region, stance: np.ndarray) -> RegionRows:
    a, b = region.halfspaces()
    h = sole_inset_offsets(a, b, 0.0, ROBOT.foot_length, ROBOT.foot_width) - a @ stance[:2]
    return RegionRows(region.name, a, h)


def test_a_sideways_push_leaves_the_region_unconstrained_but_not_region_aware() -> None:
    mdl, theta, stance, ref = _pushed_case()
    stones = _stones()
    free = MPC(mdl).solve_theta(0, theta, stance, ref)
    assert float(stones["planned"].signed_distance(free.next_footstep[:2])) > 0.02
    rs = RegionMPC(MPC(mdl)).solve(0, theta, stance, ref, [_rows(stones["planned"], stance)], 0.1)
    assert rs.region == "planned"
    p = rs.solution.next_footstep[:2]
    L, W = ROBOT.foot_length, ROBOT.foot_width
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * np.array([L / 2, W / 2])
    sole = Polygon(p + half)
    assert Polygon(stones["planned"].vertices).buffer(COVER_TOL).covers(sole)


def test_a_sideways_push_switches_to_the_named_neighbour_when_it_is_cheaper() -> None:
    mdl, theta, stance, ref = _pushed_case()
    stones = _stones()
    cands = [_rows(stones["planned"], stance), _rows(stones["left"], stance)]
    rs = RegionMPC(MPC(mdl)).solve(0, theta, stance, ref, cands, 0.1)
    assert rs.region == "left" and rs.reason == "cheaper"
    assert rs.costs["left"] < rs.costs["planned"] - 0.1
    assert float(stones["left"].signed_distance(rs.solution.next_footstep[:2])) <= ROW_TOL
    # an unreachable margin keeps the planned stone
    kept = RegionMPC(MPC(mdl)).solve(0, theta, stance, ref, cands, 1e6)
    assert kept.region == "planned"


def _sol(cost: float, name: str) -> RegionSolution:
    mdl = build_mpc(ROBOT, MPCWeights(), RATE_DT)
    s = MPC(mdl).solve_theta(0, np.zeros(10), np.zeros(3), np.zeros(3))
    return RegionSolution(s, name if math.isfinite(cost) else "", "polygon_qp", cost)


def test_choose_region_prefers_the_first_unless_infeasible_or_much_dearer() -> None:
    assert choose_region([_sol(1.0, "a"), _sol(0.95, "b")], 0.1).region == "a"
    got = choose_region([_sol(1.0, "a"), _sol(0.5, "b")], 0.1)
    assert (got.region, got.reason) == ("b", "cheaper")
    got = choose_region([_sol(math.inf, "a"), _sol(3.0, "b"), _sol(2.0, "c")], 0.1)
    assert (got.region, got.reason) == ("c", "first infeasible")
    got = choose_region([_sol(math.inf, "a"), _sol(math.inf, "b")], 0.1)
    assert (got.region, got.reason) == ("", "none feasible")


def test_bad_rows_name_the_field() -> None:
    with pytest.raises(InputError, match="regions"):
        RegionRows("x", np.zeros((2, 3)), np.zeros(2))
    with pytest.raises(InputError, match="regions"):
        RegionRows("x", np.zeros((2, 2)), np.zeros(3))


@pytest.mark.parametrize("seed", range(6))
def test_pruned_candidates_cannot_beat_the_choice(model, seed: int) -> None:  # type: ignore[no-untyped-def]
    """With several regions, the choice equals choose_region over every region solved exactly,
    and a pruned region's reported cost is a lower bound of its exact cost."""
    rng = np.random.default_rng(50 + seed)
    theta = random_theta(rng, scale=[0.3, 1.5, 3.0][seed % 3])
    k_s = int(rng.integers(0, model.n_ticks))
    stance = np.array([0.3, -0.2, 0.05])
    ref = np.array([stance[0] + theta[4], stance[1] + theta[5], 0.1])
    g = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    cands = []
    for j in range(4):
        c = theta[4:6] + rng.normal(0, 0.12, 2)
        cands.append(
            RegionRows(f"r{j}", g, np.array([c[0] + 0.03, 0.03 - c[0], c[1] + 0.04, 0.04 - c[1]]))
        )
    rs = RegionMPC(MPC(model)).solve(k_s, theta, stance, ref, cands, 0.05)
    exact = [RegionMPC(MPC(model)).solve_region(k_s, theta, stance, ref, c) for c in cands]
    want = choose_region(exact, 0.05)
    assert rs.region == want.region
    if want.region:
        assert rs.cost == pytest.approx(want.cost, rel=1e-9)
    for c, e in zip(cands, exact, strict=True):
        assert rs.costs[c.name] <= e.cost * (1 + 1e-9) + 1e-12
