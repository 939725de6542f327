"""A command's settings (``--no-cache``, ``--device``) reach every unit of work as an argument
(:mod:`dyncheck.settings`, :func:`dyncheck.workers.run_units`), whatever runs it — this
process, a pool of spawned or forked workers, a dask cluster — and nothing below the command
line reads them from the environment. Expected values: the settings the test put in force."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from dyncheck.cache.store import DiskStore
from dyncheck.errors import InvalidInput
from dyncheck.reference import derivations
from dyncheck.settings import DEVICE, NO_CACHE, Settings, current, from_environment
from dyncheck.workers import run_units, settled

ROOT = Path(__file__).resolve().parents[2]


def _seen() -> tuple[Settings, bool]:
    """What a unit of work sees: the settings in force, and whether the reference has a
    store."""
    return current(), derivations.STORE.get() is not None


@pytest.mark.parametrize("where", ["here", "fork", "spawn", "dask"])
@pytest.mark.parametrize("settings", [Settings(cache=False, device="cuda:1"), Settings()])
def test_the_command_s_settings_reach_every_unit(where, settings, monkeypatch):
    if where == "dask":
        pytest.importorskip("distributed")
    if where in ("fork", "spawn"):
        monkeypatch.setattr("dyncheck.workers.start_method", lambda: where)
    monkeypatch.delenv(NO_CACHE, raising=False)  # nothing to inherit but the argument
    monkeypatch.delenv(DEVICE, raising=False)
    units = [(f"unit {i}", _seen, ()) for i in range(2)]
    jobs = 1 if where == "here" else 2
    with settled(settings):
        seen = run_units(units, jobs=jobs, dask="local" if where == "dask" else None)
    assert seen == [(settings, settings.cache)] * 2


def test_no_cache_hands_the_reference_no_store():
    with settled(Settings(cache=False)):
        assert derivations.STORE.get() is None
        with settled(Settings()):
            assert isinstance(derivations.STORE.get(), DiskStore)
        assert derivations.STORE.get() is None


@pytest.mark.parametrize(("env", "expected"), [
    ({}, Settings()),
    ({NO_CACHE: "1"}, Settings(cache=False)),
    ({NO_CACHE: "0", DEVICE: "cuda:0"}, Settings(device="cuda:0")),
])
def test_the_environment_gives_the_options_defaults(env, expected, monkeypatch):
    monkeypatch.delenv(NO_CACHE, raising=False)
    monkeypatch.delenv(DEVICE, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert from_environment() == expected
    assert from_environment(no_cache=True).cache is False


def test_a_bogus_device_in_the_environment_names_it(monkeypatch):
    monkeypatch.setenv(DEVICE, "gpu9")
    with pytest.raises(InvalidInput, match="DYNCHECK_DEVICE must be cpu, cuda or cuda:N"):
        from_environment()


def test_only_the_command_line_reads_the_settings_from_the_environment():
    """No module but :mod:`dyncheck.settings` names the two variables: the rest reads
    :func:`~dyncheck.settings.current` (a planted reader would be found: the rule reads
    every string constant of every module)."""
    readers = []
    for folder in ("dyncheck", "adapters", "reference", "cases"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            if path.name == "settings.py" and path.parent.name == "dyncheck":
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Constant) and node.value in (NO_CACHE, DEVICE):
                    readers.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert readers == []
