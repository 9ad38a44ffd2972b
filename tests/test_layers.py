"""Layering, checked statically (ast) over every module of every package, imports inside
functions included:

* no library (``contact_core``, ``fmu_src``, ``harmonic_balance``) imports the
  application package ``damper``;
* ``contact_core``, the bottom layer, never imports ``harmonic_balance``;
* no two modules import each other, and no longer import cycle (imports under
  ``if TYPE_CHECKING:`` never run and do not count for cycles; they do for the layers).

docs/architecture.md has the layers.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LIBRARIES = ("contact_core", "fmu_src", "harmonic_balance")
APPLICATION = "damper"
PACKAGES = LIBRARIES + (APPLICATION,)


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules() -> dict[str, Path]:
    """Every module of the packages: dotted name -> file."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            if "headers" not in path.parts:
                out[_module_name(path)] = path
    return out


def _resolve(name: str, known: dict) -> str | None:
    """The deepest known module that ``name`` (a dotted import target) refers to."""
    while name:
        if name in known:
            return name
        name = name.rpartition(".")[0]
    return None


def _is_type_checking(node) -> bool:
    t = node.test
    return isinstance(node, ast.If) and (getattr(t, "id", None) == "TYPE_CHECKING"
                                         or getattr(t, "attr", None) == "TYPE_CHECKING")


def _import_nodes(tree, runtime_only: bool):
    """Import nodes anywhere in ``tree`` (function bodies included); with ``runtime_only``,
    not those under ``if TYPE_CHECKING:`` (annotations only, never executed)."""
    todo = [tree]
    while todo:
        node = todo.pop()
        if runtime_only and isinstance(node, ast.If) and _is_type_checking(node):
            todo.extend(node.orelse)
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom, ast.Call)):
            yield node
        todo.extend(ast.iter_child_nodes(node))


def imports_of(name: str, path: Path, known: dict, runtime_only: bool = False) -> set[str]:
    """Modules of the packages that module ``name`` imports, anywhere in its file."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in _import_nodes(ast.parse(path.read_text(), str(path)), runtime_only):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            # "from pkg import sub" imports the submodule pkg.sub when there is one
            targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in known else mod for a in node.names]
        elif (getattr(node.func, "attr", getattr(node.func, "id", "")) == "import_module"
              and node.args and isinstance(node.args[0], ast.Constant)):
            targets = [node.args[0].value]
        for t in targets:
            r = _resolve(t, known)
            if r is not None and r != name:
                found.add(r)
    return found


@pytest.fixture(scope="module")
def graph():
    """Every import, type-checking ones included (for the layer rules)."""
    known = modules()
    return {name: imports_of(name, path, known) for name, path in known.items()}


@pytest.fixture(scope="module")
def runtime_graph():
    """Imports that run (for cycles: an ``if TYPE_CHECKING:`` import is never executed)."""
    known = modules()
    return {name: imports_of(name, path, known, runtime_only=True) for name, path in known.items()}


def _top(name: str) -> str:
    return name.split(".")[0]


def test_the_analysis_sees_the_packages(graph):
    # sanity: the scan finds what we know is there (a broken scan must not pass silently)
    assert {_top(m) for m in graph} == set(PACKAGES)
    assert "contact_core.curve" in graph["fmu_src.element"] or any(
        _top(t) == "contact_core" for t in graph["harmonic_balance.model"])
    assert "damper.cache" in graph["damper.run.graph"]


def test_no_library_imports_the_application(graph):
    bad = sorted(f"{m} -> {t}" for m, ts in graph.items() if _top(m) in LIBRARIES
                 for t in ts if _top(t) == APPLICATION)
    assert not bad, "libraries must not import the application package: " + "; ".join(bad)


def test_contact_core_does_not_import_harmonic_balance(graph):
    bad = sorted(f"{m} -> {t}" for m, ts in graph.items() if _top(m) == "contact_core"
                 for t in ts if _top(t) == "harmonic_balance")
    assert not bad, "contact_core is the bottom layer: " + "; ".join(bad)


def test_no_two_modules_import_each_other(runtime_graph):
    graph = runtime_graph
    pairs = sorted({tuple(sorted((a, b))) for a, ts in graph.items() for b in ts if a in graph.get(b, ())})
    assert not pairs, "modules importing each other: " + "; ".join(f"{a} <-> {b}" for a, b in pairs)


def test_the_checks_catch_violations(tmp_path):
    # the same analysis on a made-up package: a function-level import cycle and an upward import
    pkg = tmp_path / "lib"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from . import c\n"
                              "def f():\n    from . import b\n    import damper.cli\n")
    (pkg / "c.py").write_text("")
    (pkg / "b.py").write_text("from .a import f\n")
    known = {"lib": pkg / "__init__.py", "lib.a": pkg / "a.py", "lib.b": pkg / "b.py", "lib.c": pkg / "c.py",
             "damper.cli": ROOT / "damper" / "cli" / "__init__.py"}
    assert imports_of("lib.a", pkg / "a.py", known) == {"lib.b", "lib.c", "damper.cli"}
    assert imports_of("lib.a", pkg / "a.py", known, runtime_only=True) == {"lib.b", "damper.cli"}
    assert imports_of("lib.b", pkg / "b.py", known) == {"lib.a"}


def test_no_import_cycles_through_more_modules(runtime_graph):
    graph = runtime_graph

    # stricter than pairs: a -> b -> c -> a is the same knot
    def reach(start):
        seen, todo = set(), list(graph[start])
        while todo:
            m = todo.pop()
            if m not in seen:
                seen.add(m)
                todo.extend(graph.get(m, ()))
        return seen

    knots = sorted(m for m in graph if m in reach(m))
    assert not knots, "modules on an import cycle: " + ", ".join(knots)
