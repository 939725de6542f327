"""The disk cache's store: entries that are authenticated before anything reads them.

The cache folder (``$DYNCHECK_CACHE``, ``$XDG_CACHE_HOME/dyncheck`` or ``~/.cache/dyncheck``)
is untrusted input: a CI cache restored from another branch, a folder shared between machines.
Every entry is therefore written as ``MAGIC``, an HMAC-SHA256 tag and the payload, the tag
keyed by a secret that lives *outside* the cache folder (``$DYNCHECK_CACHE_KEY``, or
``$XDG_CONFIG_HOME/dyncheck/cache-key``, or ``~/.config/dyncheck/cache-key``: 32 random bytes,
created 0600, refused unless it is a regular file of this user's that nobody else can read)
and over the entry's name as well as its bytes, so that neither a crafted file nor a genuine
entry moved to another name is ever deserialized. What an authentic entry holds is then read
by an unpickler that resolves only names of a fixed list of packages and plain-data builtins
(never a builtin that runs code), and checked against the type the caller expects. The
authentication is what keeps code out: those packages hold functions too, and one kind of
entry is compiled code (``reference/derivations.py``'s ``lambdified``), run only from an
authentic entry. A file that is missing is computed; one that is not authentic, not a
regular file, too large or of the wrong type is computed afresh with a one-line note on
stderr, never a traceback. Folders are created private (0700), files are written whole (a
temporary file, then a rename), and nothing is written through a folder that resolves
outside the cache folder.

Whether the cache is used at all is a command's setting (``--no-cache``,
:class:`dyncheck.settings.Settings`), handed to every unit of work as an argument; the
reference's derivations are given a :class:`DiskStore` by the comparison layer
(:func:`dyncheck.workers.settled`), never reach for one themselves.
"""

from __future__ import annotations

import hashlib
import hmac
import io
import os
import pickle
import secrets
import sys
import tempfile
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any, TypeVar

from dyncheck.adapters.compiled import private_folder
from dyncheck.regular_files import NotRegular, Refusal, open_regular

T = TypeVar("T")

KEY = "DYNCHECK_CACHE_KEY"
"""Environment variable: the file holding the cache's secret key (outside the cache folder)."""
MAGIC = b"dyncheck-cache-1\n"
TAG_BYTES = 32
KEY_BYTES = 32
MAX_ENTRY_BYTES = 1 << 30
"""The largest entry read back (a case's figures are ~1 MB, a study's references ~10 MB)."""

SAFE_PACKAGES = ("dyncheck", "numpy", "sympy", "mpmath", "pandas", "collections",
                 "datetime", "fractions", "decimal", "pathlib", "enum")
"""Packages whose classes an authentic entry may name (what dyncheck stores)."""
SAFE_BUILTINS = frozenset({
    "bool", "bytearray", "bytes", "complex", "dict", "float", "frozenset", "int", "list",
    "object", "range", "set", "slice", "str", "tuple", "type", "NotImplemented", "Ellipsis",
})
"""Builtins an entry may name: constructors of plain data, never ``eval``, ``exec``,
``getattr`` or ``__import__``."""


