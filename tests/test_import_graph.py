"""The package's import graph, module by module, read from the source: every import
statement counts — module level, inside a function, under ``TYPE_CHECKING`` — since each is
a dependency a reader must hold. No file imports itself through others (no cycle), and the
graph's height (its longest import chain, each module drawn above all it imports) is held by
a ratchet that only goes down (issue #62's goal: 9 floors)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = {"dyncheck": "dyncheck", "reference": "dyncheck.reference",
           "adapters": "dyncheck.adapters", "cases": "dyncheck.cases"}

HEIGHT = 9
"""The longest import chain among the modules under ``dyncheck/`` today (ratchet: lower it
when a change lowers it; #62's goal of 9 is met)."""
WHOLE_HEIGHT = 11
"""The longest import chain over the whole package as installed — ``adapters``, ``cases`` and
``reference`` are ``dyncheck.*`` too (ratchet: #76's goal of 11 is met; 17 when it was
filed)."""


def modules(root: Path = ROOT, folders: dict[str, str] = FOLDERS) -> dict[str, Path]:
    """Module name → file, for every module of the package."""
    out = {}
    for folder, package in folders.items():
        for path in sorted((root / folder).rglob("*.py")):
            parts = [package, *path.relative_to(root / folder).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = path
    return out


def _named(found: dict[str, Path], name: str) -> str | None:
    """The module ``name`` is, or the package module holding it (an attribute's import)."""
    parts = name.split(".")
    while parts and ".".join(parts) not in found:
        parts.pop()
    return ".".join(parts) or None


def graph(found: dict[str, Path]) -> dict[str, set[str]]:
    """Module → the package modules it imports (``from p import m`` is an edge to the
    submodule ``p.m`` where one exists, to ``p`` otherwise)."""
    edges: dict[str, set[str]] = {}
    for module, path in found.items():
        package = path.name == "__init__.py"
        out: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = module.split(".")[: len(module.split(".")) - node.level
                                                + (1 if package else 0)]
                    base = ".".join(parts + ([node.module] if node.module else []))
                names = [f"{base}.{a.name}" if f"{base}.{a.name}" in found else base
                         for a in node.names]
            out |= {m for m in map(lambda n: _named(found, n), names) if m and m != module}
        edges[module] = out
    return edges


def cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """One import cycle (its modules in order, the first repeated at the end), or None."""
    state: dict[str, int] = {}
    trail: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        trail.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                return [*trail[trail.index(nxt):], nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        trail.pop()
        state[node] = 2
        return None

    for node in sorted(edges):
        if node not in state and (found := visit(node)):
            return found
    return None


def height(edges: dict[str, set[str]], among: set[str]) -> tuple[int, list[str]]:
    """The longest import chain among ``among`` (an acyclic graph): its length in modules,
    and the chain."""
    memo: dict[str, tuple[int, list[str]]] = {}

    def up(node: str) -> tuple[int, list[str]]:
        if node not in memo:
            below = [up(n) for n in edges[node] if n in among]
            best = max(below, key=lambda x: x[0], default=(0, []))
            memo[node] = (best[0] + 1, [node, *best[1]])
        return memo[node]

    return max((up(n) for n in sorted(among)), key=lambda x: x[0])


def test_no_module_imports_itself_through_others():
    found = cycle(graph(modules()))
    assert found is None, "import cycle: " + " -> ".join(found or [])


def test_the_graph_reader_finds_a_cycle_hidden_in_a_function(tmp_path):
    """The check can fail: a cycle closed by a function-level relative import is found."""
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text("")
    (tmp_path / "pkg" / "a.py").write_text("from pkg import b\n")
    (tmp_path / "pkg" / "b.py").write_text("def f():\n    from . import a\n")
    (tmp_path / "pkg" / "c.py").write_text("from pkg.b import f\n")
    edges = graph(modules(tmp_path, {"pkg": "pkg"}))
    assert edges["pkg.c"] == {"pkg.b"}
    assert cycle(edges) == ["pkg.a", "pkg.b", "pkg.a"]


def test_the_import_graph_is_no_higher_than_its_ratchet():
    edges = graph(modules())
    inner = {m for m, p in modules().items() if p.relative_to(ROOT).parts[0] == "dyncheck"}
    floors, chain = height(edges, inner)
    assert floors <= HEIGHT, f"{floors} floors (ratchet {HEIGHT}): " + " -> ".join(chain)


def test_the_whole_packages_graph_is_no_higher_than_its_ratchet():
    floors, chain = height(graph(modules()), set(modules()))
    assert floors <= WHOLE_HEIGHT, f"{floors} floors (ratchet {WHOLE_HEIGHT}): " + \
        " -> ".join(chain)
