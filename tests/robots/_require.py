"""What the robot tests need: MuJoCo and example-robot-data (the ``robots`` extra).

Imported first by each robot test module: without the extra the importing module is skipped,
except with ``FOOTFALL_REQUIRE_ROBOTS=1`` (set by .ci/run): then it fails.
"""

from __future__ import annotations

import importlib.metadata
import os

import pytest

mujoco = pytest.importorskip("mujoco")

try:
    importlib.metadata.distribution("example-robot-data")
except importlib.metadata.PackageNotFoundError:
    if os.environ.get("FOOTFALL_REQUIRE_ROBOTS") == "1":
        raise
    pytest.skip(
        "example-robot-data is not installed (pip install 'footfall[robots]')",
        allow_module_level=True,
    )
