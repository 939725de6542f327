"""The cache's store (dyncheck/cache/store.py) on a hostile cache folder: nothing placed there by
anyone else is ever run, and what it holds costs a recomputation, never a wrong result.

Expected values: the results computed without any cache (the ``compute`` functions), and a
marker file that a malicious entry's code would create, which must stay absent.
"""

from __future__ import annotations

import os
import pickle
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from dyncheck.cache import store
from dyncheck.settings import NO_CACHE


class _Runs:
    """A pickle payload that, when loaded, runs ``touch marker`` (what an attacker writes)."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):
        return (os.system, (f"touch {self.marker}",))


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache folder and a key outside it, both private to the test."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("DYNCHECK_CACHE", str(folder))
    monkeypatch.setenv(store.KEY, str(tmp_path / "config" / "cache-key"))
    monkeypatch.delenv(NO_CACHE, raising=False)
    store._key.cache_clear()
    yield folder
    store._key.cache_clear()


def _stored(folder: Path, value: object) -> Path:
    path = folder / "derivations" / "x" / "entry.pickle"
    assert store.cached(path, lambda: value) == (value, False)
    assert store.cached(path, lambda: "recomputed") == (value, True)
    return path


def _hostile(marker: Path) -> dict[str, bytes]:
    """Bytes an attacker can place at an entry's path, without the key."""
    evil = pickle.dumps(_Runs(marker))
    return {
        "plain malicious pickle": evil,
        "malicious pickle behind the magic and a forged tag": store.MAGIC + b"\0" * 32 + evil,
        "truncated": store.MAGIC + b"\1" * 5,
        "empty": b"",
        "wrong magic": b"PK\x03\x04" + evil,
    }


@pytest.mark.parametrize("kind", list(_hostile(Path("m"))))
def test_a_hostile_file_runs_nothing_and_is_recomputed(cache, tmp_path, capsys, kind):
    marker = tmp_path / "marker"
    path = _stored(cache, {"a": 1.5})
    path.write_bytes(_hostile(marker)[kind])
    assert store.cached(path, lambda: {"a": 1.5}) == ({"a": 1.5}, False)
    assert not marker.exists()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "computed afresh" in err and "Traceback" not in err
    assert store.cached(path, lambda: "again") == ({"a": 1.5}, True)  # replaced, authentic


def test_an_authentic_entry_moved_to_another_name_is_refused(cache, capsys):
    path = _stored(cache, 42)
    other = path.with_name("other.pickle")
    other.write_bytes(path.read_bytes())
    assert store.cached(other, lambda: 7) == (7, False)
    assert "not authentic" in capsys.readouterr().err


def test_an_authentic_entry_naming_a_builtin_that_runs_code_is_refused(cache, tmp_path, capsys):
    """Defence in depth: even with the key (a leaked one), loading resolves no builtin that
    runs code — the entry is written as dyncheck writes, its payload a malicious pickle."""
    marker = tmp_path / "marker"
    path = cache / "derivations" / "x" / "entry.pickle"
    store.write_entry(path, pickle.dumps(_Runs(marker)))
    assert store.cached(path, lambda: 3) == (3, False)
    assert not marker.exists()
    assert "does not decode" in capsys.readouterr().err


def test_an_entry_of_the_wrong_type_is_recomputed(cache, capsys):
    path = _stored(cache, "a string")
    assert store.cached(path, lambda: (1, 2), expect=tuple) == ((1, 2), False)
    assert "not the expected tuple" in capsys.readouterr().err


