"""The cache of measured demonstrations (dyncheck/cache/measured.py): a second `dyncheck
explain` reads back what the first measured, and anything that could change a number — an
engine's version, a file of dyncheck, --no-cache, a failure — measures afresh.

Expected values: the entry measured live by :func:`catalogue.explain` (the engines run), which
the cached path must reproduce exactly."""

from __future__ import annotations

import pytest

from dyncheck.__main__ import main
from dyncheck.cache import measured as measured_cache
from dyncheck.explain import catalogue

NAME = "hinge-axis-sign"


@pytest.fixture
def counted(monkeypatch, empty_cache):
    """An empty cache folder and the demonstration NAME wrapped to count its runs."""
    demo, origin = catalogue.DEMOS[NAME]
    runs = []

    def counting():
        runs.append(1)
        return demo()

    monkeypatch.setitem(catalogue.DEMOS, NAME, (counting, origin))
    return runs


def test_a_second_explain_reads_the_entry_back_without_running_it(counted):
    (live,) = catalogue.explain(NAME)
    assert len(counted) == 1
    first, read = catalogue.explain_cached(NAME)
    assert (first, read, len(counted)) == ([live], 0, 2)
    again, read = catalogue.explain_cached(NAME)
    assert (again, read, len(counted)) == ([live], 1, 2)


def test_no_cache_measures_every_time(counted, no_cache):
    for _ in range(2):
        assert catalogue.explain_cached(NAME)[1] == 0
    assert len(counted) == 2


def test_a_failed_entry_is_never_stored(counted, monkeypatch):
    def broken():
        counted.append(1)
        raise RuntimeError("engine API changed")

    monkeypatch.setitem(catalogue.DEMOS, NAME, (broken, catalogue.DEMOS[NAME][1]))
    for _ in range(2):
        (entry,), read = catalogue.explain_cached(NAME)
        assert entry.failed == "RuntimeError: engine API changed" and read == 0
    assert len(counted) == 2


def test_another_engine_version_measures_afresh(counted, monkeypatch):
    catalogue.explain_cached(NAME)
    installed = measured_cache._installed
    monkeypatch.setattr(
        measured_cache, "_installed",
        lambda p: "99.0.0" if p == "mujoco" else installed(p),
    )
    measured_cache.fingerprint.cache_clear()
    assert catalogue.explain_cached(NAME)[1] == 0
    assert len(counted) == 2


def test_an_edited_file_of_dyncheck_changes_the_fingerprint(tmp_path, monkeypatch):
    root = tmp_path / "pkg"
    root.mkdir()
    (root / "demo.py").write_text("X = 1\n")
    monkeypatch.setattr(measured_cache, "_source_roots", lambda: [root])
    measured_cache.fingerprint.cache_clear()
    before = measured_cache.fingerprint()
    (root / "demo.py").write_text("X = 2\n")
    measured_cache.fingerprint.cache_clear()
    assert measured_cache.fingerprint() != before
    measured_cache.fingerprint.cache_clear()


def test_an_unreadable_file_is_measured_again_and_replaced(counted):
    catalogue.explain_cached(NAME)
    path = measured_cache.path_for("explain", NAME)
    path.write_bytes(b"half a pickle")
    assert catalogue.explain_cached(NAME)[1] == 0
    assert catalogue.explain_cached(NAME)[1] == 1
    assert len(counted) == 2


def test_the_command_says_what_it_read_back(counted, capsys):
    assert main(["explain", NAME]) == 0
    first = capsys.readouterr().out
    assert "read from the cache" not in first
    assert main(["explain", NAME]) == 0
    again = capsys.readouterr().out
    assert again.startswith(first.rstrip("\n"))
    assert "1 of 1 measured by an earlier `dyncheck explain`" in again
    assert main(["explain", NAME, "--no-cache"]) == 0
    assert capsys.readouterr().out == first
    assert len(counted) == 2


def test_a_second_run_reads_its_conventions_back_with_their_engines(counted, monkeypatch):
    """A run's catalogue units go through the same cache: the second run's entries and the
    engine versions they name are the first's, without running the demonstration again."""
    import dyncheck.run as run_module
    from dyncheck.cases import get_case

    monkeypatch.setattr(catalogue, "DEMOS", {NAME: catalogue.DEMOS[NAME]})
    runs = [
        run_module.run([get_case("simple_pendulum")], ["reference"],
                       conventions=catalogue.units(["reference"]))
        for _ in range(2)
    ]
    assert len(counted) == 1
    assert runs[0].conventions == runs[1].conventions == catalogue.explain(NAME)
    # the demonstration's engine (hinge-axis-sign maps the compound pendulum into Pinocchio)
    assert runs[0].engines == runs[1].engines and "pinocchio" in runs[1].engines


def test_another_cpu_measures_afresh(counted, monkeypatch):
    """Float32 code compiled for another CPU rounds differently (two CPUs' MJX runs differ):
    a cache folder shared between machines must not hand one CPU's numbers to another."""
    catalogue.explain_cached(NAME)
    monkeypatch.setattr(measured_cache, "_cpu", lambda: "model name : another\nflags : sse2")
    measured_cache.fingerprint.cache_clear()
    assert catalogue.explain_cached(NAME)[1] == 0
    assert len(counted) == 2
