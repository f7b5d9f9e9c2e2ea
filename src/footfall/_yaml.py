"""The YAML loader of every file footfall reads (scenes, quadruped scenes, studies)."""

from __future__ import annotations

from typing import Any

import yaml
from yaml.constructor import ConstructorError

#: YAML's safe loader (no Python objects from tags), libyaml's C implementation when installed
_SAFE: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

#: the tag of a YAML merge key (``<<: *base``), whose keys a mapping may override
_MERGE = "tag:yaml.org,2002:merge"


class UniqueKeyLoader(_SAFE):
    """YAML's safe loader, refusing a mapping that repeats a key.

    YAML itself lets the last of two equal keys win, so ``mass: 30`` followed further down by
    ``mass: 3`` silently drops the first: the error names the key and both lines (a merge key's
    ``<<`` entries may still be overridden, as YAML intends)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            if key_node.tag == _MERGE:
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                first = seen.get(key)
            except TypeError:  # unhashable: the base class says so
                continue
            if first is not None:
                raise ConstructorError(
                    "while constructing a mapping",
                    node.start_mark,
                    f"found the key {key!r} twice (first on line {first + 1})",
                    key_node.start_mark,
                )
            seen[key] = key_node.start_mark.line
        result: dict[Any, Any] = super().construct_mapping(node, deep=deep)
        return result


def safe_load(text: str) -> Any:
    """``yaml.safe_load`` with :class:`UniqueKeyLoader` (what ``yaml.load`` does with it)."""
    loader = UniqueKeyLoader(text)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()
