"""Functions a reader can hold, read from the package's source: none over
:data:`MOST_LINES` lines but the ones listed in :data:`LONG` (a ratchet: each may only shrink,
and leaves the list once it fits), and no more functions taking five or more positional
arguments than :data:`MANY_POSITIONAL` (a ratchet too: past four, arguments are named)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MOST_LINES = 80

LONG: dict[str, int] = {}
"""The functions over :data:`MOST_LINES` lines, with their length (a ratchet: none since #62
split the last two, ``reference/tree.py:_at_chunk`` and ``sympy_mechanics._derive``)."""

MANY_POSITIONAL = 85
"""How many functions took five or more positional arguments (``self`` not counted) when the
ratchet was set."""


Definition = ast.FunctionDef | ast.AsyncFunctionDef


def functions(root: Path = ROOT) -> list[tuple[str, Definition]]:
    """(``path:name``, the definition) for every function and method of the package (a
    name may be defined more than once in a file: methods of two classes, nested helpers)."""
    out = []
    for folder in ("dyncheck", "adapters", "reference", "cases"):
        for path in sorted((root / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, Definition):
                    out.append((f"{path.relative_to(root).as_posix()}:{node.name}", node))
    return out


def longest() -> dict[str, int]:
    """``path:name`` → the length of its longest definition."""
    out: dict[str, int] = {}
    for name, node in functions():
        out[name] = max(out.get(name, 0), lines(node))
    return out


def lines(node: ast.AST) -> int:
    return int(node.end_lineno or node.lineno) - node.lineno + 1  # type: ignore[attr-defined]


def positional(node: Definition) -> int:
    return sum(a.arg not in ("self", "cls") for a in node.args.posonlyargs + node.args.args)


def test_no_function_is_longer_than_its_budget():
    found = longest()
    over = {name: n for name, n in found.items() if n > LONG.get(name, MOST_LINES)}
    assert not over, f"over budget ({MOST_LINES} lines, or its ratchet in LONG): {over}"


def test_the_ratchet_lists_only_functions_still_over_the_budget():
    found = longest()
    fits = {name: found.get(name) for name in LONG if found.get(name, 0) <= MOST_LINES}
    assert not fits, f"fits the budget now (or is gone): take it off LONG: {fits}"
    shrunk = {name: found[name] for name in LONG if found[name] < LONG[name]}
    assert not shrunk, f"shorter now: lower its entry in LONG to the new length: {shrunk}"


def test_functions_of_many_positional_arguments_only_decrease():
    many = [name for name, node in functions() if positional(node) >= 5]
    assert len(many) <= MANY_POSITIONAL, (
        f"{len(many)} functions take five or more positional arguments (ratchet "
        f"{MANY_POSITIONAL}): make the new ones' arguments keyword-only (`*,`)")
    assert len(many) == MANY_POSITIONAL, (
        f"{len(many)} now: lower MANY_POSITIONAL to it")


def test_the_readers_measure_what_they_say(tmp_path):
    """The checks can fail: a 3-line function of six positional arguments, one of them
    ``self``, is measured as 3 lines and 5 positional arguments."""
    (tmp_path / "dyncheck").mkdir()
    (tmp_path / "dyncheck" / "m.py").write_text(
        "class A:\n    def f(self, a, b, c, d, e, *, k=1):\n        x = 1\n        return x\n")
    ((name, node),) = functions(tmp_path)
    assert name == "dyncheck/m.py:f"
    assert (lines(node), positional(node)) == (3, 5)