def cache_root() -> Path:
    """``$DYNCHECK_CACHE`` or ``$XDG_CACHE_HOME/dyncheck`` or ``~/.cache/dyncheck``."""
    if os.environ.get("DYNCHECK_CACHE"):
        return Path(os.environ["DYNCHECK_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "dyncheck"


def key_path() -> Path:
    if os.environ.get(KEY):
        return Path(os.environ[KEY])
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "dyncheck" / "cache-key"


def note(message: str) -> None:
    """One line on stderr (the cache never fails a run; it says what it skipped)."""
    print(f"dyncheck: cache: {message}", file=sys.stderr)


def _inside(path: Path, folder: Path) -> bool:
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except OSError:
        return True  # unresolvable (a symlink loop): treated as unsafe


def _read_key(path: Path) -> bytes:
    """The key at ``path`` (a ValueError naming what is wrong with it)."""
    try:
        with open_regular(path, follow=False) as f:
            info = os.fstat(f.fileno())
            if info.st_uid != os.getuid() or info.st_mode & 0o077:
                raise ValueError(f"{path} must belong to this user and be private (chmod 600)")
            key = f.read(KEY_BYTES + 1)
    except NotRegular as exc:
        raise ValueError(f"{path} {exc}") from None
    if len(key) != KEY_BYTES:
        raise ValueError(f"{path} holds {len(key)} bytes, not {KEY_BYTES}")
    return key


@cache
def _key(path: Path, root: Path) -> bytes | None:
    """The cache's secret key, created on first use; None (cache off, said once) where it
    cannot be had safely."""
    try:
        if _inside(path, root):
            raise ValueError(f"{path} lies inside the cache folder {root}")
        try:
            return _read_key(path)
        except FileNotFoundError:
            private_folder(path.parent)
            try:
                fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
            except FileExistsError:  # another process made it first
                return _read_key(path)
            with os.fdopen(fd, "wb") as f:
                f.write(secrets.token_bytes(KEY_BYTES))
            return _read_key(path)
    except (OSError, ValueError) as exc:
        note(f"off (its key: {exc})")
        return None


def key() -> bytes | None:
    return _key(key_path(), cache_root())


def _tag(secret: bytes, name: str, payload: bytes) -> bytes:
    mac = hmac.new(secret, MAGIC, hashlib.sha256)
    mac.update(name.encode("utf-8", "surrogateescape") + b"\0")
    mac.update(payload)
    return mac.digest()


class _Unpickler(pickle.Unpickler):
    """Resolves only classes of :data:`SAFE_PACKAGES` and the builtins of plain data."""

    def find_class(self, module: str, name: str) -> Any:
        top = module.split(".")[0]
        if (module == "builtins" and name in SAFE_BUILTINS) or (
            top in SAFE_PACKAGES and top != "builtins"
        ):
            return super().find_class(module, name)
        raise pickle.UnpicklingError(f"refused to load {module}.{name}")


def loads(data: bytes) -> Any:
    return _Unpickler(io.BytesIO(data)).load()


class Invalid(Exception):
    """An entry that exists but is not to be used (the message says why)."""


def _read(path: Path, name: str, secret: bytes) -> bytes:
    """The authenticated payload at ``path``; FileNotFoundError where there is none,
    :class:`Invalid` where what is there is not to be read."""
    try:
        with open_regular(path, follow=False, most=MAX_ENTRY_BYTES) as f:
            data = f.read(MAX_ENTRY_BYTES + 1)
    except NotRegular as exc:
        raise Invalid(f"is {exc.size} bytes (more than {MAX_ENTRY_BYTES})"
                      if exc.refusal is Refusal.TOO_LARGE else str(exc)) from None
    head = len(MAGIC) + TAG_BYTES
    if not data.startswith(MAGIC) or len(data) < head:
        raise Invalid("is not a dyncheck cache entry")
    payload = data[head:]
    if not hmac.compare_digest(data[len(MAGIC):head], _tag(secret, name, payload)):
        raise Invalid("is not authentic (written by someone else, or for another name)")
    return payload


def read_entry(path: Path, decode: Callable[[bytes], T] = loads) -> T | None:
    """The value stored at ``path`` (authenticated, decoded), or None where there is none
    or it is not to be used (said in one line)."""
    secret, root = key(), cache_root()
    if secret is None:
        return None
    name = _name(path, root)
    try:
        return decode(_read(path, name, secret))
    except FileNotFoundError:
        return None
    except Invalid as exc:
        note(f"{name} {exc}: computed afresh")
    except Exception as exc:  # an authentic entry that does not decode (an older format)
        note(f"{name} does not decode ({type(exc).__name__}): computed afresh")
    return None


def _name(path: Path, root: Path) -> str:
    try:
        return path.relative_to(root).as_posix()
    except ValueError:
        return path.as_posix()


def write_entry(path: Path, payload: bytes) -> None:
    """Store ``payload`` at ``path`` whole and authenticated; a read-only, full or unsafe
    cache folder costs time, never a result."""
    secret, root = key(), cache_root()
    if secret is None:
        return
    try:
        private_folder(path.parent)
        if not _inside(path.parent, root):
            note(f"{_name(path, root)} not written: its folder resolves outside {root}")
            return
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(MAGIC + _tag(secret, _name(path, root), payload) + payload)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        pass


def cached(
    path: Path, compute: Callable[[], T], keep: Callable[[T], bool] = lambda _result: True,
    *, expect: type | tuple[type, ...] = object,
) -> tuple[T, bool]:
    """The object stored at ``path``, or ``compute()`` stored there (when ``keep`` of it is
    true); with whether it was read back. What is read back must be an instance of
    ``expect``; anything else is computed afresh and replaced."""
    found = read_entry(path)
    if found is not None:
        if isinstance(found, expect):
            return found, True
        note(f"{_name(path, cache_root())} holds a {type(found).__name__}, not the "
             f"expected {getattr(expect, '__name__', expect)}: computed afresh")
    result = compute()
    if keep(result):
        try:
            payload = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
        except (pickle.PicklingError, TypeError, AttributeError):
            return result, False
        write_entry(path, payload)
    return result, False


class DiskStore:
    """The cache folder as :class:`dyncheck.reference.derivations.Store`: an entry by its
    name under :func:`cache_root`, computed where missing (see :func:`cached`)."""

    def __call__(self, name: str, compute: Callable[[], T],
                 keep: Callable[[T], bool] = lambda _result: True, *,
                 expect: type | tuple[type, ...] = object) -> T:
        return cached(cache_root() / name, compute, keep, expect=expect)[0]
