"""The registry is the one place that names an engine (#43, #47): an engine's name written as
a string literal anywhere in the package but its own modules and ``adapters/__init__.py`` is
a second home for what the registration says (the conventions catalogue, which teaches
about the engines by name, aside). Engines registered since the rule (Newton,
PyBullet) have none; the older ones have the counts below, which may only go down (lower the
number with the change that removes one: the test fails on a count that shrank too, so the
table stays true)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from dyncheck.adapters import BUILT_IN, REGISTRY

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ("dyncheck", "adapters", "cases", "reference")
TEACHING = ("dyncheck/explain/",)
"""The conventions catalogue and its demonstrations name the engines they teach about (and
the engines a demonstration needs): not a second home of a registration."""
FORMATS = ("adapters/formats/files.py",)
"""The file formats' module: MJCF's root element is ``<mujoco>``, a format's word, not an
engine's name."""
LEGACY: dict[str, int] = {}
"""Engine-name literals allowed outside the engine's modules (its registration's among them)
and the teaching texts: none (5a550eb had 61 in 11 files, #62's review 28 more; the version
matrix's engines and the bench's raw loops are now the registrations' and the adapters'
own)."""


def _own(name: str) -> set[str]:
    """The engine's modules: its folder's (registration, loader and the rest), its adapter's
    and loader's where they live elsewhere (an installed engine's), and the registrations of
    its ports, which name the engine they port (``Registration.ports``)."""
    reg = REGISTRY[name]
    modules = {m for m in ((reg.model or "").split(":")[0],) if m}
    files = {m.removeprefix("dyncheck.").replace(".", "/") + ".py" for m in modules}
    for module in BUILT_IN:
        folder = Path(module.__file__ or "").parent.relative_to(ROOT).as_posix()
        if name in module.REGISTRATIONS:
            files |= {p.relative_to(ROOT).as_posix() for p in (ROOT / folder).rglob("*.py")}
        elif any(r.ports == name for r in module.REGISTRATIONS.values()):
            files.add(f"{folder}/__init__.py")
    return files


def _literals(name: str, root: Path = ROOT) -> list[str]:
    pattern = re.compile(r"""(["'])""" + re.escape(name) + r"""\1""")
    own = _own(name)
    found = []
    for folder in PACKAGE:
        for path in sorted((root / folder).rglob("*.py")):
            relative = path.relative_to(root).as_posix()
            if relative not in own and not relative.startswith((*TEACHING, *FORMATS)):
                found += [relative] * len(pattern.findall(path.read_text(encoding="utf-8")))
    return found


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_an_engine_is_named_only_in_its_modules_and_the_registry(name):
    found = _literals(name)
    assert len(found) == LEGACY.get(name, 0), (
        f"{name!r} written in {sorted(set(found))} ({len(found)} times; "
        f"allowed {LEGACY.get(name, 0)}): read it from adapters.REGISTRY instead")


def test_the_rule_catches_a_name_written_elsewhere(tmp_path):
    """The scan itself: a module that writes "newton" is found, its own module is not."""
    for folder in PACKAGE:
        (tmp_path / folder).mkdir()
    (tmp_path / "dyncheck" / "leak.py").write_text('ENGINE = "newton"\n')
    (tmp_path / "adapters" / "newton").mkdir()
    (tmp_path / "adapters" / "newton" / "model.py").write_text('ENGINE = "newton"\n')
    assert _literals("newton", tmp_path) == ["dyncheck/leak.py"]


ENGINE_PACKAGES = ("mujoco", "mujoco_warp", "pinocchio", "pydrake", "jax", "warp", "newton",
                   "pybullet", "sympy")
"""The engines' import packages (sympy's too: sympy.physics.mechanics is an engine here)."""

BLOCKED_IMPORT = """
import importlib.abc, sys
BLOCKED = {blocked!r}
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name in BLOCKED or name.startswith(tuple(b + "." for b in BLOCKED)):
            raise ImportError("blocked: " + name)
sys.meta_path.insert(0, Block())
import dyncheck.adapters as a
print(" ".join(sorted(a.REGISTRY)))
"""


@pytest.mark.parametrize("blocked", [ENGINE_PACKAGES, ("dyncheck.adapters.formats",),
                                     (*ENGINE_PACKAGES, "dyncheck.adapters.formats")],
                         ids=["engines", "formats", "both"])
def test_every_registration_imports_with_no_engine_and_no_model_format(blocked):
    """#76: the registrations (the facts needed before any engine) import with every engine
    package and the MJCF/URDF toolkit refused at import: the registry is then whole."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", BLOCKED_IMPORT.format(blocked=blocked)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == sorted(REGISTRY)


def _imports(path: Path) -> set[str]:
    import ast

    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            found.add("." * node.level + (node.module or ""))
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    return found


REGISTRATION_NEEDS = {"__future__", "dyncheck.adapters.registration", "dyncheck.vocabulary"}
"""All a registration module may import: the record, the vocabulary of integrators."""


@pytest.mark.parametrize("module", BUILT_IN, ids=lambda m: m.__name__.rsplit(".", 1)[-1])
def test_a_registration_imports_no_other_engine_folder(module):
    """#76: an engine folder's ``__init__`` holds its registrations and imports only the
    record (read from its source: importing it would already have imported the others)."""
    assert module.__file__ is not None and module.__file__.endswith("__init__.py")
    assert _imports(Path(module.__file__)) <= REGISTRATION_NEEDS


def test_the_registration_rule_catches_an_import_of_another_engine(tmp_path):
    """The rule can fail: a registration importing MuJoCo's folder is found."""
    (tmp_path / "__init__.py").write_text(
        "from dyncheck.adapters.mujoco import MUJOCO\n"
        "from dyncheck.adapters.registration import A\n")
    assert not _imports(tmp_path / "__init__.py") <= REGISTRATION_NEEDS
