"""The Hypothesis profile of tests/conftest.py: derandomised unless FOOTFALL_HYPOTHESIS=dev."""

import os

import pytest
from hypothesis import settings


@pytest.mark.skipif(
    os.environ.get("FOOTFALL_HYPOTHESIS", "ci") != "ci", reason="another profile was asked for"
)
def test_examples_are_the_same_on_every_run() -> None:
    from tests.planning import test_miqcqp

    # a test's own @settings keeps the profile's other fields
    own = test_miqcqp.test_segment_reach_rows_are_conservative._hypothesis_internal_use_settings
    for s in (settings.default, own):
        assert s.derandomize and s.deadline is None and s.print_blob and s.database is None
    assert own.max_examples == 200
