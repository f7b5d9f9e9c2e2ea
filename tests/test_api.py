"""Every name a package exports resolves (mink's drifted ``__all__`` is the counterexample)."""

from __future__ import annotations

import importlib
import pkgutil

import pytest

import footfall


def packages() -> list[str]:
    names = ["footfall"]
    for info in pkgutil.walk_packages(footfall.__path__, "footfall."):
        if info.ispkg:
            names.append(info.name)
    return names


@pytest.mark.parametrize("name", packages())
def test_exports_resolve(name: str) -> None:
    module = importlib.import_module(name)
    for export in getattr(module, "__all__", []):
        assert hasattr(module, export), f"{name}.__all__ lists missing {export!r}"
