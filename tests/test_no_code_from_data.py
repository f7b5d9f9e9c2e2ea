"""No file a user hands in can run code: the source never deserialises with pickle or marshal,
never loads YAML with a loader that builds Python objects, never evals."""

from __future__ import annotations

import ast
from pathlib import Path

import footfall

SRC = Path(footfall.__file__).parent
FORBIDDEN_MODULES = {"pickle", "cPickle", "dill", "marshal", "shelve", "cloudpickle"}
FORBIDDEN_CALLS = {"eval", "exec"}
UNSAFE_YAML = {"load", "load_all", "unsafe_load", "full_load"}


def test_no_unsafe_deserialisation_in_the_source() -> None:
    found = []
    for path in SRC.rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Import | ast.ImportFrom):
                names = (
                    [a.name for a in node.names]
                    if isinstance(node, ast.Import)
                    else [node.module or ""]
                )
                found += [
                    f"{path.name}: import {n}"
                    for n in names
                    if n.split(".")[0] in FORBIDDEN_MODULES
                ]
            elif isinstance(node, ast.Call):
                f = node.func
                if isinstance(f, ast.Name) and f.id in FORBIDDEN_CALLS:
                    found.append(f"{path.name}:{node.lineno}: {f.id}()")
                if (
                    isinstance(f, ast.Attribute)
                    and isinstance(f.value, ast.Name)
                    and f.value.id == "yaml"
                    and f.attr in UNSAFE_YAML
                ):
                    found.append(f"{path.name}:{node.lineno}: yaml.{f.attr}()")
    assert not found, found
