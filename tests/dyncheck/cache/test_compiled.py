"""The compiled-code caches (dyncheck/cache/compiled.py): an entry the authenticated manifest
does not vouch for is deleted before an engine sees the folder — swapped, changed, planted,
a link — and JAX, given the checked folder, compiles such an entry again instead of running
it. Expected values: the files the test wrote and what a jitted function computes."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dyncheck.adapters import compiled
from dyncheck.cache import compiled as compiled_caches
from dyncheck.settings import Settings

SECRET = b"k" * 32


def _entries(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*")
            if p.is_file() and not p.is_symlink() and p.name != compiled_caches.MANIFEST}


def _filled(tmp_path: Path) -> Path:
    folder = tmp_path / "jax"
    (folder / "sub").mkdir(parents=True)
    for name, body in (("a", b"code a"), ("b", b"code b"), ("sub/c", b"code c")):
        (folder / name).write_bytes(body)
    compiled_caches.sign(folder, SECRET)
    return folder


def test_vouched_entries_are_kept(tmp_path):
    folder = _filled(tmp_path)
    assert compiled_caches.verify(folder, SECRET) == []
    assert _entries(folder) == {"a": b"code a", "b": b"code b", "sub/c": b"code c"}


def test_swapped_changed_and_planted_entries_are_deleted(tmp_path):
    folder = _filled(tmp_path)
    a, b = (folder / "a").read_bytes(), (folder / "b").read_bytes()
    (folder / "a").write_bytes(b)  # two entries swapped
    (folder / "b").write_bytes(a)
    (folder / "sub" / "c").write_bytes(b"code c, changed")
    (folder / "planted").write_bytes(b"someone else's code")
    outside = tmp_path / "outside"
    outside.write_bytes(b"not ours")
    (folder / "link").symlink_to(outside)
    removed = compiled_caches.verify(folder, SECRET)
    assert sorted(removed) == ["a", "b", "link", "planted", "sub/c"]
    assert _entries(folder) == {}
    assert outside.read_bytes() == b"not ours"  # a link is deleted, never followed


@pytest.mark.parametrize("damage", ["missing", "forged", "other key"])
def test_without_an_authentic_manifest_nothing_is_trusted(tmp_path, damage):
    folder = _filled(tmp_path)
    manifest = folder / compiled_caches.MANIFEST
    if damage == "missing":
        manifest.unlink()
    elif damage == "forged":
        manifest.write_bytes(manifest.read_bytes().replace(b'"a"', b'"x"'))
    else:
        compiled_caches.sign(folder, b"o" * 32)
    assert sorted(compiled_caches.verify(folder, SECRET)) == ["a", "b", "sub/c"]


def test_a_manifest_that_is_a_fifo_is_no_manifest_and_never_blocks(tmp_path):
    """#81: a FIFO planted where the manifest lives hung every command that checked the
    folder (reading it waits for a writer forever). It is read as no manifest: nothing
    trusted, every entry deleted, at once."""
    import threading

    folder = _filled(tmp_path)
    manifest = folder / compiled_caches.MANIFEST
    manifest.unlink()
    os.mkfifo(manifest)
    removed: list[str] = []
    worker = threading.Thread(
        target=lambda: removed.extend(compiled_caches.verify(folder, SECRET)), daemon=True)
    worker.start()
    worker.join(10)
    if worker.is_alive():  # the old answer: blocked on the FIFO; let it go, then fail
        with open(os.open(manifest, os.O_WRONLY | os.O_NONBLOCK), "wb"):
            pass
        pytest.fail("reading a FIFO manifest blocked")
    assert sorted(removed) == ["a", "b", "sub/c"]
    compiled_caches.sign(folder, SECRET)  # the FIFO replaced by a signed manifest
    assert manifest.is_file() and compiled_caches.verify(folder, SECRET) == []


def test_a_lock_that_is_a_fifo_is_not_taken(tmp_path, monkeypatch):
    """A FIFO planted where the folder's lock lives is no lock of ours: the command goes on
    without the folder (compiling afresh, as when another command holds it), at once."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("DYNCHECK_CACHE_KEY", str(tmp_path / "key"))
    folder = tmp_path / "cache" / "compiled"
    (folder / "jax").mkdir(parents=True, mode=0o700)
    folder.chmod(0o700)
    os.mkfifo(folder / ".lock")
    with compiled_caches.held(Settings()) as settings:
        assert settings.compiled is None


