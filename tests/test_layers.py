"""The layers' import rules, read from the source (every import statement, module level or
inside a function): ``reference/`` uses numpy, scipy, sympy and the standard library only —
never an engine; ``adapters/`` never sees the reference (nor the comparison layer);
``cases/`` holds models, not engines; only the comparison layer (``dyncheck/``) sees both."""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
THIRD_PARTY = {"numpy", "scipy", "sympy"}
ENGINES = {"mujoco", "pinocchio", "pydrake", "mujoco_warp", "jax"}


def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def _modules(folder: str) -> list[Path]:
    return sorted((ROOT / folder).glob("*.py"))


def _top(name: str) -> str:
    return name.split(".")[0]


@pytest.mark.parametrize("path", _modules("reference"), ids=lambda p: p.name)
def test_reference_imports_numpy_scipy_sympy_only(path):
    for name in _imports(path):
        top = _top(name)
        if name.startswith("dyncheck."):
            assert name.startswith("dyncheck.reference"), f"{path.name} imports {name}"
        else:
            assert top in THIRD_PARTY | sys.stdlib_module_names, f"{path.name} imports {name}"


@pytest.mark.parametrize("path", _modules("adapters"), ids=lambda p: p.name)
def test_adapters_never_import_the_reference_or_the_comparison_layer(path):
    for name in _imports(path):
        if name.startswith("dyncheck."):
            allowed = ("dyncheck.adapters", "dyncheck.cases", "dyncheck.errors",
                       "dyncheck.vocabulary", "dyncheck.settings", "dyncheck.regular_files")
            assert name.startswith(allowed), f"{path.name} imports {name}"


@pytest.mark.parametrize("path", _modules("cases"), ids=lambda p: p.name)
def test_cases_import_no_engine_no_adapter_no_reference(path):
    for name in _imports(path):
        assert _top(name) not in ENGINES, f"{path.name} imports {name}"
        if name.startswith("dyncheck."):
            assert name.startswith(("dyncheck.cases", "dyncheck.errors",
                                    "dyncheck.vocabulary")), f"{path.name} imports {name}"


@pytest.mark.parametrize("path", _modules("dyncheck/errata"), ids=lambda p: p.name)
def test_errata_checks_are_engine_free(path):
    """The book's formulas are checked by derivation alone: sympy (pandas for the page's
    table), no engine, no reference, nothing of dyncheck but the errata package and the
    errors at the bottom of the import graph."""
    for name in _imports(path):
        top = _top(name)
        if name.startswith("dyncheck"):
            assert name.startswith(("dyncheck.errata", "dyncheck.errors")), (
                f"{path.name} imports {name}")
        else:
            assert top in {"sympy", "pandas"} | sys.stdlib_module_names, (
                f"{path.name} imports {name}")


def test_the_rule_reader_sees_function_level_imports(tmp_path):
    """The check can fail: an import hidden in a function body is found."""
    module = tmp_path / "m.py"
    module.write_text("def f():\n    import mujoco\n    from dyncheck.reference import rigid\n")
    assert _imports(module) == {"mujoco", "dyncheck.reference"}


def _layer(module: str) -> str | None:
    """The layer of a dyncheck module name: errors, the vocabulary, the settings and the
    opener of untrusted files (the bottom: they import nothing of dyncheck but one
    another), reference, cases, adapters, or
    the comparison layer (everything else under dyncheck/)."""
    if not module.startswith("dyncheck"):
        return None
    parts = module.split(".")
    if len(parts) == 1:
        return "comparison"
    if parts[1] in ("errors", "vocabulary", "settings", "regular_files"):
        return "errors"
    return parts[1] if parts[1] in ("reference", "cases", "adapters") else "comparison"


def _layer_of_path(path: Path) -> str:
    rel = path.relative_to(ROOT).parts
    if rel[0] in ("reference", "cases", "adapters"):
        return rel[0]
    bottom = path.name in ("errors.py", "vocabulary.py", "settings.py",
                           "regular_files.py") and len(rel) == 2
    return "errors" if bottom else "comparison"


