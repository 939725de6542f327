"""The exact moving frame the checks of (2.2.50)–(2.2.69) and exercises 23 and 30 decide
their identities on: ℓ(t) = (I − S)⁻¹(I + S), the Cayley transform of a skew S(t) with
polynomial entries — a proper orthogonal matrix of rational functions whose angular velocity
changes in size and direction — with the generic ℓ_ij(t) expressions are built on, and the
vee and dual maps of (2.2.61)."""

from __future__ import annotations

from functools import cache

import sympy as sp
from sympy.core.function import AppliedUndef

from dyncheck.errata.registry import (
    POINTS,
)
from dyncheck.errata.rigid import levi_civita

R3 = range(3)


def nil(m: sp.Matrix | sp.Expr) -> bool:
    """Every entry is 0 at each instant of POINTS, exactly: ℓ and its rates take the Cayley
    frame's values there; a path's values x_i(t) and rates ẋ_i(t) are free (independent
    symbols). The differentiation before it is symbolic."""
    entries = list(m) if isinstance(m, sp.MatrixBase) else [m]
    t = frame()[0]
    for at in POINTS:
        for e in entries:
            e = e.xreplace(instant(at))
            e = e.xreplace({d: sp.Dummy() for d in e.atoms(sp.Derivative)})
            e = e.xreplace({f: sp.Dummy() for f in e.atoms(AppliedUndef)})
            if sp.expand(e.subs(t, at)) != 0:
                return False
    return True


@cache
def frame() -> tuple[sp.Symbol, sp.Matrix]:
    t = sp.Symbol("t", real=True)
    a, b, c = t, t**2 / 2, 1 - t / 3
    S = sp.Matrix([[0, -a, b], [a, 0, -c], [-b, c, 0]])
    return t, ((sp.eye(3) - S).inv() * (sp.eye(3) + S)).applyfunc(sp.cancel)


@cache
def generic() -> sp.Matrix:
    """ℓ(t) as nine undefined functions ℓ_ij(t): expressions are built and differentiated on
    these (sympy's product rule, fast) and evaluated on the Cayley frame at an instant."""
    t = frame()[0]
    return sp.Matrix(3, 3, lambda i, j: sp.Function(f"l{i + 1}{j + 1}")(t))


@cache
def instant(at: sp.Expr) -> dict[sp.Expr, sp.Expr]:
    """ℓ_ij, ℓ̇_ij, ℓ̈_ij of the Cayley frame at t = ``at``, keyed by the generic ℓ's terms."""
    t, ell = frame()
    gen = generic()
    out: dict[sp.Expr, sp.Expr] = {}
    for order in (2, 1, 0):
        rate = ell.diff(t, order) if order else ell
        for i in R3:
            for j in R3:
                key = gen[i, j].diff(t, order) if order else gen[i, j]
                out[key] = sp.cancel(rate[i, j]).subs(t, at)
    return out


def vee(skew: sp.Matrix) -> sp.Matrix:
    """ω_i = ½ e_ijk ω_jk (relative-motion.d13)."""
    return sp.Matrix([sum(levi_civita(i, j, k) * skew[j, k] for j in R3 for k in R3) / 2
                      for i in R3])


def dual(w: sp.Matrix) -> sp.Matrix:
    """ω_mn = e_imn ω_i (2.2.61)."""
    return sp.Matrix(3, 3, lambda m, n: sum(levi_civita(i, m, n) * w[i] for i in R3))