def test_a_command_checks_the_folder_and_signs_it_when_it_ends(tmp_path, monkeypatch):
    """A planted entry is gone before the command's engines see the folder; what the
    command's engines write is vouched for by the next command; --no-cache uses none."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("DYNCHECK_CACHE_KEY", str(tmp_path / "key"))
    planted = tmp_path / "cache" / "compiled" / "jax" / "planted"
    planted.parent.mkdir(parents=True, mode=0o700)
    planted.write_bytes(b"code")
    with compiled_caches.held(Settings()) as settings:
        assert settings.compiled == str(tmp_path / "cache" / "compiled")
        assert not planted.exists()
        assert compiled.folder(settings, "jax") == planted.parent
        (planted.parent / "written").write_bytes(b"this command's kernel")
    with compiled_caches.held(Settings()) as again:
        assert (planted.parent / "written").exists()  # signed: vouched for
        assert again.compiled == settings.compiled
    with compiled_caches.held(Settings(cache=False)) as off:
        assert off.compiled is None
    assert compiled.folder(Settings(cache=False, compiled=settings.compiled), "jax") is None


def test_a_second_command_at_once_leaves_the_first_one_s_folder_alone(tmp_path, monkeypatch):
    """Another dyncheck holds the folder (its lock, shared): this one neither checks it —
    which would delete the other's entries not yet signed — nor uses it."""
    import fcntl

    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("DYNCHECK_CACHE_KEY", str(tmp_path / "key"))
    fresh = tmp_path / "cache" / "compiled" / "warp" / "kernel.o"
    fresh.parent.mkdir(parents=True, mode=0o700)
    (tmp_path / "cache" / "compiled" / "jax").mkdir(mode=0o700)
    fresh.write_bytes(b"the other command's kernel, not signed yet")
    fd = os.open(tmp_path / "cache" / "compiled" / ".lock", os.O_RDWR | os.O_CREAT, 0o600)
    fcntl.flock(fd, fcntl.LOCK_SH)  # (as the other command holds it)
    try:
        with compiled_caches.held(Settings()) as settings:
            assert settings.compiled is None
        assert fresh.exists()
    finally:
        os.close(fd)


def test_a_folder_others_can_write_is_not_used(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("DYNCHECK_CACHE_KEY", str(tmp_path / "key"))
    shared = tmp_path / "cache" / "compiled" / "warp"
    shared.mkdir(parents=True)
    os.chmod(shared, 0o777)
    with compiled_caches.held(Settings()) as settings:
        assert settings.compiled is None
    assert compiled.warp_folder(Settings()) != shared  # a temporary one instead


JAX_RUN = """
import sys, jax, jax.numpy as jnp
jax.config.update("jax_compilation_cache_dir", sys.argv[1])
jax.config.update("jax_persistent_cache_min_compile_time_secs", 0)
jax.config.update("jax_persistent_cache_min_entry_size_bytes", -1)
x = jnp.arange(4.0)
print(jax.jit(lambda y: y * 2 + 1)(x).tolist(), jax.jit(lambda y: jnp.sin(y) - 3)(x).tolist())
"""


@pytest.mark.skipif(importlib.util.find_spec("jax") is None, reason="needs the 'mjx' extra")
def test_swapped_jax_entries_are_compiled_again_not_run(tmp_path):
    """Two functions compiled into JAX's persistent cache; their entries swapped; the check
    deletes both, and the next process compiles them again (their files are back) and
    computes the right values."""
    folder = tmp_path / "jax"
    folder.mkdir(mode=0o700)

    def run() -> str:
        done = subprocess.run([sys.executable, "-c", JAX_RUN, str(folder)],
                              capture_output=True, text=True, timeout=300,
                              env={**os.environ, "JAX_PLATFORMS": "cpu"})
        assert done.returncode == 0, done.stderr[-2000:]
        return done.stdout.strip()

    expected = run()
    compiled_caches.sign(folder, SECRET)
    entries = [p for p in folder.rglob("*") if p.is_file() and p.name != ".manifest"
               and p.stat().st_size > 100]
    assert len(entries) >= 2, [p.name for p in folder.rglob("*")]
    first, second = entries[:2]
    a, b = first.read_bytes(), second.read_bytes()
    first.write_bytes(b)
    second.write_bytes(a)
    removed = compiled_caches.verify(folder, SECRET)
    assert {first.relative_to(folder).as_posix(), second.relative_to(folder).as_posix()} \
        <= set(removed)
    assert run() == expected
    assert first.exists() and second.exists()  # compiled again


AFTER_COMMAND = """
import jax, jax.numpy as jnp
from dyncheck.cache import compiled as compiled_caches
from dyncheck.adapters.mjx import port as mjx_
from dyncheck.settings import Settings
from dyncheck.workers import settled

with compiled_caches.held(Settings()) as settings, settled(settings):
    mjx_._compile_cache()
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", -1)
    print(jax.jit(lambda y: y * 2 + 1)(jnp.arange(4.0)).tolist())
print(jax.jit(lambda y: jnp.cos(y) - 5)(jnp.arange(4.0)).tolist())  # a library call after it
with compiled_caches.held(Settings()):
    pass
"""


@pytest.mark.skipif(importlib.util.find_spec("jax") is None, reason="needs the 'mjx' extra")
def test_jax_writes_nothing_into_the_folder_once_the_command_ends(tmp_path):
    """JAX keeps the cache folder it first opened whatever its setting says later: the
    command's end points it away, so a function compiled after it (a library call, the next
    command of a test session) leaves no entry that the next command finds unsigned and
    deletes (CI's stop 69: "compiled code not vouched for" before a usage error)."""
    env = {**os.environ, "JAX_PLATFORMS": "cpu", "DYNCHECK_CACHE": str(tmp_path / "cache"),
           "DYNCHECK_CACHE_KEY": str(tmp_path / "key")}
    done = subprocess.run([sys.executable, "-c", AFTER_COMMAND], capture_output=True,
                          text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    first, second = (json.loads(line) for line in done.stdout.split("\n")[:2])
    assert first == [1.0, 3.0, 5.0, 7.0]
    np.testing.assert_allclose(second, np.cos(range(4)) - 5, rtol=1e-6)  # (float32)
    assert "not vouched" not in done.stderr, done.stderr
    assert _entries(tmp_path / "cache" / "compiled" / "jax")  # the command's own, kept
