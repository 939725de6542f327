"""What a check of one of §2.2's formulas returns (:class:`Finding`), the registry of
checks by inventory id (:func:`check`), and the helpers every check shares."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from functools import cache

import sympy as sp


class Verdict(StrEnum):
    HOLDS = "holds"
    ERRATUM = "erratum"
    NOTATION = "notation"
    NOT_CHECKABLE = "not checkable"
    PENDING = "not yet checked"


class Method(StrEnum):
    SYMPY = "sympy derivation"
    DIMENSION = "dimensional analysis"
    NUMERIC = "numeric"
    NONE = "none"


@dataclass(frozen=True, kw_only=True)
class Finding:
    """One formula's verdict and its evidence."""

    verdict: Verdict
    method: Method
    evidence: str
    uses: tuple[str, ...] = ()
    corrected: str | None = None
    """The corrected form (LaTeX), for an erratum or a notation slip."""
    effect: str | None = None
    """Where it matters numerically, the size of the erratum's effect."""
    printed_residual: Callable[[], sp.Expr] | None = field(default=None, compare=False)
    corrected_residual: Callable[[], sp.Expr] | None = field(default=None, compare=False)


CHECKS: dict[str, Callable[[], Finding]] = {}
"""The check of each inventory id (memoized: a derivation runs once per process)."""


def check(*ids: str) -> Callable[[Callable[[], Finding]], Callable[[], Finding]]:
    def register(fn: Callable[[], Finding]) -> Callable[[], Finding]:
        once = cache(fn)  # one derivation serves every id it checks
        once.__wrapped__ = fn  # inspect.getsource shows the derivation
        for ident in ids:
            if ident in CHECKS:
                raise ValueError(f"two checks for {ident}")
            CHECKS[ident] = once
        return once

    return register


def derived(ok: bool, **evidence: object) -> Finding:
    """A derivation's finding: ``holds`` when it came out, else ``erratum`` (then the check
    must be rewritten to carry the corrected form — the tests demand it)."""
    return Finding(verdict=Verdict.HOLDS if ok else Verdict.ERRATUM, **evidence)  # type: ignore[arg-type]


def zero(expr: sp.Expr) -> bool:
    return sp.simplify(expr) == 0


POINTS = (sp.Rational(1, 3), sp.Integer(1), sp.Integer(2))
"""Parameter values (a curve's t, a motion's instant) where an identity in one variable is
decided: exactly where its terms are rational there, else to DIGITS digits."""
DIGITS = 50
TINY = sp.Float(10) ** -40
"""What counts as zero in a DIGITS-digit evaluation (10 digits of margin)."""


def negligible(value: sp.Expr) -> bool:
    """|value| < TINY, evaluated to DIGITS digits."""
    return bool(abs(sp.N(value, DIGITS)) < TINY)


def findings(ids: list[str]) -> dict[str, Finding]:
    """Each id's finding (PENDING where no check is written yet)."""
    out = {}
    for ident in ids:
        fn = CHECKS.get(ident)
        out[ident] = fn() if fn else Finding(verdict=Verdict.PENDING, method=Method.NONE,
                                             evidence="no check written yet")
    return out


def dimensions() -> dict[str, sp.Expr]:
    """Base dimensions M, L, T, Θ (a curve parameter's unit) and the derived energy and φ."""
    M, L, T, Th = sp.symbols("M L T Θ", positive=True)
    energy = M * L**2 / T**2
    phi = sp.sqrt(M * energy * (L / Th) ** 2)
    return {"M": M, "L": L, "T": T, "Θ": Th, "energy": energy, "phi": phi}

