"""Type hints checked (mypy, configured in pyproject.toml) on the installed layout: the
top-level ``reference/``, ``adapters/``, ``cases/`` are the subpackages ``dyncheck.reference``
… (package-dir), which mypy cannot follow through the editable install's import hook, so the
test builds a folder of links with that layout and checks ``-p dyncheck``.

A ratchet, not a pass: the errors that remain are counted per file in
``tests/mypy-baseline.json``; a file with more errors than its count fails (a new error), and
one with fewer fails too until its count is lowered (so the baseline stays true).
``DYNCHECK_WRITE_PAGES=1`` rewrites it."""

from __future__ import annotations

import json
import os
import re
from collections import Counter
from pathlib import Path

import pytest

mypy_api = pytest.importorskip("mypy.api", reason="mypy (extra `test`) is not installed")

ROOT = Path(__file__).resolve().parents[1]
BASELINE = ROOT / "tests" / "mypy-baseline.json"
MAPPED = ("reference", "adapters", "cases")
ERROR = re.compile(r"^(?P<path>[^:]+\.py):\d+: error: ")


def _layout(tmp: Path) -> Path:
    pkg = tmp / "dyncheck"
    pkg.mkdir(parents=True)
    for entry in (ROOT / "dyncheck").iterdir():
        if entry.name != "__pycache__":
            (pkg / entry.name).symlink_to(entry)
    for name in MAPPED:
        (pkg / name).symlink_to(ROOT / name)
    return tmp


def _source(path: str) -> str:
    """The repository path of a module mypy names relative to the layout (``dyncheck/…``)."""
    parts = Path(path).parts[1:]
    return "/".join(parts if parts[0] in MAPPED else ("dyncheck", *parts))


@pytest.mark.slow
def test_type_errors_do_not_grow(tmp_path, monkeypatch):
    layout = _layout(tmp_path / "layout")
    monkeypatch.setenv("MYPYPATH", str(layout))
    monkeypatch.chdir(layout)
    out, err, status = mypy_api.run(["--config-file", str(ROOT / "pyproject.toml"),
                                     "--cache-dir", str(tmp_path / "cache"),
                                     "--no-error-summary", "-p", "dyncheck"])
    assert status in (0, 1), f"mypy could not run: {err or out}"
    lines = [m for m in (ERROR.match(line) for line in out.splitlines()) if m]
    found = Counter(_source(m["path"]) for m in lines)
    if os.environ.get("DYNCHECK_WRITE_PAGES"):
        BASELINE.write_text(json.dumps(dict(sorted(found.items())), indent=1) + "\n")
    baseline = json.loads(BASELINE.read_text())
    grown = {f: (n, baseline.get(f, 0)) for f, n in found.items() if n > baseline.get(f, 0)}
    shrunk = {f: (found.get(f, 0), n) for f, n in baseline.items() if found.get(f, 0) < n}
    assert not grown, "new type errors (file: now, baseline):\n" + "\n".join(
        line for line in out.splitlines() if any(f in line for f in grown)) + f"\n{grown}"
    assert not shrunk, f"fewer type errors than the baseline — lower it: {shrunk}"
