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
    modules = {m for m in (reg.module, (reg.model or "").split(":")[0]) if m}
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
