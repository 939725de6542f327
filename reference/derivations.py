"""Exact derivations cached on disk: a second run does no symbolic work.

A derivation (a metric, Christoffel symbols, the standard form M, h of (2.2.26)) is stored
as its sympy result under the user's cache folder, keyed by what it is derived from (the
``srepr`` of its inputs), sympy's version and the content of this package's source — an
edit of any derivation, or another sympy, derives afresh. The store is the caller's:
:data:`STORE`, set by the comparison layer (``dyncheck.cache.store.DiskStore``, whose entries are
authenticated data: a file placed in the cache folder by anyone else is never deserialized);
unset (``--no-cache``, or this package used alone), everything is derived afresh.

The numeric functions made from derived expressions are kept too (:func:`lambdified`): the
code ``sympy.lambdify`` generates and compiles, stored as Python's code object, so that a
second process builds the same function without printing the expressions again (only from
an authenticated entry of the store).
"""

from __future__ import annotations

import hashlib
import io
import marshal
import pickle
import sys
import types
from collections.abc import Callable, Sequence
from contextvars import ContextVar
from functools import cache
from pathlib import Path
from typing import Any, Protocol, TypeVar

import numpy as np

__all__ = ["STORE", "Store", "derived", "lambdified", "value_bytes"]

T = TypeVar("T")


class Store(Protocol):
    """Where derivations are kept: the entry called ``name`` (a relative path), or
    ``compute()`` kept under it when ``keep`` of it is true; what is read back is an
    instance of ``expect``."""

    def __call__(self, name: str, compute: Callable[[], T],
                 keep: Callable[[T], bool] = ..., *,
                 expect: type | tuple[type, ...] = ...) -> T: ...


STORE: ContextVar[Store | None] = ContextVar("dyncheck_reference_store", default=None)
"""The store derivations are kept in, set by the caller; None: derive everything afresh."""


@cache
def _source_key() -> str:
    """A hash of this package's source files and sympy's version."""
    import sympy as sp  # here: importing this module (`dyncheck list`) imports no sympy

    h = hashlib.sha256(sp.__version__.encode())
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def derived(kind: str, inputs: object, compute: Callable[[], T]) -> T:
    """``compute()``, or its result stored by an earlier call with the same ``kind`` and
    ``inputs`` (sympy objects, tuples of them, plain values)."""
    store = STORE.get()
    if store is None:
        return compute()
    import sympy as sp

    key = hashlib.sha256(f"{kind}\n{sp.srepr(inputs)}".encode()).hexdigest()[:32]
    return store(f"derivations/{_source_key()}/{kind}-{key}.pickle", compute)


class _Canonical(pickle.Pickler):
    """A pickler whose bytes depend on values only (see :func:`value_bytes`)."""

    def reducer_override(self, obj: Any) -> Any:  # called for every object pickled
        if isinstance(obj, np.ndarray) and not obj.flags.c_contiguous:
            return np.ascontiguousarray(obj).__reduce_ex__(5)
        return NotImplemented


def value_bytes(obj: object) -> bytes:
    """``obj`` pickled so that equal values give equal bytes, for a cache key (never read
    back): pickle's memo off, so that how objects share parts does not show (an expression
    rebuilt from the cache shares its subexpressions unlike one just derived), and every
    array C-contiguous (a column view pickles unlike its copy). Without both, a run keyed
    what it had just computed unlike what the next run read back, and the next run computed
    it again. A self-referential object raises ``ValueError``."""
    buf = io.BytesIO()
    pickler = _Canonical(buf, protocol=5)
    pickler.fast = True  # no memo
    pickler.dump(obj)
    return buf.getvalue()


@cache
def _namespace(modules: str) -> dict[str, Any]:
    """The globals ``sympy.lambdify`` gives a function of ``modules`` ("numpy": numpy's and
    numpy.linalg's names; "math": math's), with Python's builtins."""
    import sympy as sp

    return sp.lambdify((), 0, modules=modules).__globals__


def _global_names(code: types.CodeType) -> set[str]:
    """Every global name ``code`` and the code objects inside it look up."""
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= _global_names(const)
    return names


def _storable(f: Callable[..., Any], modules: str) -> bool:
    """Whether ``f`` is rebuilt exactly from its code and :func:`_namespace`: no defaults, no
    closure, and every name its code reads bound to the same object in both globals, or in
    neither (an attribute's name, or a builtin)."""
    if not isinstance(f, types.FunctionType) or f.__defaults__ or f.__closure__:
        return False
    ns, own, missing = _namespace(modules), f.__globals__, object()
    same_builtins = own.get("__builtins__") is ns.get("__builtins__")
    return same_builtins and all(
        own.get(name, missing) is ns.get(name, missing) for name in _global_names(f.__code__)
    )


def lambdified(
    args: Sequence[Any], exprs: Any, modules: str, cse: bool = True
) -> Callable[..., Any]:
    """``sympy.lambdify(args, exprs, modules=modules, cse=cse)``, its compiled code kept on
    disk beside the derivations (keyed by the arguments' and expressions' :func:`value_bytes`,
    the option, sympy's and Python's versions and this package's source): a second process
    builds the same function — the same code in the same names — from the stored code object
    instead of printing and compiling the expressions again (~1 s of a warm run). A function
    that reads anything but the module's names, or of expressions that cannot be pickled, is
    never stored (made afresh each time)."""
    import sympy as sp

    def make() -> Callable[..., Any]:
        return sp.lambdify(args, exprs, modules=modules, cse=cse)

    store = STORE.get()
    if store is None:
        return make()
    h = hashlib.sha256(f"{modules}\n{cse}\n{sys.version}\n".encode())
    try:
        h.update(value_bytes((tuple(args), exprs)))
    except (pickle.PicklingError, AttributeError, TypeError, ValueError):  # no key: made anew
        return make()
    name = f"lambdified/{_source_key()}/{h.hexdigest()[:32]}.pickle"
    made: list[Callable[..., Any]] = []

    def code() -> bytes | None:
        made.append(make())
        return marshal.dumps(made[0].__code__) if _storable(made[0], modules) else None

    stored = store(name, code, lambda c: c is not None, expect=bytes)
    if made:
        return made[0]
    assert stored is not None  # only a storable function's code is stored
    return types.FunctionType(marshal.loads(stored), _namespace(modules))
