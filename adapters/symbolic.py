"""How an adapter that derives its equations symbolically (sympy.physics.mechanics) keeps
them and makes numeric functions of them (:class:`Symbolic`): adapters never import the
reference, whose caches the comparison layer hands in."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

_T = TypeVar("_T")


def _computed(kind: str, inputs: object, compute: Callable[[], _T]) -> _T:
    return compute()


def _lambdified(args: Sequence[Any], exprs: Any, modules: str) -> Callable[..., Any]:
    import sympy as sp

    return sp.lambdify(args, exprs, modules=modules, cse=True)


@dataclass(frozen=True, kw_only=True)
class Symbolic:
    """How an adapter that derives its equations symbolically keeps them — ``derive(kind,
    inputs, compute)``: ``compute()``'s result, keyed by ``kind`` and ``inputs`` — and makes
    numeric functions of them — ``lambdify(args, exprs, modules)``, as ``sympy.lambdify``
    with ``cse=True``. The default computes both afresh; the comparison layer, which may see
    the reference, hands in the reference's disk caches (``dyncheck.implementations.CACHED``):
    adapters never import the reference, and nothing is patched in at import."""

    derive: Callable[[str, object, Callable[[], Any]], Any] = _computed
    lambdify: Callable[[Sequence[Any], Any, str], Callable[..., Any]] = _lambdified


AFRESH = Symbolic()
"""Equations derived and compiled afresh (no cache)."""
