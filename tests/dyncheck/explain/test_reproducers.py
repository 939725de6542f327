"""Every engine defect's reproducer (``dyncheck explain NAME --reproducer FILE``) is a
standalone script: it imports only its engine, numpy and the standard library, runs in a
fresh virtual environment that holds only the distributions of those imports and what they
require (nothing of dyncheck, no other engine; run isolated, ``-I``), prints the expected and the
observed value and exits 1 while the defect stands — so that the pinned
releases' defects are asserted here, and a release that fixes one fails this test when it
lands (the expected values are the physics': a closed form, or the engine's own finite
differences)."""

from __future__ import annotations

import ast
import importlib.metadata
import subprocess
import sys
import venv
from pathlib import Path

import pytest
from packaging.requirements import Requirement

from dyncheck.__main__ import main
from dyncheck.adapters import REGISTRY
from dyncheck.explain.catalogue import DEMOS
from dyncheck.explain.reproducers import REPRODUCERS


def _closure(package: str) -> list[importlib.metadata.Distribution]:
    """The installed distribution ``package`` and every one it requires on this platform
    (its extras' requirements left out), each once."""
    seen: dict[str, importlib.metadata.Distribution] = {}
    todo = [package]
    while todo:
        name = todo.pop()
        dist = importlib.metadata.distribution(name)
        key = dist.metadata["Name"].lower().replace("_", "-")
        if key in seen:
            continue
        seen[key] = dist
        for text in dist.requires or ():
            need = Requirement(text)
            if need.marker is None or need.marker.evaluate({"extra": ""}):
                todo.append(need.name)
    return list(seen.values())


def _fresh_python(packages: frozenset[str], folder: Path) -> Path:
    """A new virtual environment (no pip, no system site) holding only ``packages`` and their
    requirements: each of their installed files linked into its site-packages (their
    ``.pth`` files with them, so that a package laid out as cmeel's is found as pip would
    install it). Its interpreter."""
    venv.EnvBuilder(with_pip=False, symlinks=True).create(folder)
    python = folder / "bin" / "python"
    site = Path(subprocess.run(
        [str(python), "-I", "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True, text=True, check=True).stdout.strip())
    for dist in {d.metadata["Name"]: d for p in sorted(packages) for d in _closure(p)}.values():
        root = Path(str(dist.locate_file("")))
        for entry in dist.files or ():
            if entry.parts[0] == ".." or "__pycache__" in entry.parts:
                continue
            target = site / entry
            if not target.exists() and (root / entry).exists():
                target.parent.mkdir(parents=True, exist_ok=True)
                target.symlink_to(root / entry)
    return python


@pytest.fixture(scope="module")
def fresh(tmp_path_factory):
    """(engine, top-level modules) → the interpreter of a fresh venv with only the engine's
    distribution (its registration's) and those that provide the modules (one per pair,
    made on first use)."""
    made: dict[tuple[str, frozenset[str]], Path] = {}
    providers = importlib.metadata.packages_distributions()

    def python(engine: str, imports: frozenset[str]) -> Path:
        if (engine, imports) not in made:
            wanted = {REGISTRY[engine].package,
                      *(d for m in imports for d in providers.get(m, ()))}
            made[engine, imports] = _fresh_python(frozenset(wanted),
                                                  tmp_path_factory.mktemp("venv"))
        return made[engine, imports]

    return python


def test_a_fresh_venv_holds_only_the_engine_and_what_it_requires(fresh):
    """The environment the reproducers run in: PyBullet (which requires nothing) imports
    there, numpy and dyncheck do not — the isolation is real, not the test's interpreter."""
    python = fresh("pybullet", frozenset())
    probe = ("import importlib.util as u; "
             "print([m for m in ('pybullet', 'numpy', 'dyncheck', 'mujoco') if u.find_spec(m)])")
    done = subprocess.run([str(python), "-I", "-c", probe], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == "['pybullet']"


def _imported(script: str) -> set[str]:
    tree = ast.parse(script)
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module.split(".")[0])
    return found


@pytest.mark.parametrize("name", list(REPRODUCERS))
def test_a_reproducer_is_standalone_and_fails_while_its_defect_stands(name, tmp_path, capsys,
                                                                     fresh):
    found = REPRODUCERS[name]
    assert name in DEMOS and found.engine in REGISTRY  # a catalogue entry, an engine's
    path = tmp_path / "reproducer.py"
    assert main(["explain", name, "--reproducer", str(path)]) == 0
    assert str(path) in capsys.readouterr().out
    script = path.read_text(encoding="utf-8")
    others = _imported(script) - set(sys.stdlib_module_names)
    assert others == set(found.imports), others  # its engine and numpy, nothing of dyncheck
    assert "dyncheck" not in script
    python = fresh(found.engine, found.imports)
    done = subprocess.run([str(python), "-I", str(path)], capture_output=True, text=True,
                          cwd=tmp_path, timeout=600)
    assert done.returncode == 1, done.stdout + done.stderr  # the defect of the pinned release
    assert "Traceback" not in done.stderr, done.stderr  # its own exit, not an exception's
    assert "expected" in done.stdout and "observed" in done.stdout


def test_a_name_without_a_reproducer_is_one_line_naming_those_with_one(tmp_path, capsys):
    """A convention an engine documents (the quaternion order) has no reproducer: exit 2
    before anything is written, the names that have one listed."""
    path = tmp_path / "reproducer.py"
    assert main(["explain", "quaternion-storage-order", "--reproducer", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--reproducer" in err[0] and "pinocchio-mjcf-options" in err[0]
    assert not path.exists()
