"""Bench caches are keyed by the code that fills them (tsmd.bench.cache_key)."""

from __future__ import annotations

from pathlib import Path

from tsmd.bench.cache_key import code_key, keyed_cache, source_files


def _tree(root: Path) -> None:
    for rel, text in {"tsmd/calibration/run.py": "A = 1\n", "tsmd/bench/online.py": "B = 1\n",
                      "simrig/plant.py": "C = 1\n"}.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


def _key(root: Path) -> str:
    files = source_files(root, ("tsmd", "simrig"), ("tsmd/bench",))
    return code_key(files, root)


def test_the_key_is_the_same_for_the_same_code(tmp_path: Path) -> None:
    _tree(tmp_path)
    assert _key(tmp_path) == _key(tmp_path)


def test_a_change_in_the_calibration_code_changes_the_key(tmp_path: Path) -> None:
    _tree(tmp_path)
    before = _key(tmp_path)
    (tmp_path / "tsmd/calibration/run.py").write_text("A = 2\n")
    assert _key(tmp_path) != before


def test_a_change_in_the_plants_changes_the_key(tmp_path: Path) -> None:
    _tree(tmp_path)
    before = _key(tmp_path)
    (tmp_path / "simrig/plant.py").write_text("C = 2\n")
    assert _key(tmp_path) != before


def test_a_module_no_profile_passes_through_keeps_the_key(tmp_path: Path) -> None:
    _tree(tmp_path)
    before = _key(tmp_path)
    (tmp_path / "tsmd/bench/online.py").write_text("B = 2\n")
    assert _key(tmp_path) == before


def test_the_cache_of_this_code_is_a_subdirectory_of_the_one_given(tmp_path: Path) -> None:
    keyed = keyed_cache(tmp_path)
    assert keyed.parent == tmp_path
    assert keyed.name.startswith("code-")
