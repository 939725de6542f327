"""Every engine defect's reproducer (``dyncheck explain NAME --reproducer FILE``) is a
standalone script: it imports only its engine, numpy and the standard library, runs in an
isolated interpreter (``python -I``: no user site, no PYTHONPATH, not the checkout), prints the
expected and the observed value and exits 1 while the defect stands — so that the pinned
releases' defects are asserted here, and a release that fixes one fails this test when it
lands (the expected values are the physics': a closed form, or the engine's own finite
differences)."""

from __future__ import annotations

import ast
import subprocess
import sys

import pytest

from dyncheck.adapters import REGISTRY
from dyncheck.catalogue import DEMOS
from dyncheck.cli import main
from dyncheck.explain.reproducers import REPRODUCERS


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
def test_a_reproducer_is_standalone_and_fails_while_its_defect_stands(name, tmp_path, capsys):
    found = REPRODUCERS[name]
    assert name in DEMOS and found.engine in REGISTRY  # a catalogue entry, an engine's
    path = tmp_path / "reproducer.py"
    assert main(["explain", name, "--reproducer", str(path)]) == 0
    assert str(path) in capsys.readouterr().out
    script = path.read_text(encoding="utf-8")
    others = _imported(script) - set(sys.stdlib_module_names)
    assert others == set(found.imports), others  # its engine and numpy, nothing of dyncheck
    assert "dyncheck" not in script
    done = subprocess.run([sys.executable, "-I", str(path)], capture_output=True, text=True,
                          cwd=tmp_path, timeout=600)
    assert done.returncode == 1, done.stdout + done.stderr  # the defect of the pinned release
    assert "expected" in done.stdout and "observed" in done.stdout


def test_a_name_without_a_reproducer_is_one_line_naming_those_with_one(tmp_path, capsys):
    """A convention an engine documents (the quaternion order) has no reproducer: exit 2
    before anything is written, the names that have one listed."""
    path = tmp_path / "reproducer.py"
    assert main(["explain", "quaternion-storage-order", "--reproducer", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--reproducer" in err[0] and "pinocchio-mjcf-options" in err[0]
    assert not path.exists()
