"""The packages' dependencies point one way: no import cycle; drivers and simrig never reach up.

Read from the sources with ``ast`` (tests/support/imports.py), so an import hidden in a
function counts as much as one at the top.
"""

from __future__ import annotations

from pathlib import Path

from support.imports import PACKAGES, cycles, import_graph, imported_names

LAYERS = {"drivers": set(), "simrig": {"drivers"}, "tsmd": {"drivers", "simrig"}}
"""What each package may import besides itself: drivers is hardware, simrig simulates it."""


def test_no_module_of_tsmd_drivers_or_simrig_is_part_of_an_import_cycle() -> None:
    found = cycles(import_graph())
    assert found == [], "import cycles: " + "; ".join(" <-> ".join(c) for c in found)


def test_drivers_imports_neither_tsmd_nor_simrig_and_simrig_does_not_import_tsmd() -> None:
    graph = import_graph()
    wrong = sorted(f"{module} imports {target}"
                   for module, targets in graph.items() for target in targets
                   if (top := target.split(".")[0]) != module.split(".")[0]
                   and top not in LAYERS[module.split(".")[0]])
    assert wrong == []


def test_no_module_outside_tsmd_bench_imports_tsmd_bench() -> None:
    """The daemon (data sheet included) runs without the benchmarks: they sit on top of it."""
    graph = import_graph()
    wrong = sorted(f"{module} imports {target}" for module, targets in graph.items()
                   if module.startswith("tsmd.") and not module.startswith("tsmd.bench")
                   and module != "tsmd.commands.bench"
                   for target in targets if target.startswith("tsmd.bench"))
    assert wrong == []


def test_the_graph_covers_every_package() -> None:
    graph = import_graph()
    assert {m.split(".")[0] for m in graph} == set(PACKAGES)
    assert "simrig.plant" in graph["simrig.rig"]


def test_an_import_inside_a_function_counts_and_one_for_type_checking_does_not(
        tmp_path: Path) -> None:
    source = tmp_path / "mod.py"
    source.write_text("from typing import TYPE_CHECKING\n"
                      "if TYPE_CHECKING:\n    import tsmd.profile\n"
                      "def f():\n    from tsmd import replay\n    from . import sibling\n")
    names = imported_names(source, "tsmd.mod")
    assert {"tsmd.replay", "tsmd.sibling"} <= names
    assert "tsmd.profile" not in names


def test_a_cycle_through_three_modules_is_found() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == [["a", "b", "c"]]


def test_a_chain_without_a_way_back_is_no_cycle() -> None:
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []
