"""The caches of compiled machine code dyncheck points an engine at — JAX's persistent
compilation cache (MJX) and Warp's kernel cache (MuJoCo Warp, Newton) — under the same guard
as the disk store (:mod:`dyncheck.cache.store`): what they hold is loaded and run as found, so a
folder restored from another branch's CI cache, or edited by anyone, must never reach them
unchecked.

Both live in one folder, ``<cache>/compiled/{jax,warp}``, private to this user (0700, owned by
them, nobody else may write it) and vouched for by a manifest: an HMAC-SHA256, keyed by the
store's secret (kept outside the cache folder), over every entry's path and SHA-256. The
command line checks it before any engine starts (:func:`held`): an entry the manifest
does not vouch for — changed, swapped with another, planted, a link, not a regular file — is
deleted, so the engine compiles it again instead of running it. When the command ends the
manifest is signed anew over the entries the folder holds then (written by the engines of
this command, in a folder only this user can write). One command at a time uses the folder
(a lock: exclusive to check it, shared while the command runs): a second command started
meanwhile compiles into temporary folders, so that neither deletes the other's entries
before they are signed (the kernels of a running command went missing under it: "Failed to
load object file"). The folder reaches every unit of work
as :attr:`dyncheck.settings.Settings.compiled`; without it (``--no-cache``, no key, an unsafe
folder, or an engine used as a library) JAX keeps no persistent cache and Warp compiles into
a temporary folder of its own, removed at exit.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

from dyncheck.adapters.compiled import private, released
from dyncheck.cache import store
from dyncheck.regular_files import NotRegular, open_regular
from dyncheck.settings import Settings

ENGINES = ("jax", "warp")
"""The compiled caches, one folder each."""
MANIFEST = ".manifest"
MAGIC = b"dyncheck-compiled-1\n"
MANIFEST_MOST = 64 << 20
"""The largest manifest read (a listing of names and digests: megabytes at most)."""


def _entries(folder: Path) -> dict[str, Path]:
    """Every path below ``folder`` but the manifest, by its name relative to it (links and
    special files included: they are deleted, never followed)."""
    out = {}
    for root, dirs, files in os.walk(folder, followlinks=False):
        for name in [*files, *(d for d in dirs if Path(root, d).is_symlink())]:
            path = Path(root, name)
            relative = path.relative_to(folder).as_posix()
            if relative != MANIFEST:
                out[relative] = path
    return out


def _digest(path: Path) -> str | None:
    """SHA-256 of a regular file (None for anything else: never opened through a link)."""
    try:
        with open_regular(path, follow=False) as f:
            h = hashlib.sha256()
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
            return h.hexdigest()
    except (NotRegular, OSError):
        return None


def _tag(secret: bytes, payload: bytes) -> bytes:
    return hmac.new(secret, MAGIC + payload, hashlib.sha256).digest()


def _vouched(folder: Path, secret: bytes) -> dict[str, str]:
    """The entries the manifest vouches for (name → SHA-256); none where it is missing,
    forged, unreadable, too large or not a regular file."""
    try:
        with open_regular(folder / MANIFEST, follow=False, most=MANIFEST_MOST) as f:
            data = f.read(MANIFEST_MOST + 1)
    except (NotRegular, OSError):
        return {}
    head = len(MAGIC) + 32
    if not data.startswith(MAGIC) or len(data) < head \
            or not hmac.compare_digest(data[len(MAGIC):head], _tag(secret, data[head:])):
        return {}
    try:
        found = json.loads(data[head:])
    except ValueError:
        return {}
    return {str(k): str(v) for k, v in found.items()} if isinstance(found, dict) else {}


def verify(folder: Path, secret: bytes) -> list[str]:
    """Delete every entry of ``folder`` its manifest does not vouch for; the names
    deleted."""
    vouched = _vouched(folder, secret)
    removed = []
    for name, path in sorted(_entries(folder).items()):
        if vouched.get(name) is not None and vouched[name] == _digest(path):
            continue
        try:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink()
            removed.append(name)
        except OSError:
            pass
    return removed


def sign(folder: Path, secret: bytes) -> None:
    """Write ``folder``'s manifest over the regular files it holds now (whole: a temporary
    file renamed)."""
    listing = {name: digest for name, path in sorted(_entries(folder).items())
               if (digest := _digest(path)) is not None}
    payload = json.dumps(listing, sort_keys=True).encode()
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".manifest.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(MAGIC + _tag(secret, payload) + payload)
        os.replace(tmp, folder / MANIFEST)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextmanager
def held(settings: Settings) -> Iterator[Settings]:
    """The command's settings with its checked compiled-code folder (:attr:`Settings.
    compiled`) while the block runs: the folder taken (:func:`_take`), each engine's folder
    verified, then held shared until the block ends, when it is signed and let go. The
    settings unchanged where the cache is off, has no key, the folder is not private, or
    another command holds it (this one then compiles into temporary folders, silently: it
    costs time, never a result)."""
    if not settings.cache:
        yield settings
        return
    root = store.cache_root()
    secret = store.key()
    folder = root / "compiled"
    if secret is None or not all(private(folder / name) for name in ENGINES) \
            or not folder.resolve().is_relative_to(root.resolve()):
        yield settings
        return
    fd = _take(folder)
    if fd is None:
        yield settings
        return
    try:
        removed = [f"{name}/{entry}" for name in ENGINES
                   for entry in verify(folder / name, secret)]
        if removed:
            store.note(f"compiled code not vouched for, deleted (compiled again): "
                       f"{', '.join(removed[:3])}" + (f" (+{len(removed) - 3})"
                                                      if len(removed) > 3 else ""))
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_SH)  # checked: held shared while the command runs
        try:
            yield replace(settings, compiled=str(folder))
        finally:
            released()  # no engine of this process writes there once the command ends
        _sign_all(folder, secret)  # (not after a failure: unsigned entries compile again)
    finally:
        os.close(fd)


def _take(folder: Path) -> int | None:
    """Take the folder for this command: an exclusive lock to check it (kept shared while it
    runs, so that no other command deletes the entries this one's engines write before they
    are signed, nor finds them unsigned); None where another command holds it."""
    import fcntl

    try:
        fd = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK,
                     0o600)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # a FIFO, a device: not a lock of ours
            raise OSError("not a regular file")
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def _sign_all(folder: Path, secret: bytes) -> None:
    for name in ENGINES:
        try:
            if private(folder / name):
                sign(folder / name, secret)
        except OSError:
            pass  # (a read-only or full disk: the next command compiles afresh)
