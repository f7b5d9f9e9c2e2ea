"""Scene files a hostile or careless user might hand in: each is refused with a SceneError, quickly."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from footfall.errors import SceneError
from footfall.terrain import builtin_scene, load_scene, scene_to_yaml
from footfall.terrain.scene import MAX_SCENE_BYTES

BOMB = "\n".join(
    [
        'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]',
        *(
            f"{k}: &{k} [{', '.join([f'*{p}'] * 9)}]"
            for p, k in zip("abcdefgh", "bcdefghi", strict=True)
        ),
        "name: *i",
        "description: *i",
    ]
)


def test_alias_bomb_is_refused_before_it_expands() -> None:
    with pytest.raises(SceneError, match="alias"):
        load_scene(BOMB + "\n")


def test_aliases_of_a_sane_size_still_load() -> None:
    text = scene_to_yaml(builtin_scene("flat"))
    text = text.replace("start:", "extra_anchor: &v [0.0, 0.0]\nstart:", 1)
    # an unknown key is refused by the schema, not by the size check
    with pytest.raises(SceneError, match="extra_anchor"):
        load_scene(text)


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_a_device_is_not_read() -> None:
    with pytest.raises(SceneError, match="regular file"):
        load_scene(Path("/dev/zero"))


def test_a_folder_is_not_a_scene(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match="regular file"):
        load_scene(tmp_path)


def test_an_oversized_file_is_refused_without_reading_it(tmp_path: Path) -> None:
    big = tmp_path / "big.yaml"
    with big.open("wb") as fh:
        fh.truncate(MAX_SCENE_BYTES + 1)  # sparse: costs no disk
    with pytest.raises(SceneError, match="bytes"):
        load_scene(big)


def test_a_fifo_is_not_opened(tmp_path: Path) -> None:
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    fifo = tmp_path / "scene.yaml"
    os.mkfifo(fifo)
    with pytest.raises(SceneError, match="regular file"):
        load_scene(fifo)  # opening a FIFO with no writer would block forever


def test_non_utf8_bytes_name_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_bytes(b"name: \xff\xfe\n")
    with pytest.raises(SceneError, match="UTF-8"):
        load_scene(bad)


def test_too_many_regions_are_refused_before_they_are_built() -> None:
    import yaml

    from footfall.terrain.terrain import MAX_REGIONS

    data = yaml.safe_load(scene_to_yaml(builtin_scene("flat")))
    square = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]]
    data["regions"] = [
        {"name": f"r{i}", "height": 0.0, "vertices": square} for i in range(MAX_REGIONS + 1)
    ]
    with pytest.raises(SceneError, match="regions"):
        load_scene(yaml.safe_dump(data))


def test_python_tags_run_nothing(tmp_path: Path) -> None:
    marker = tmp_path / "pwned"
    text = f'name: !!python/object/apply:os.system ["touch {marker}"]\n'
    with pytest.raises(SceneError, match="constructor"):
        load_scene(text)
    assert not marker.exists()
