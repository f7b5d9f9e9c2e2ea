"""The MPC's solvers against references that share no code with them (issue 24).

- the torque-disc QP (``solve_ball_qp``): the closed form of ``P = p I`` (each block alone:
  ``v_j = -q_j / max(p, ||q_j||)``), scipy's SLSQP on the same problem, and KKT conditions
  recomputed here;
- its pieces: the cold start's multipliers by hand, the dual's ``S = (P + Lambda)^-1`` and value
  from numpy's inverse;
- the footstep-polygon QP (``_clarabel_in_polygon``): SLSQP with the polygon and disc rows.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from footfall.control.ball_qp import _ball_dual, _cold_start, solve_ball_qp
from footfall.control.mpc import _check_polygon, _clarabel_in_polygon
from footfall.errors import InputError


def _random_pd(rng: np.random.Generator, n: int, cond: float = 1.0) -> np.ndarray:
    a = rng.normal(size=(n, n))
    return a @ a.T + cond * np.eye(n)


def _slsqp(p: np.ndarray, q: np.ndarray, extra: list[dict] | None = None, n_u: int | None = None):
    """Reference minimiser of 1/2 z'Pz + q'z with ||z_j|| <= 1 on the first n_u entries' blocks."""
    n = q.shape[0]
    n_u = n if n_u is None else n_u
    cons = [
        {"type": "ineq", "fun": (lambda z, j=j: 1.0 - z[2 * j] ** 2 - z[2 * j + 1] ** 2)}
        for j in range(n_u // 2)
    ] + (extra or [])
    best = None
    rng = np.random.default_rng(0)
    for start in [np.zeros(n), *(rng.uniform(-0.5, 0.5, n) for _ in range(4))]:
        res = minimize(
            lambda z: 0.5 * z @ p @ z + q @ z,
            start,
            jac=lambda z: p @ z + q,
            constraints=cons,
            method="SLSQP",
            options={"ftol": 1e-14, "maxiter": 500},
        )
        if best is None or res.fun < best.fun:
            best = res
    return best


def _objective(p: np.ndarray, q: np.ndarray, v: np.ndarray) -> float:
    return float(0.5 * v @ p @ v + q @ v)


@pytest.mark.parametrize("p_scale", [0.5, 2.0, 10.0])
def test_scaled_identity_has_the_closed_form_solution(p_scale: float) -> None:
    """P = p I decouples the blocks: v_j = -q_j / max(p, ||q_j||), lambda_j = max(||q_j|| - p, 0)."""
    q = np.array([3.0, 4.0, 0.1, -0.2, -1.0, 0.0, 0.0, 0.0])  # norms 5, 0.22, 1, 0
    p = p_scale * np.eye(8)
    v, lam, _, ok = solve_ball_qp(p, q)
    assert ok
    norms = np.linalg.norm(q.reshape(4, 2), axis=1)
    expected_v = -(q.reshape(4, 2) / np.maximum(p_scale, norms)[:, None]).ravel()
    np.testing.assert_allclose(v, expected_v, atol=1e-9)
    np.testing.assert_allclose(lam, np.maximum(norms - p_scale, 0.0), atol=1e-7)


def test_cold_start_is_each_blocks_exact_multiplier_with_a_diagonal_p() -> None:
    q = np.array([3.0, 4.0, 0.3, 0.4, 0.0, -6.0])  # norms 5, 0.5, 6
    p = np.diag([2.0, 2.0, 1.0, 1.0, 4.0, 2.0])  # block diagonals 2, 1, (4 + 2) / 2 = 3
    lam = _cold_start(p, q)
    # unconstrained norms ||P^-1 q_j||: 2.5, 0.5, 3 -> p_jj * max(norm - 1, 0)
    np.testing.assert_allclose(lam, [2.0 * 1.5, 0.0, 3.0 * 2.0])


def test_dual_matches_numpy_inverse_and_its_closed_form_value() -> None:
    rng = np.random.default_rng(3)
    p = _random_pd(rng, 6)
    q = rng.normal(0, 3, 6)
    lam = np.array([0.5, 0.0, 2.0])
    s, v, phi = _ball_dual(p, q, lam)
    ref = np.linalg.inv(p + np.diag(np.repeat(lam, 2)))
    np.testing.assert_allclose(s, ref, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(v, -ref @ q, rtol=1e-10, atol=1e-12)
    assert phi == pytest.approx(0.5 * q @ ref @ q + 0.5 * lam.sum(), rel=1e-12)


def test_dual_refuses_a_matrix_that_is_not_positive_definite() -> None:
    p = np.diag([1.0, -3.0, 1.0, 1.0])
    with pytest.raises(np.linalg.LinAlgError):
        _ball_dual(p, np.ones(4), np.zeros(2))
    # the multipliers lift it: P + Lambda is positive definite with lambda_0 > 3
    _, v, _ = _ball_dual(p, np.ones(4), np.array([4.0, 0.0]))
    assert np.all(np.isfinite(v))


@pytest.mark.parametrize("seed", range(6))
def test_random_problems_match_slsqp_and_the_kkt_conditions(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    n = 2 * int(rng.integers(1, 6))
    p = _random_pd(rng, n, cond=0.2)
    q = rng.normal(0, 4, n)
    v, lam, _, ok = solve_ball_qp(p, q)
    assert ok
    vb = v.reshape(-1, 2)
    norms = np.linalg.norm(vb, axis=1)
    assert np.all(norms <= 1.0 + 1e-12) and np.all(lam >= 0.0)
    # complementarity and stationarity, recomputed here
    assert np.all(lam * np.abs(1.0 - norms**2) < 1e-7)
    assert np.abs(p @ v + q + np.repeat(lam, 2) * v).max() < 1e-6
    ref = _slsqp(p, q)
    assert _objective(p, q, v) <= ref.fun + 1e-8
    np.testing.assert_allclose(v, ref.x, atol=1e-4)


def test_warm_start_from_the_solution_converges_at_once_and_cold_takes_steps() -> None:
    rng = np.random.default_rng(11)
    p = _random_pd(rng, 8, cond=0.1)
    q = rng.normal(0, 20, 8)
    v, lam, it_cold, ok = solve_ball_qp(p, q)
    assert ok and it_cold >= 1 and np.count_nonzero(lam) >= 1
    v2, lam2, it_warm, ok2 = solve_ball_qp(p, q, lam0=lam)
    np.testing.assert_allclose(lam2, lam, atol=1e-12)
    assert ok2 and it_warm == 0
    np.testing.assert_allclose(v2, v, atol=1e-12)
    # negative warm starts are clipped to the feasible multipliers, not trusted
    v3, _, _, ok3 = solve_ball_qp(p, q, lam0=-np.ones(4))
    assert ok3
    np.testing.assert_allclose(v3, v, atol=1e-7)


def _several_iterations_case() -> tuple[np.ndarray, np.ndarray]:
    """A 5-disc problem (poorly conditioned P, large q) that takes several Newton iterations."""
    rng = np.random.default_rng(12)
    return _random_pd(rng, 10, cond=0.01), rng.normal(0, 50, 10)


def test_iteration_limit_reports_no_convergence_and_returns_a_feasible_point() -> None:
    p, q = _several_iterations_case()
    _, _, it_full, ok = solve_ball_qp(p, q)
    assert ok and it_full >= 2
    v, _, it, ok0 = solve_ball_qp(p, q, max_iter=0)
    assert ok0 is False and it == 0  # a bool, as documented (not merely falsy)
    assert np.all(np.linalg.norm(v.reshape(-1, 2), axis=1) <= 1.0 + 1e-12)
    # a loose tolerance stops earlier than a tight one
    _, _, it_loose, ok_loose = solve_ball_qp(p, q, tol=1e-2)
    assert ok_loose and it_loose <= it_full


def test_inactive_discs_leave_the_unconstrained_optimum() -> None:
    rng = np.random.default_rng(13)
    p = _random_pd(rng, 6, cond=5.0)
    q = rng.normal(0, 0.1, 6)
    v, lam, it, ok = solve_ball_qp(p, q)
    assert ok and it == 0 and np.all(lam == 0.0)
    np.testing.assert_allclose(v, np.linalg.solve(p, -q), atol=1e-12)


def _backtracking_case(
    seed: int, q_decades: float = 2.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """A torque-disc QP on which the full Newton step is rejected at least once (ill-conditioned
    P, ``q`` up to ``10^q_decades``; seeds chosen by ``_trace`` below, which checks that they
    still are)."""
    rng = np.random.default_rng(seed)
    n = 2 * int(rng.integers(1, 6))
    a = rng.normal(size=(n, n))
    p = a @ a.T + 10 ** rng.uniform(-3, 1) * np.eye(n)
    q = rng.normal(size=n) * 10 ** rng.uniform(-1, q_decades)
    lam0 = None if rng.random() < 0.5 else rng.uniform(0, 10 ** rng.uniform(-2, 3), n // 2)
    return p, q, lam0


def _trace(monkeypatch: pytest.MonkeyPatch, p, q, lam0):  # type: ignore[no-untyped-def]
    """Run ``solve_ball_qp`` recording every evaluation of the dual and every Newton step.

    Returns the result and the iterations as ``(base, step, trials)``: ``base`` = (lam, s, v, phi)
    the iterate, ``step`` the Newton direction, ``trials`` the evaluations of the line search in
    order (the last one is accepted). A solve that evaluates the dual 2000 times is stopped (a
    line search that never ends must fail the test, not hang it)."""
    from footfall.control import ball_qp

    events: list[tuple[str, object]] = []
    real_dual, real_step = ball_qp._ball_dual, ball_qp._newton_step

    def dual(pp, qq, lam):  # type: ignore[no-untyped-def]
        if len(events) > 2000:
            raise RuntimeError("the line search does not end")
        out = real_dual(pp, qq, lam)
        events.append(("dual", (np.array(lam, dtype=float), *out)))
        return out

    def step(*args):  # type: ignore[no-untyped-def]
        out = real_step(*args)
        events.append(("step", np.array(out)))
        return out

    monkeypatch.setattr(ball_qp, "_ball_dual", dual)
    monkeypatch.setattr(ball_qp, "_newton_step", step)
    result = ball_qp.solve_ball_qp(p, q, lam0)
    iterations = []
    base = events[0][1]
    i = 1
    while i < len(events):
        assert events[i][0] == "step"
        direction = events[i][1]
        trials = []
        i += 1
        while i < len(events) and events[i][0] == "dual":
            trials.append(events[i][1])
            i += 1
        iterations.append((base, direction, trials))
        base = trials[-1]
    return result, iterations


@pytest.mark.parametrize("seed", [12, 15, 18, 20, 25])
def test_line_search_backtracks_by_halving_and_accepts_by_armijo(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The dual line search of ``solve_ball_qp``, checked step by step against its rule written
    here: trial k is ``max(lam + 2^-k d, 0)``; a trial is accepted iff
    ``phi_new <= phi + 1e-4 grad.(lam_new - lam)`` (grad = (1 - ||v_j||^2) / 2 from the dual's own
    v) or the predicted decrease is below rounding; the dual objective never increases; the
    answer matches SLSQP. Every seed here makes the full step fail at least once (random
    problems of the other tests never do, which left the backtracking untested)."""
    p, q, lam0 = _backtracking_case(seed)
    (v, _, it, ok), iterations = _trace(monkeypatch, p, q, lam0)
    assert ok and len(iterations) == it
    assert any(len(trials) > 1 for _, _, trials in iterations), "no backtracking on this seed"
    for (lam_b, _, v_b, phi_b), d, trials in iterations:
        grad = 0.5 * (1.0 - np.sum(v_b.reshape(-1, 2) ** 2, axis=1))
        for k, (lam_t, _, _, phi_t) in enumerate(trials):
            np.testing.assert_allclose(lam_t, np.maximum(lam_b + 0.5**k * d, 0.0), rtol=0, atol=0)
            dec = float(grad @ (lam_t - lam_b))
            armijo = phi_t <= phi_b + 1e-4 * dec or abs(dec) <= 1e-13 * (1.0 + abs(phi_b))
            assert armijo == (k == len(trials) - 1), (k, len(trials), phi_t, phi_b, dec)
        assert trials[-1][3] <= phi_b + 1e-12 * (1.0 + abs(phi_b))
    ref = _slsqp(p, q)
    assert _objective(p, q, v) <= ref.fun + 1e-8 * (1.0 + abs(ref.fun))


@pytest.mark.parametrize("seed", range(8))
def test_secular_step_is_exact_for_separable_active_discs(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With ``P`` block-diagonal of ``p_j I`` blocks, each disc alone has ``||v_j|| =
    ||q_j|| / (p_j + lambda_j)``: ``1 / ||v_j|| - 1`` is linear in ``lambda_j``, so the secular
    Newton step (Newton on that function) lands on the optimum ``lambda_j = ||q_j|| - p_j`` from
    any positive warm start in one full step when every disc is active (``||q_j|| > p_j``), up to
    the step's 1e-12 regulariser; the answer is the closed form ``v_j = -q_j / ||q_j||``. A step
    rescaled otherwise (plain Newton on the dual gradient, another factor) lands elsewhere."""
    rng = np.random.default_rng(300 + seed)
    n_b = int(rng.integers(1, 6))
    pj = 10 ** rng.uniform(-1, 1, n_b)
    q = rng.normal(size=2 * n_b)
    q *= np.repeat(pj * rng.uniform(2.0, 20.0, n_b) / np.linalg.norm(q.reshape(-1, 2), axis=1), 2)
    lam0 = rng.uniform(0.01, 30.0, n_b)
    qn = np.linalg.norm(q.reshape(-1, 2), axis=1)
    (v, lam, it, ok), iterations = _trace(monkeypatch, np.diag(np.repeat(pj, 2)), q, lam0)
    assert ok and 1 <= it <= 2
    _, _, first_trials = iterations[0]
    assert len(first_trials) == 1  # the full step is taken
    np.testing.assert_allclose(first_trials[0][0], qn - pj, rtol=1e-6)
    np.testing.assert_allclose(lam, qn - pj, rtol=1e-9)
    np.testing.assert_allclose(v, -q / np.repeat(qn, 2), atol=1e-9)


def _wide_case(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """As :func:`_backtracking_case` with ``q`` up to 1000: a few of these make the secular step
    point uphill on the dual (seeds chosen with ``_secular_step`` below, which checks them)."""
    return _backtracking_case(seed, q_decades=3.0)


def _secular_step(lam: np.ndarray, v: np.ndarray, s: np.ndarray) -> np.ndarray | None:
    """The secular Newton direction of the free multipliers, from the module docstring's
    formula (the dual Hessian ``H_jl = v_j^T S_jl v_l`` and the gradient rescaled per block by
    ``2 ||v_j||^2 / (1 + ||v_j||)``); None when some multiplier is held at 0."""
    vb = v.reshape(-1, 2)
    grad = 0.5 * (1.0 - np.sum(vb**2, axis=1))
    if np.any((lam <= 1e-3) & (grad > 0.0)):
        return None
    n_b = lam.shape[0]
    hess = np.array(
        [
            [vb[j] @ s[2 * j : 2 * j + 2, 2 * k : 2 * k + 2] @ vb[k] for k in range(n_b)]
            for j in range(n_b)
        ]
    )
    nrm = np.linalg.norm(vb, axis=1)
    return -np.linalg.solve(hess, grad * 2.0 * nrm**2 / (1.0 + nrm))


@pytest.mark.parametrize("seed", [145, 229, 578])
def test_an_uphill_secular_step_falls_back_to_newton(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where the secular step is not a descent direction of the dual (checked here from its
    formula), the step taken is: every Newton direction of the solve goes downhill
    (``grad . d < 0``), and the answer matches SLSQP."""
    p, q, lam0 = _wide_case(seed)
    (v, _, it, ok), iterations = _trace(monkeypatch, p, q, lam0)
    assert ok and len(iterations) == it
    uphill = 0
    for (lam_b, s_b, v_b, _), d, _ in iterations:
        grad = 0.5 * (1.0 - np.sum(v_b.reshape(-1, 2) ** 2, axis=1))
        sec = _secular_step(lam_b, v_b, s_b)
        if sec is not None and grad @ sec >= 0.0:
            uphill += 1
        assert grad @ d < 0.0
    assert uphill >= 1, "the secular step never points uphill on this seed"
    ref = _slsqp(p, q)
    assert _objective(p, q, v) <= ref.fun + 1e-8 * (1.0 + abs(ref.fun))


def test_a_line_search_that_finds_no_decrease_takes_a_tiny_step_and_goes_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A first direction that goes uphill (the Newton step reversed, injected): every trial fails
    the Armijo test, the search halves down to alpha < 1e-10 (2^-34 of the step), takes that
    tiny step and continues with the true Newton steps to the same answer as an undisturbed
    solve."""
    from footfall.control import ball_qp

    p, q, lam0 = _backtracking_case(12)
    v_ref, lam_ref, _, ok_ref = solve_ball_qp(p, q, lam0)
    real_step = ball_qp._newton_step
    calls = {"n": 0}

    def reversed_first(*args):  # type: ignore[no-untyped-def]
        d = real_step(*args)
        calls["n"] += 1
        return -d if calls["n"] == 1 else d

    monkeypatch.setattr(ball_qp, "_newton_step", reversed_first)
    (v, lam, _, ok), iterations = _trace(monkeypatch, p, q, lam0)
    (lam_b, _, _, _), d, trials = iterations[0]
    assert len(trials) == 35  # alpha = 1, 1/2, ..., 2^-34 < 1e-10
    np.testing.assert_allclose(trials[-1][0], np.maximum(lam_b + 0.5**34 * d, 0.0), rtol=0, atol=0)
    assert ok and ok_ref
    np.testing.assert_allclose(v, v_ref, atol=1e-8)
    np.testing.assert_allclose(lam, lam_ref, rtol=1e-6, atol=1e-9)


def _polygon_case(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    rng = np.random.default_rng(200 + seed)
    n_u = 4
    p = _random_pd(rng, n_u + 2, cond=0.5)
    q = rng.normal(0, 3, n_u + 2)
    # a square |d_x|, |d_y| <= 0.05 around the origin, usually active
    a = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    b = np.full(4, 0.05)
    return p, q, a, b, n_u


@pytest.mark.parametrize("seed", range(4))
def test_polygon_qp_matches_slsqp(seed: int) -> None:
    p, q, a, b, n_u = _polygon_case(seed)
    res = _clarabel_in_polygon(p, q, a, b, n_u)
    assert str(res.status) == "Solved"
    z = np.asarray(res.x)
    assert np.all(a @ z[n_u:] <= b + 1e-7)
    assert np.all(np.linalg.norm(z[:n_u].reshape(-1, 2), axis=1) <= 1.0 + 1e-7)
    extra = [
        {"type": "ineq", "fun": (lambda z, k=k: b[k] - a[k] @ z[n_u:])} for k in range(a.shape[0])
    ]
    ref = _slsqp(p, q, extra, n_u)
    assert _objective(p, q, z) == pytest.approx(ref.fun, abs=1e-7)
    np.testing.assert_allclose(z, ref.x, atol=1e-4)


def test_polygon_arrays_are_checked() -> None:
    a, b = _check_polygon([[1.0, 0.0], [0.0, 1.0]], [0.1, 0.2])
    assert a.shape == (2, 2) and b.shape == (2,)
    for bad_a, bad_b, field in (
        ([1.0, 0.0], [0.1], "a"),
        (np.zeros((0, 2)), np.zeros(0), "a"),
        ([[1.0, np.nan]], [0.1], "a"),
        ([[1.0, 0.0, 0.0]], [0.1], "a"),
        ([[1.0, 0.0]], [0.1, 0.2], "b"),
        ([[1.0, 0.0]], [np.inf], "b"),
    ):
        with pytest.raises(InputError) as err:
            _check_polygon(bad_a, bad_b)
        assert err.value.field == field


def _plain_newton_step(lam: np.ndarray, grad: np.ndarray, vb: np.ndarray, s: np.ndarray):  # type: ignore[no-untyped-def]
    """Newton on the dual gradient itself (no secular rescaling), written here from the dual
    Hessian ``H_jl = v_j^T S_jl v_l``: the method the secular step is claimed to beat."""
    n_b = lam.shape[0]
    bound = (lam <= 1e-12) & (grad > 0.0)
    free = ~bound
    step = -grad.copy()
    if free.any():
        hess = np.einsum("ja,jalb,lb->jl", vb, s.reshape(n_b, 2, n_b, 2), vb)
        hf = hess[np.ix_(free, free)] + 1e-12 * np.eye(int(free.sum()))
        step[free] = -np.linalg.solve(hf, grad[free])
    return step


def _iterations(problems: list[tuple[np.ndarray, np.ndarray]]) -> int:
    total = 0
    for p, q in problems:
        _, _, it, ok = solve_ball_qp(p, q)
        assert ok
        total += it
    return total


def test_secular_newton_takes_far_fewer_iterations_than_plain_newton(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The module's claim: the secular (More-Sorensen) step needs far fewer dual iterations than
    Newton on the dual gradient, on the same problems (here under 3/4 of them)."""
    import footfall.control.ball_qp as ball_qp

    problems = []
    for seed in range(120):
        rng = np.random.default_rng(1000 + seed)
        n = 2 * int(rng.integers(2, 12))
        a = rng.normal(size=(n, n))
        problems.append(
            (a @ a.T + rng.uniform(0.01, 1.0) * np.eye(n), rng.normal(0, rng.uniform(1, 50), n))
        )
    secular = _iterations(problems)
    monkeypatch.setattr(ball_qp, "_newton_step", _plain_newton_step)
    plain = _iterations(problems)
    assert secular < 0.75 * plain


def test_iteration_limit_is_exact() -> None:
    """A problem that converges in k iterations converges with max_iter = k, not with k - 1."""
    p, q = _several_iterations_case()
    v, _, k, ok = solve_ball_qp(p, q)
    assert ok and k >= 2
    v_k, _, it_k, ok_k = solve_ball_qp(p, q, max_iter=k)
    assert ok_k and it_k == k
    np.testing.assert_array_equal(v_k, v)
    _, _, it_less, ok_less = solve_ball_qp(p, q, max_iter=k - 1)
    assert not ok_less and it_less == k - 1


@pytest.mark.parametrize("scale", [1e-6, 1e3])
def test_far_warm_starts_reach_the_same_solution(scale: float) -> None:
    rng = np.random.default_rng(14)
    p = _random_pd(rng, 12, cond=0.05)
    q = rng.normal(0, 30, 12)
    v, _, _, ok = solve_ball_qp(p, q)
    v2, _, _, ok2 = solve_ball_qp(p, q, lam0=np.full(6, scale))
    assert ok and ok2
    np.testing.assert_allclose(v2, v, atol=1e-7)


def test_dual_errors_say_what_failed() -> None:
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        _ball_dual(np.diag([1.0, -3.0]), np.ones(2), np.zeros(1))


def test_polygon_errors_name_the_value_and_the_shape() -> None:
    with pytest.raises(InputError) as err:
        _check_polygon([[1.0, np.nan]], [0.1])
    assert err.value.value == [[1.0, np.nan]] or "nan" in str(err.value)
    assert err.value.expected == "finite edge normals of shape (E, 2), E >= 1"
    with pytest.raises(InputError) as err:
        _check_polygon([[1.0, 0.0]], [0.1, 0.2])
    assert err.value.value == [0.1, 0.2]
    assert "shape (1,)" in err.value.expected


def test_polygon_solve_prints_nothing(capfd: pytest.CaptureFixture[str]) -> None:
    p, q, a, b, n_u = _polygon_case(0)
    _clarabel_in_polygon(p, q, a, b, n_u)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