def test_no_cycle_between_layers():
    """The folders' import graph is acyclic: errors → (reference, cases) → adapters →
    comparison, with every import (module level or in a function) counted."""
    edges: dict[str, set[str]] = {}
    for folder in ("reference", "cases", "adapters", "dyncheck"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            src = _layer_of_path(path)
            for name in _imports(path):
                dst = _layer(name)
                if dst is not None and dst != src:
                    edges.setdefault(src, set()).add(dst)
    order: list[str] = []
    state: dict[str, int] = {}

    def visit(node: str, trail: tuple[str, ...]) -> None:
        if state.get(node) == 1:
            raise AssertionError(f"import cycle between layers: {' -> '.join((*trail, node))}")
        if state.get(node) == 2:
            return
        state[node] = 1
        for nxt in sorted(edges.get(node, ())):
            visit(nxt, (*trail, node))
        state[node] = 2
        order.append(node)

    for node in sorted(edges):
        visit(node, ())
    assert order.index("errors") < order.index("comparison")
    assert "comparison" not in edges.get("adapters", set())


def _package_files() -> list[Path]:
    """Every module of the package: dyncheck/ and the top-level folders it maps."""
    return sorted(p for folder in ("dyncheck", "adapters", "cases", "reference")
                  for p in (ROOT / folder).rglob("*.py"))


def _private_definitions() -> dict[str, set[str]]:
    """Every private name (``_x``) a module of the package defines — functions, classes,
    methods, module and class attributes — by module."""
    defined: dict[str, set[str]] = {}
    for path in _package_files():
        names = defined.setdefault(path.as_posix(), set())
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                names.add(node.name)
            elif isinstance(node, ast.Assign | ast.AnnAssign):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for target in targets:
                    for leaf in ast.walk(target):
                        if isinstance(leaf, ast.Name):
                            names.add(leaf.id)
                        elif isinstance(leaf, ast.Attribute):
                            names.add(leaf.attr)
        defined[path.as_posix()] = {n for n in names if _private(n)}
    return defined


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def test_no_module_reaches_into_another_modules_private_names():
    """#43: a private name (``_x``) is used only in the module that defines it — imported by
    no other, read on no other's object. Another module needing it is a sign it is public API
    (rename it) or that the work belongs in its home. Third-party privates (JAX's, MJX's) are
    not ours to police here."""
    defined = _private_definitions()
    ours = set().union(*defined.values())
    reaches = []
    for path in _package_files():
        mine, where = defined[path.as_posix()], path.relative_to(ROOT)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("dyncheck"):
                reaches += [f"{where}:{node.lineno}: imports {a.name}" for a in node.names
                            if _private(a.name)]
            elif (isinstance(node, ast.Attribute) and _private(node.attr)
                  and node.attr in ours and node.attr not in mine
                  and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
                reaches.append(f"{where}:{node.lineno}: reads .{node.attr}")
    assert not reaches, "\n".join(reaches)


def test_no_module_asks_an_implementation_for_its_engine_by_duck_typing():
    """#43: an implementation's engine is ``Implementation.adapter`` (None on the book's
    side) and an engine's facts are attributes of ``CaseEngine`` with defaults: a chain
    ``getattr(getattr(impl, "adapter", None), ...)`` hides both from the type checker."""
    chains = [f"{path.relative_to(ROOT)}:{n}" for path in _package_files()
              for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
              if "getattr(getattr(" in line]
    assert not chains, chains


NOT_ENGINES = {
    ("dyncheck/__main__.py", "impl"): "an argparse namespace: commands differ in their flags",
    ("dyncheck/commands/options.py", "device"): "an argparse namespace",
    ("dyncheck/commands/options.py", "out"): "an argparse namespace",
    ("dyncheck/commands/options.py", "no_cache"): "an argparse namespace",
    ("dyncheck/implementations.py", "softness"): "the reference's general method of a case",
    ("dyncheck/studies/references.py", "softness"): "the reference's general method",
    ("dyncheck/studies/drift.py", "field_potential"): "the reference's general method",
    ("dyncheck/studies/drift.py", "inertia"): "a case (rigid cases hold one)",
    ("dyncheck/studies/controlled.py", "polynomial_degree"): "the reference's general method",
    ("dyncheck/studies/study.py", "polynomial_degree"): "the reference's general method",
    ("dyncheck/cache/store.py", "__name__"): "a type named in a message",
    ("dyncheck/workers.py", "sched_getaffinity"): "the platform's os module",
    ("dyncheck/workers.py", "_processes"): "concurrent.futures' pool",
}
"""The comparison layer's ``hasattr``/``getattr`` by a written name, each on what is not an
engine (with why)."""


def test_no_engine_is_asked_what_it_can_do_by_its_attributes():
    """#62: an engine's capabilities are class facts (``ModelEngine.offers``, the adapter's
    attributes with defaults), read as such: the comparison layer asks no object whether it
    has an attribute of a written name, but for :data:`NOT_ENGINES` (an engine's own modules
    under adapters/ may probe their engine's API across releases)."""
    found = set()
    for path in sorted((ROOT / "dyncheck").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id in ("hasattr", "getattr") and len(node.args) >= 2
                    and isinstance(node.args[1], ast.Constant)):
                found.add((path.relative_to(ROOT).as_posix(), node.args[1].value))
    assert found <= set(NOT_ENGINES), sorted(found - set(NOT_ENGINES))
    assert set(NOT_ENGINES) <= found, f"gone, take off NOT_ENGINES: {set(NOT_ENGINES) - found}"


MAX_LINES = 500
"""#43: a module a reader holds in mind at once; a longer one is split where its parts have
names of their own (the commands from the command line, the Cayley frame from the checks on
it)."""


@pytest.mark.parametrize("path", _package_files(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_module_of_the_package_is_over_500_lines(path):
    lines = path.read_text(encoding="utf-8").count("\n")
    assert lines <= MAX_LINES, f"{path.relative_to(ROOT)}: {lines} lines"


LITERAL_ELSEWHERE = {
    ("adapters/integrators.py", "failed"): "scipy's solve_ivp status, not a verdict",
    ("dyncheck/report/figures.py", "trajectory"): "a figure's file name, not a quantity",
    ("dyncheck/check/dynamics.py", "mass_matrix"): "a field of Dynamics, not the quantity",
    ("adapters/model_tree.py", "euler"): "Orientation.EULER: Example 9's angles in q",
    ("adapters/formats/mjcf_copy.py", "euler"): "MJCF's body attribute euler=, an orientation",
    ("adapters/formats/frames.py", "euler"): "MJCF's orientation attribute euler=",
}
"""Strings spelled like a member of the vocabulary that mean something else."""


def test_no_quantity_verdict_or_integrator_is_written_as_a_string_outside_the_vocabulary():
    """#43: the closed sets have one home (dyncheck/vocabulary.py); a quantity, a verdict or
    an integrator written as a string literal elsewhere is a second definition that can drift
    (``diff`` and the report's tables once ranked ``skipped`` in two different orders)."""
    import io
    import tokenize

    from dyncheck.vocabulary import Integrator, Quantity, Verdict

    words = {m.value for e in (Quantity, Verdict, Integrator) for m in e}
    found = []
    for path in _package_files():
        where = path.relative_to(ROOT).as_posix()
        if where == "dyncheck/vocabulary.py":
            continue
        text = path.read_text(encoding="utf-8")
        for token in tokenize.generate_tokens(io.StringIO(text).readline):
            value = token.string[1:-1]
            if (token.type == tokenize.STRING and token.string[:1] in "\"'"
                    and token.string[-1:] == token.string[:1] and value in words
                    and (where, value) not in LITERAL_ELSEWHERE):
                found.append(f"{where}:{token.start[0]}: {token.string}")
    assert not found, "\n".join(found)


def _module_level(body: list[ast.stmt]):
    """The statements a module runs when imported (inside top-level ``if``/``try``/``with``
    blocks too; not function or class bodies)."""
    for node in body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            continue
        yield node
        for name in ("body", "orelse", "finalbody"):
            yield from _module_level(getattr(node, name, []))
        for handler in getattr(node, "handlers", []):
            yield from _module_level(handler.body)


def _root(node: ast.expr) -> str | None:
    while isinstance(node, ast.Attribute | ast.Subscript | ast.Call):
        node = node.func if isinstance(node, ast.Call) else node.value
    return node.id if isinstance(node, ast.Name) else None


REGISTERING = {"dyncheck/errata/frenet.py": "check"}
"""Module-level calls that register a definition in the module's own table (a decorator
applied by hand), by module: not a side effect on anything imported."""


@pytest.mark.parametrize("path", _package_files(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_importing_a_module_changes_nothing_outside_it(path):
    """#43: importing a module sets no attribute of anything it imported (``Adapter.derive =
    …``, ``wp.config.log_level = …``), writes no item of another module's table or of
    ``os.environ``, and calls nothing for its effect on another module (``jax.config.update``,
    ``wp.init()``): engines' and libraries' process-wide settings are made where the engine is
    first used. Allowed: assigning to the module's own names and tables, calling its own
    functions (a self-check), and :data:`REGISTERING`."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    own = {t.id for node in _module_level(tree.body)
           if isinstance(node, ast.Assign | ast.AnnAssign)
           for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
           for t in ([target] if isinstance(target, ast.Name) else
                     target.elts if isinstance(target, ast.Tuple) else [])
           if isinstance(t, ast.Name)}
    own |= {n.name for n in tree.body
            if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)}
    where = path.relative_to(ROOT).as_posix()
    found = []
    for node in _module_level(tree.body):
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, ast.AugAssign | ast.AnnAssign) else []
        for target in targets:
            if isinstance(target, ast.Attribute | ast.Subscript) and _root(target) not in own:
                found.append(f"{where}:{node.lineno}: sets {ast.unparse(target)}")
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Call):
            root = _root(node.value)
            if root not in own and REGISTERING.get(where) != root:
                found.append(f"{where}:{node.lineno}: calls {ast.unparse(node.value)[:60]}")
    assert not found, "\n".join(found)


def test_the_rule_on_import_effects_sees_a_patch(tmp_path):
    """The reader of :func:`test_importing_a_module_changes_nothing_outside_it` finds the two
    kinds it forbids (a patched class, a library's setting) and lets a module's own table
    be filled."""
    source = ("import jax\nfrom x import Adapter\nTABLE = {}\nTABLE['a'] = 1\n"
              "Adapter.derive = staticmethod(len)\nif True:\n    jax.config.update('k', 1)\n")
    tree = ast.parse(source)
    kinds = [type(n).__name__ for n in _module_level(tree.body)]
    assert kinds.count("Assign") == 3 and kinds.count("Expr") == 1
    assert _root(ast.parse("jax.config.update('k', 1)").body[0].value) == "jax"  # type: ignore[attr-defined]


def test_a_fresh_interpreter_importing_every_module_finds_nothing_patched():
    """#43: in a fresh interpreter, importing every module of the package (those whose
    engines are installed) leaves the adapter base class without a plugged-in cache, JAX
    without a compilation cache or 64-bit mode, and Warp uninitialised at its default log
    level — the settings each engine makes when first used."""
    import subprocess

    script = """
import importlib, pkgutil, sys
count = 0
for top in ("dyncheck", "dyncheck.adapters", "dyncheck.cases", "dyncheck.reference"):
    package = importlib.import_module(top)
    for info in pkgutil.walk_packages(package.__path__, top + "."):
        if info.name.endswith("__main__"):
            continue
        try:
            importlib.import_module(info.name)
            count += 1
        except ImportError:
            pass
print("modules", count)
from dyncheck.adapters.base import ModelEngine
print("adapter", sorted(k for k in ("derive", "lambdify") if k in vars(ModelEngine)))
if "jax" in sys.modules:
    import jax
    print("jax", jax.config.jax_compilation_cache_dir, jax.config.jax_enable_x64)
if "warp" in sys.modules:
    import warp as wp
    from warp._src import context
    print("warp", wp.config.log_level, context.runtime is None)
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300, cwd=ROOT)
    assert done.returncode == 0, done.stderr[-2000:]
    lines = dict(line.split(" ", 1) for line in done.stdout.splitlines())
    assert int(lines["modules"]) >= len(_package_files()) // 2  # mapped folders included
    assert lines["adapter"] == "[]"
    if "jax" in lines:
        assert lines["jax"] == "None False"
    if "warp" in lines:
        assert lines["warp"] == "20 True"  # logging.INFO, Warp's default
