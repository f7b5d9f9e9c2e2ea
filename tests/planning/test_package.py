"""``footfall.planning`` imports its modules when a name is first used (reading a plan does not
import the solvers): every public name still resolves to what its module defines."""

from __future__ import annotations

import importlib
import pkgutil
import subprocess
import sys
import types

import footfall.planning as planning


def test_every_public_name_is_its_modules_object_after_every_module_is_imported() -> None:
    for info in pkgutil.iter_modules(planning.__path__):
        importlib.import_module(f"footfall.planning.{info.name}")
    for name in planning.__all__:
        obj = getattr(planning, name)
        assert not isinstance(obj, types.ModuleType), name  # a submodule took the name
        module, attr = planning._WHERE.get(name, (f"footfall.planning.{name}", name))
        if name in planning._WHERE:
            assert obj is getattr(importlib.import_module(module), attr), name


def test_reading_a_plan_imports_neither_the_solvers_nor_scipy() -> None:
    code = (
        "import sys; from footfall.planning import load_plan, FootstepPlan; "
        "print(sorted(m for m in ('scipy.linalg', 'scipy.integrate', 'footfall.planning.miqcqp',"
        " 'footfall.planning.check') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
