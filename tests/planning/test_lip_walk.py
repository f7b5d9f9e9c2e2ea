"""LIP walking pattern generator of document 004."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from footfall.errors import InputError
from footfall.planning import LipWalk, LipWalkParams, lip_example, lip_walk
from tests.conftest import IVP_ATOL, IVP_RTOL

#: the document's stop criterion
STOP_SPEED = 0.01  # m/s
#: the circle must close on itself within this distance (issue 2)
CIRCLE_CLOSURE = 0.05  # m
EXAMPLES = ("straight", "diagonal", "turn", "circle")


@pytest.mark.parametrize("name", EXAMPLES)
def test_trajectory_matches_piecewise_integration(name: str) -> None:
    """The whole CoM path equals an integration of x'' = g/z_c (x - p) over the footholds.

    Each phase is integrated from the generator's start state; its end must be the next phase's
    start state, so position and velocity are continuous across every step switch. (Phases are
    not chained through the integrator: the LIP's unstable mode would amplify its own error.)
    """
    walk = lip_walk(lip_example(name))
    p = walk.params
    t_sup = p.t_sup

    def f(_: float, s: np.ndarray, foot: np.ndarray) -> np.ndarray:
        return np.concatenate([s[2:], p.g / p.z_c * (s[:2] - foot)])

    state = np.concatenate([p.com0, p.vel0])
    worst = 0.0
    for k in range(walk.footholds.shape[0]):
        sol = solve_ivp(
            f, (0.0, t_sup), state, args=(walk.footholds[k],), rtol=IVP_RTOL, atol=IVP_ATOL
        )
        assert sol.success
        end = sol.y[:, -1]
        if k + 1 < walk.footholds.shape[0]:
            worst = max(worst, np.max(np.abs(end[:2] - walk.com_start[k + 1])))
            worst = max(worst, np.max(np.abs(end[2:] - walk.vel_start[k + 1])))
            state = np.concatenate([walk.com_start[k + 1], walk.vel_start[k + 1]])
    worst = max(worst, np.max(np.abs(end - np.concatenate([walk.final_com, walk.final_vel]))))
    assert worst < 1e-8


@pytest.mark.parametrize("name", EXAMPLES)
def test_sampled_path_is_continuous_at_switches(name: str) -> None:
    walk = lip_walk(lip_example(name))
    dt = 1e-4
    traj = walk.com_trajectory(dt)
    switch = np.flatnonzero(np.diff(traj["step"]) != 0)
    assert switch.size == walk.footholds.shape[0] - 1
    for key, rate in (("x", "vx"), ("y", "vy")):
        jump = np.abs(traj[key][switch + 1] - traj[key][switch])
        # Over one sample the position moves by about v dt; anything more is a discontinuity.
        assert np.all(jump <= np.abs(traj[rate][switch]) * dt * 1.01 + 1e-9)
        accel_bound = walk.params.g / walk.params.z_c * 1.0  # |x - p| < 1 m
        assert np.all(np.abs(np.diff(traj[rate])[switch]) <= accel_bound * dt)


@pytest.mark.parametrize("name", EXAMPLES)
def test_each_foothold_minimises_the_placement_cost(name: str) -> None:
    """Kajita eq. (4.58): checked with a numerical minimiser, not the closed form (4.59)."""
    assert_footholds_minimise_cost(lip_walk(lip_example(name)))


def test_one_step_walk_with_its_own_stop_weights_minimises_the_cost() -> None:
    """A single given step (the stop step's heading is then the only heading) and stop weights
    that differ from the walking weights: the stop foothold must use ``a_stop``, ``b_stop``."""
    params = LipWalkParams(
        z_c=0.8, t_sup=0.7, sx=(0.2,), sy=(0.2,), theta=(0.4,), a=5.0, b=2.0, a_stop=3.0,
        b_stop=0.25, vel0=(0.1, -0.05), g=9.8,
    )  # fmt: skip
    walk = lip_walk(params)
    assert walk.footholds.shape == (2, 2)
    assert_footholds_minimise_cost(walk)


def test_lip_walk_refuses_anything_but_parameters() -> None:
    with pytest.raises(InputError) as err:
        lip_walk({"z_c": 0.8})  # type: ignore[arg-type]
    assert err.value.field == "params"
    assert err.value.value == "dict"
    assert err.value.expected == "a LipWalkParams (see footfall.planning)"


def assert_footholds_minimise_cost(walk: LipWalk) -> None:
    lip = walk.lip
    p = walk.params
    t_sup = p.t_sup
    # Recover each step's target from the generator's own targets by re-deriving them independently.
    sx = np.array([*p.sx, 0.0])
    sy = np.array([*p.sy, 0.0])
    th = np.array([*p.headings, p.headings[-1]])
    c = np.cosh(t_sup / lip.Tc)
    s = np.sinh(t_sup / lip.Tc)
    for n in range(sx.size):
        rot = np.array([[np.cos(th[n]), -np.sin(th[n])], [np.sin(th[n]), np.cos(th[n])]])
        bar = rot @ np.array([sx[n] / 2, (-1) ** n * sy[n] / 2])
        vbar = np.array([(c + 1) / (lip.Tc * s) * bar[0], (c - 1) / (lip.Tc * s) * bar[1]])
        target = walk.ideal_footholds[n] + bar
        last = n == sx.size - 1
        a, b = (p.a_stop, p.b_stop) if last else (p.a, p.b)
        for axis in range(2):

            def cost(q: float, axis: int = axis) -> float:
                x, v = lip.state_at(
                    [walk.com_start[n, axis]], [walk.vel_start[n, axis]], [q], t_sup
                )
                return float(a * (target[axis] - x[0]) ** 2 + b * (vbar[axis] - v[0]) ** 2)

            best = minimize_scalar(cost, bracket=(-5.0, 5.0), tol=1e-12).x
            assert walk.footholds[n, axis] == pytest.approx(best, abs=1e-6)


def test_ideal_footholds_follow_walk_parameters() -> None:
    walk = lip_walk(lip_example("straight"))
    np.testing.assert_allclose(
        walk.ideal_footholds,
        [[0, 0], [0, 0.2], [0.3, 0.0], [0.6, 0.2], [0.9, 0.0], [0.9, 0.2]],
        atol=1e-12,
    )


@pytest.mark.parametrize("name", ["straight", "turn"])
def test_stop_brings_com_to_rest(name: str) -> None:
    walk = lip_walk(lip_example(name))
    assert np.linalg.norm(walk.final_vel) < STOP_SPEED
    # ... over the last foot, within half a sole length
    assert np.linalg.norm(walk.final_com - walk.footholds[-1]) < 0.1


def test_turning_example_reproduces_document_final_speed() -> None:
    """Document 004 section 3.3 reports v_x = 0, v_y = 0.0044 m/s for this example."""
    walk = lip_walk(lip_example("turn"))
    assert walk.final_vel[0] == pytest.approx(0.0, abs=1e-9)
    assert walk.final_vel[1] == pytest.approx(0.0044, abs=5e-5)


def test_circle_closes_on_itself() -> None:
    walk = lip_walk(lip_example("circle"))
    # Step 19 is the same foot at the same place of the circle as step 1, one lap later.
    assert np.linalg.norm(walk.footholds[19] - walk.footholds[1]) < CIRCLE_CLOSURE
    assert np.linalg.norm(walk.final_com - np.array(walk.params.com0)) < CIRCLE_CLOSURE
    # and it is a real circle, not a walk on the spot: the path spans more than 1.5 m
    traj = walk.com_trajectory(0.01)
    assert np.ptp(traj["x"]) > 1.5 and np.ptp(traj["y"]) > 1.5


def test_velocity_target_is_not_rotated_twice() -> None:
    """Document 004's erratum on Kajita eq. (4.62): a walk at a constant heading phi is NOT the
    rotated copy of the straight walk, because the velocity target is computed per world axis from
    the rotated position target and then left unrotated (as the reference MATLAB code does)."""
    phi = np.deg2rad(30.0)
    base = dict(z_c=0.8, t_sup=0.8, sx=(0.0, 0.3, 0.3, 0.0), sy=(0.2,) * 4, g=9.8)
    rotated = lip_walk(LipWalkParams(theta=(phi,) * 4, **base))
    straight = lip_walk(LipWalkParams(**base))
    r = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    copy = straight.footholds @ r.T
    assert np.max(np.abs(rotated.footholds[1:] - copy[1:])) > 1e-3


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"sy": (0.2, 0.3, 0.2, 0.2)}, "sy"),  # the document's own example is one short
        ({"theta": (0.0, 0.1)}, "theta"),
        ({"z_c": 0.0}, "z_c"),
        ({"t_sup": -0.8}, "t_sup"),
        ({"sx": (0.0, float("nan"), 0.3, 0.3, 0.0)}, "sx"),
        ({"sx": ()}, "sx"),
        ({"a": -1.0}, "a"),
        ({"a": 0.0, "b": 0.0}, "a, b"),
        ({"com0": (0.0,)}, "com0"),
    ],
)
def test_bad_input_names_the_parameter(kwargs: dict, field: str) -> None:
    args = dict(z_c=0.8, t_sup=0.8, sx=(0.0, 0.25, 0.25, 0.25, 0.0), sy=(0.2,) * 5)
    args.update(kwargs)
    with pytest.raises(InputError) as err:
        LipWalkParams(**args)
    assert err.value.field == field


def test_a_support_phase_too_long_for_double_precision_is_refused() -> None:
    # T_c = sqrt(0.8 / 9.81) = 0.2856 s; 1000 s would overflow cosh and write NaN footholds
    from footfall.errors import InputError
    from footfall.planning.lip_walk import LipWalkParams

    with pytest.raises(InputError, match="t_sup"):
        LipWalkParams(z_c=0.8, t_sup=1000.0, sx=(0.0, 0.3), sy=(0.2, 0.2))
    ok = LipWalkParams(z_c=0.8, t_sup=5.0, sx=(0.0, 0.3), sy=(0.2, 0.2))
    assert ok.t_sup == 5.0


def test_written_json_is_strict(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import json

    from footfall._io import write_json

    path = write_json(tmp_path / "x.json", {"a": float("nan"), "b": np.array([1.0, np.inf])})
    assert json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(c)) == {
        "a": None,
        "b": [1.0, None],
    }


def has_words(text: str, words: str) -> bool:
    """``words`` occur in ``text`` as whole words (not glued to other letters or digits)."""
    return re.search(rf"(?<!\w){re.escape(words)}(?!\w)", text) is not None


#: z_c = 1 m, g = 4 m/s^2: T_c = sqrt(z_c / g) = 0.5 s exactly, so the support-time limit is
#: 20 T_c = 10 s exactly (a mutant using z_c g, z_c / z_c or 1 / T_c moves it)
LIMIT_ARGS = dict(z_c=1.0, g=4.0, sx=(0.0, 0.3), sy=(0.2, 0.2))
LIMIT_T_SUP = 10.0  # s


def test_support_time_limit_is_twenty_time_constants() -> None:
    """``t_sup <= 20 T_c`` with ``T_c = sqrt(z_c / g)``: the limit itself is accepted, a hair
    above it is refused, and the message gives the limit, T_c and its formula."""
    assert LipWalkParams(t_sup=LIMIT_T_SUP, **LIMIT_ARGS).t_sup == LIMIT_T_SUP
    above = LIMIT_T_SUP * (1.0 + 1e-9)
    with pytest.raises(InputError) as err:
        LipWalkParams(t_sup=above, **LIMIT_ARGS)
    assert err.value.field == "t_sup"
    assert err.value.value == above
    text = err.value.expected
    assert "at most 20 T_c = 10 s" in text
    assert "T_c = sqrt(z_c / g) = 0.5 s" in text
    assert "exp(T_sup / T_c)" in text and has_words(text, "to rounding")
    # the limit scales with sqrt(z_c / g): T_c = 1 s at z_c = g = 4 admits 20 s, not 20.1 s
    assert LipWalkParams(z_c=4.0, g=4.0, t_sup=20.0, sx=(0.0,), sy=(0.2,)).t_sup == 20.0
    with pytest.raises(InputError, match="t_sup"):
        LipWalkParams(z_c=4.0, g=4.0, t_sup=20.1, sx=(0.0,), sy=(0.2,))


@pytest.mark.parametrize(
    ("kwargs", "field", "value", "words"),
    [
        ({"z_c": -1.0}, "z_c", -1.0, "> 0"),
        ({"t_sup": 0.0}, "t_sup", 0.0, "> 0"),
        ({"g": 0.0}, "g", 0.0, "> 0"),
        ({"g": float("inf")}, "g", float("inf"), "finite"),
        ({"sy": (0.2, 0.2)}, "sy", [0.2, 0.2], "3 values, one per step like sx (got 2)"),
        ({"theta": (0.0,) * 4}, "theta", [0.0] * 4, "3 values, one per step like sx (got 4)"),
        ({"sy": (0.2, float("nan"), 0.2)}, "sy", None, "finite"),
        ({"theta": (0.0, float("inf"), 0.0)}, "theta", None, "finite"),
        ({"b": -0.5}, "b", -0.5, ">= 0"),
        ({"a_stop": -0.5}, "a_stop", -0.5, ">= 0"),
        ({"b_stop": -0.5}, "b_stop", -0.5, ">= 0"),
        ({"a": 0.0, "b": 0.0}, "a, b", (0.0, 0.0), "weights not both zero"),
        ({"a_stop": 0.0, "b_stop": 0.0}, "a_stop, b_stop", (0.0, 0.0), "weights not both zero"),
        ({"vel0": (0.0, 0.0, 0.0)}, "vel0", None, "exactly 2 numbers"),
        ({"foot0": (0.0,)}, "foot0", None, "exactly 2 numbers"),
    ],
)
def test_bad_input_names_field_value_and_expectation(
    kwargs: dict, field: str, value: object, words: str
) -> None:
    args: dict = dict(z_c=0.8, t_sup=0.8, sx=(0.0, 0.3, 0.0), sy=(0.2,) * 3)
    args.update(kwargs)
    with pytest.raises(InputError) as err:
        LipWalkParams(**args)
    assert err.value.field == field
    if value is not None:
        assert err.value.value == value
    assert has_words(err.value.expected, words)


def test_parameters_are_stored_as_floats_under_their_own_names() -> None:
    """Integers and numpy scalars come back as Python floats in the field they were given for,
    and one weight of a pair may be zero."""
    p = LipWalkParams(
        z_c=1,
        t_sup=np.float32(0.5),
        sx=[0, 1, 2],
        sy=np.array([3, 4, 5]),
        theta=(6, 7, 8),
        a=0,
        b=2,
        com0=(9, 10),
        vel0=[11, 12],
        foot0=np.array([13, 14]),
        a_stop=3,
        b_stop=0,
        g=4,
    )
    values = {
        "z_c": 1.0,
        "t_sup": 0.5,
        "sx": (0.0, 1.0, 2.0),
        "sy": (3.0, 4.0, 5.0),
        "headings": (6.0, 7.0, 8.0),
        "a": 0.0,
        "b": 2.0,
        "com0": (9.0, 10.0),
        "vel0": (11.0, 12.0),
        "foot0": (13.0, 14.0),
        "a_stop": 3.0,
        "b_stop": 0.0,
        "g": 4.0,
    }
    for name, want in values.items():
        got = getattr(p, name)
        assert got == want, name
        items = got if isinstance(got, tuple) else (got,)
        assert all(type(v) is float for v in items), name
    assert p.n_steps == 4
    assert LipWalkParams(z_c=1.0, t_sup=0.5, sx=(0.0,), sy=(0.2,), a=1.0, b=0.0).b == 0.0
    q = LipWalkParams(z_c=1.0, t_sup=0.5, sx=(0.0,), sy=(0.2,), a_stop=0.0, b_stop=1.0)
    assert q.a_stop == 0.0 and q.headings == (0.0,)


def test_com_trajectory_ends_at_the_final_state_on_its_last_sample() -> None:
    """The time grid runs from 0 to the duration inclusive; the last sample is the end of the
    stop step, by the LIP closed form x(T) = p + (x0 - p) cosh(T / T_c) + T_c v0 sinh(T / T_c)."""
    walk = lip_walk(lip_example("straight"))
    p = walk.params
    n = walk.footholds.shape[0]
    duration = n * p.t_sup
    tc = np.sqrt(p.z_c / p.g)
    c, s = np.cosh(p.t_sup / tc), np.sinh(p.t_sup / tc)
    x0, v0, foot = walk.com_start[-1], walk.vel_start[-1], walk.footholds[-1]
    end = foot + (x0 - foot) * c + tc * v0 * s
    end_vel = (x0 - foot) * s / tc + v0 * c
    for dt in (0.1, 0.04, 0.07):  # 0.07 does not divide the duration: the grid stops short
        traj = walk.com_trajectory(dt)
        count = int(np.floor(duration / dt + 1e-9)) + 1
        assert traj["t"].size == count
        np.testing.assert_allclose(traj["t"], dt * np.arange(count), atol=1e-12)
        assert traj["step"][-1] == min(int(traj["t"][-1] / p.t_sup + 1e-9), n - 1)
        if count - 1 == round(duration / dt):
            assert traj["t"][-1] == pytest.approx(duration, abs=1e-12)
            assert traj["step"][-1] == n - 1
            np.testing.assert_allclose([traj["x"][-1], traj["y"][-1]], end, atol=1e-12)
            np.testing.assert_allclose([traj["vx"][-1], traj["vy"][-1]], end_vel, atol=1e-12)
    # a sample at a step switch belongs to the step that starts there
    traj = walk.com_trajectory(0.1)
    k = round(p.t_sup / 0.1)
    assert traj["step"][k] == 1 and traj["step"][k - 1] == 0
    np.testing.assert_allclose([traj["x"][k], traj["y"][k]], walk.com_start[1], atol=1e-12)
    np.testing.assert_allclose([traj["vx"][k], traj["vy"][k]], walk.vel_start[1], atol=1e-12)
    default = walk.com_trajectory()  # every 0.01 s
    assert default["t"].size == round(duration / 0.01) + 1
    np.testing.assert_allclose(np.diff(default["t"]), 0.01, atol=1e-12)
    with pytest.raises(InputError) as err:
        walk.com_trajectory(0.0)
    assert err.value.field == "dt" and "> 0" in err.value.expected
