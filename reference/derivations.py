"""Exact derivations cached on disk: a second run does no symbolic work.

A derivation (a metric, Christoffel symbols, the canonical form M, h of (2.2.26)) is stored
as its pickled sympy result under the user's cache folder, keyed by what it is derived from
(the ``srepr`` of its inputs), sympy's version and the content of this package's source — an
edit of any derivation, or another sympy, derives afresh. ``DYNCHECK_NO_CACHE=1`` (the
command line's ``--no-cache``) neither reads nor writes the cache. A file that cannot be read
back is derived again and replaced; files are written whole (a temporary file, then a rename),
so that processes deriving the same thing at once never read half a file.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")

NO_CACHE = "DYNCHECK_NO_CACHE"
"""Environment variable: set (to anything but empty or 0), the cache is bypassed."""


def cache_root() -> Path:
    """``$DYNCHECK_CACHE`` or ``$XDG_CACHE_HOME/dyncheck`` or ``~/.cache/dyncheck``."""
    if os.environ.get("DYNCHECK_CACHE"):
        return Path(os.environ["DYNCHECK_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "dyncheck"


@cache
def _source_key() -> str:
    """A hash of this package's source files and sympy's version."""
    import sympy as sp  # here: `dyncheck list` reads NO_CACHE without importing sympy

    h = hashlib.sha256(sp.__version__.encode())
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def enabled() -> bool:
    return os.environ.get(NO_CACHE, "") in ("", "0")


def derived(kind: str, inputs: object, compute: Callable[[], T]) -> T:
    """``compute()``, or its result stored by an earlier call with the same ``kind`` and
    ``inputs`` (sympy objects, tuples of them, plain values)."""
    if not enabled():
        return compute()
    import sympy as sp

    key = hashlib.sha256(f"{kind}\n{sp.srepr(inputs)}".encode()).hexdigest()[:32]
    path = cache_root() / "derivations" / _source_key() / f"{kind}-{key}.pickle"
    return cached(path, compute)[0]


def cached(
    path: Path, compute: Callable[[], T], keep: Callable[[T], bool] = lambda _result: True
) -> tuple[T, bool]:
    """The object stored at ``path``, or ``compute()`` stored there (when ``keep`` of it is
    true); with whether it was read back. A file that cannot be read back is computed again
    and replaced; files are written whole (a temporary file, then a rename)."""
    try:
        with path.open("rb") as f:
            return pickle.load(f), True  # our own files, in the user's cache folder
    except (OSError, EOFError, pickle.UnpicklingError, AttributeError, ValueError, TypeError):
        pass  # not stored yet, or unreadable: compute (again)
    result = compute()
    if keep(result):
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
            with os.fdopen(fd, "wb") as f:
                pickle.dump(result, f, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(tmp, path)
        except OSError:
            pass  # a read-only or full cache folder costs time, never a result
    return result, False