def test_a_folder_symlink_or_fifo_where_a_file_should_be(cache, tmp_path, capsys):
    """Each costs a recomputation: a folder is not a file, a symlink out is never followed
    (/etc/passwd stays unread, the link itself is replaced), a FIFO never blocks."""
    base = cache / "derivations" / "x"
    base.mkdir(parents=True)
    (base / "folder.pickle").mkdir()
    (base / "link.pickle").symlink_to("/etc/passwd")
    os.mkfifo(base / "fifo.pickle")
    for name in ("folder", "link", "fifo"):
        assert store.cached(base / f"{name}.pickle", lambda n=name: n) == (name, False)
    assert (base / "link.pickle").is_file() and not (base / "link.pickle").is_symlink()
    assert store.cached(base / "link.pickle", lambda: "again") == ("link", True)
    assert Path("/etc/passwd").read_bytes()[:4] != store.MAGIC[:4]


def test_nothing_is_written_through_a_folder_that_leads_outside(cache, tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    cache.mkdir()
    (cache / "derivations").symlink_to(outside)
    assert store.cached(cache / "derivations" / "e.pickle", lambda: 1) == (1, False)
    assert list(outside.iterdir()) == []


def test_folders_and_key_are_private(cache, tmp_path):
    _stored(cache, 1)
    for folder in (cache, cache / "derivations", cache / "derivations" / "x"):
        assert stat.S_IMODE(folder.stat().st_mode) == 0o700, folder
    key = tmp_path / "config" / "cache-key"
    assert stat.S_IMODE(key.stat().st_mode) == 0o600
    assert stat.S_IMODE(key.parent.stat().st_mode) == 0o700
    entry = next((cache / "derivations" / "x").iterdir())
    assert stat.S_IMODE(entry.stat().st_mode) == 0o600


@pytest.mark.parametrize("problem", ["inside the cache folder", "readable by others",
                                     "wrong size"])
def test_a_key_that_is_not_safe_turns_the_cache_off(cache, tmp_path, monkeypatch, capsys,
                                                    problem):
    key = cache / "cache-key" if problem == "inside the cache folder" else tmp_path / "k"
    key.parent.mkdir(parents=True, exist_ok=True)
    key.write_bytes(b"k" * (5 if problem == "wrong size" else store.KEY_BYTES))
    os.chmod(key, 0o644 if problem == "readable by others" else 0o600)
    monkeypatch.setenv(store.KEY, str(key))
    store._key.cache_clear()
    calls = []
    for _ in range(2):
        assert store.cached(cache / "d" / "e.pickle", lambda: calls.append(1) or 5)[0] == 5
    assert len(calls) == 2  # nothing read back: nothing was stored
    assert not (cache / "d").exists()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cache: off" in err


def test_a_hostile_cache_folder_leaves_a_run_unchanged(tmp_path):
    """End to end, in a fresh interpreter as a user meets it: a run fills the cache, every
    entry is replaced by a malicious pickle, and the next run gives the same CSV bytes as the
    first, runs nothing, and says what it recomputed in one line per entry."""
    marker = tmp_path / "marker"
    env = {**os.environ, "DYNCHECK_CACHE": str(tmp_path / "cache"),
           store.KEY: str(tmp_path / "key")}
    env.pop(NO_CACHE, None)

    def run(out: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "dyncheck", "run", "simple_pendulum", "--impl", "reference",
             "--impl", "mujoco", "--jobs", "1", "--out", str(tmp_path / out)],
            env=env, capture_output=True, text=True, timeout=300, check=False,
        )

    first = run("first")
    assert first.returncode == 0, first.stderr
    entries = [p for p in (tmp_path / "cache").rglob("*") if p.is_file()]
    assert entries
    evil = pickle.dumps(_Runs(marker))
    for p in entries:
        p.write_bytes(evil)
    second = run("second")
    assert second.returncode == 0, second.stderr
    assert not marker.exists()
    assert "Traceback" not in second.stderr
    stored = [p for p in entries  # (the compiled-code folders' manifests are not entries)
              if p.relative_to(tmp_path / "cache").parts[0] != "compiled"]
    assert second.stderr.count("not a dyncheck cache entry") >= len(stored) - 1
    for name in ("discrepancies.csv", "convergence.csv"):
        assert (tmp_path / "first" / name).read_bytes() == (tmp_path / "second" / name).read_bytes()
