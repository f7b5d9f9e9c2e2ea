"""Property-based hostile input: whatever a scene file or a plan file holds, reading it either
succeeds or raises footfall's own InputError (never a raw numpy / pydantic / yaml / KeyError)."""

from __future__ import annotations

import copy
import json
from typing import Any

import hypothesis.strategies as st
import pytest
from hypothesis import HealthCheck, given, settings

from footfall.errors import InputError
from footfall.planning import make_plan
from footfall.planning.plan import FootstepPlan
from footfall.terrain import builtin_scene, load_scene, scene_to_yaml

SCENE = builtin_scene("flat")
PLAN = make_plan(SCENE, "kinematic", 8)
assert PLAN.has_solution, PLAN.message
PLAN_DICT = json.loads(json.dumps(PLAN.to_dict(SCENE.name)))
SCENE_YAML = scene_to_yaml(SCENE)

#: JSON-like junk: what a tampered file could put in any field
junk = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**12), 10**12)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=20),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)


def _paths(data: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every path to a value inside nested dicts and lists."""
    out = [prefix] if prefix else []
    if isinstance(data, dict):
        for k, v in data.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data[:3]):
            out += _paths(v, (*prefix, i))
    return out


PLAN_PATHS = _paths(PLAN_DICT)


def _replace(data: Any, path: tuple[Any, ...], value: Any) -> Any:
    data = copy.deepcopy(data)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(path=st.sampled_from(PLAN_PATHS), value=junk)
def test_a_tampered_plan_file_reads_or_raises_input_error(
    path: tuple[Any, ...], value: Any
) -> None:
    data = _replace(PLAN_DICT, path, value)
    try:
        plan = FootstepPlan.from_dict(data, SCENE.robot, "plan.json")
    except InputError:
        return
    assert isinstance(plan, FootstepPlan)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=st.text(max_size=300))
def test_any_text_as_a_scene_loads_or_raises_input_error(text: str) -> None:
    if "\n" not in text:
        text += "\n"  # YAML text, never a path
    try:
        load_scene(text)
    except InputError:
        pass


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cut=st.integers(0, len(SCENE_YAML)), insert=st.text(max_size=12))
def test_a_damaged_scene_file_loads_or_raises_input_error(cut: int, insert: str) -> None:
    text = SCENE_YAML[:cut] + insert + SCENE_YAML[cut:]
    if "\n" not in text:
        text += "\n"
    try:
        load_scene(text)
    except InputError:
        pass


@pytest.mark.parametrize("key", ["footsteps", "alip", "planner", "status"])
def test_a_missing_section_names_the_field(key: str) -> None:
    data = {k: v for k, v in PLAN_DICT.items() if k != key}
    if key in PLAN_DICT:
        with pytest.raises(InputError):
            FootstepPlan.from_dict(data, SCENE.robot, "plan.json")
