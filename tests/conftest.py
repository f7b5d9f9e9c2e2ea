"""Shared test settings: named tolerances, headless rendering."""

import os
import time
from collections.abc import Iterator
from dataclasses import replace

import pytest
from hypothesis import settings

from footfall.planning.plan import FootstepPlan

# MuJoCo picks its GL backend at import; offscreen EGL works headless (tests that render say so).
os.environ.setdefault("MUJOCO_GL", "egl")

# Hypothesis draws the same examples on every run by default (profile "ci", also what CI runs), so
# a failure reproduces from the test id alone and a green run means the same thing everywhere;
# FOOTFALL_HYPOTHESIS=dev draws fresh examples each run (and keeps failures in .hypothesis/) to
# look for new counterexamples. Tests keep their own max_examples; deadline None because the
# examples solve problems whose time varies with machine load.
settings.register_profile(
    "ci", derandomize=True, max_examples=100, deadline=None, print_blob=True, database=None
)
settings.register_profile("dev", derandomize=False, max_examples=100, deadline=None)
settings.load_profile(os.environ.get("FOOTFALL_HYPOTHESIS", "ci"))


#: agreement between closed-form/discrete models and a tight solve_ivp integration
INTEGRATION_TOL = 1e-7
#: solve_ivp tolerances used as the independent reference
IVP_RTOL = 1e-11
IVP_ATOL = 1e-12


def first_steps(plan: FootstepPlan, n: int) -> FootstepPlan:
    """The first ``n`` single supports of ``plan`` (a short walk, fast to simulate); the final
    state is the plan's state at the start of phase ``n``."""
    return replace(
        plan,
        footsteps=plan.footsteps[: n + 1],
        headings=plan.headings[: n + 1],
        sides=plan.sides[: n + 1],
        regions=plan.regions[: n + 1],
        states=plan.states[:n],
        torques=plan.torques[:n],
        final_state=plan.states[n, 0],
    )


class VirtualClock:
    """``time.perf_counter`` for a test (fixture :func:`virtual_clock`): it moves only when read
    (``step`` seconds a read) or when told (:meth:`advance`), so a time limit falls after the
    same work on any machine, loaded or not. Processes forked while it is installed inherit a
    copy that moves with their own reads."""

    def __init__(self, step: float = 1e-3) -> None:
        self.step = step
        self.now = 1000.0

    def __call__(self) -> float:
        self.now += self.step
        return self.now

    def advance(self, seconds: float) -> None:
        """Let ``seconds`` pass (work that takes time without reading the clock)."""
        self.now += seconds


@pytest.fixture
def virtual_clock(monkeypatch: pytest.MonkeyPatch) -> Iterator[VirtualClock]:
    """A :class:`VirtualClock` installed as ``time.perf_counter`` for the test."""
    clock = VirtualClock()
    monkeypatch.setattr(time, "perf_counter", clock)
    yield clock
