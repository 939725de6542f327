"""Lagrange's equations on a general metric: (2.2.4), (2.2.5), (2.2.21)–(2.2.26), exercises
8–11 and the energy integral. The derivations use a 2-dimensional space with a general metric
and potential (the results are identities in N)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import sympy as sp

from dyncheck.errata.registry import Finding, Method, Verdict, check, derived, dimensions, zero


@dataclass(frozen=True)
class _Lagrange:
    t: sp.Symbol
    M: sp.Symbol
    x: tuple[sp.Expr, ...]
    xd: tuple[sp.Expr, ...]
    xdd: tuple[sp.Expr, ...]
    g: sp.Matrix
    V: sp.Expr
    T: sp.Expr
    gamma: tuple[tuple[tuple[sp.Expr, ...], ...], ...]
    """Christoffel symbols of the second kind {i; m n} of g."""


def christoffel(g: sp.Matrix, p: Sequence[sp.Symbol]) -> list[list[list[sp.Expr]]]:
    """{i; m n} = ½ g^{ir} (∂g_rm/∂pⁿ + ∂g_rn/∂pᵐ − ∂g_mn/∂pʳ) of the metric g in the
    coordinates p."""
    ginv, dim = g.inv(), range(len(p))
    return [[[sum(ginv[i, r] * (g[r, m].diff(p[n]) + g[r, n].diff(p[m]) - g[m, n].diff(p[r]))
                  for r in dim) / 2 for n in dim] for m in dim] for i in dim]


@cache
def general_lagrange() -> _Lagrange:
    t, M = sp.symbols("t M", positive=True)
    x = tuple(sp.Function(f"x{i + 1}")(t) for i in range(2))
    xd = tuple(xi.diff(t) for xi in x)
    xdd = tuple(xi.diff(t, 2) for xi in x)
    p = sp.symbols("p1 p2")
    g11, g12, g22, V = (sp.Function(n)(*p) for n in ("g11", "g12", "g22", "V"))
    g_p = sp.Matrix([[g11, g12], [g12, g22]])
    at = dict(zip(p, x, strict=True))
    g = g_p.subs(at)
    gamma = tuple(tuple(tuple(c.subs(at) for c in row) for row in mat)
                  for mat in christoffel(g_p, p))
    T = M / 2 * sum(g[m, n] * xd[m] * xd[n] for m in range(2) for n in range(2))
    return _Lagrange(t, M, x, xd, xdd, g, V.subs(at), T, gamma)


def partial(expr: sp.Expr, var: sp.Expr) -> sp.Expr:
    """∂expr/∂var for var a coordinate x(t) or a velocity ẋ(t), the others held fixed."""
    s = sp.Dummy()
    return expr.subs(var, s).diff(s).subs(s, var)


def acceleration(c: _Lagrange) -> list[sp.Expr]:
    """fⁱ of (2.2.5): ẍⁱ + {i; m n} ẋᵐ ẋⁿ."""
    return [c.xdd[i] + sum(c.gamma[i][m][n] * c.xd[m] * c.xd[n] for m in range(2)
                           for n in range(2)) for i in range(2)]


@check("2.2.22", "ex8.i1", "ex9.i1", "ex10.i1")
def _lagrange_derivatives() -> Finding:
    c = general_lagrange()
    ok = True
    for r in range(2):
        p_r = partial(c.T, c.xd[r])
        ok &= zero(p_r - c.M * sum(c.g[r, m] * c.xd[m] for m in range(2)))
        dg = [sum(partial(c.g[r, m], c.x[n]) * c.xd[n] for n in range(2)) for m in range(2)]
        ok &= zero(p_r.diff(c.t) - c.M * sum(c.g[r, m] * c.xdd[m] + dg[m] * c.xd[m]
                                             for m in range(2)))
        ok &= zero(partial(c.T, c.x[r]) - c.M / 2 * sum(
            partial(c.g[m, n], c.x[r]) * c.xd[m] * c.xd[n] for m in range(2) for n in range(2)))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.21",),
        evidence="∂T/∂ẋʳ, d/dt ∂T/∂ẋʳ and ∂T/∂xʳ of T = ½ M g_mn ẋᵐẋⁿ, differentiated by "
                 "sympy on a general 2-D metric along a general curve, equal the three printed "
                 "lines (the exercises 8–10 state the same three results)",
    )


@check("2.2.23")
def _lagrange_form() -> Finding:
    c = general_lagrange()
    f = acceleration(c)
    ok = all(zero(partial(c.T, c.xd[r]).diff(c.t) - partial(c.T, c.x[r])
                  - c.M * sum(c.g[r, i] * f[i] for i in range(2))) for r in range(2))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.22", "2.2.5", "2.2.18"),
        evidence="d/dt ∂T/∂ẋʳ − ∂T/∂xʳ − M g_ri fⁱ with fⁱ = ẍⁱ + {i; m n} ẋᵐẋⁿ of (2.2.5), "
                 "Christoffel symbols computed from a general 2-D metric: 0 (sympy); = Q_r by "
                 "(2.2.18)",
    )


@check("2.2.5")
def _acceleration_is_a_vector() -> Finding:
    """In spherical coordinates (ρ, θ, φ) the Cartesian acceleration is J f with
    fⁱ = ẍⁱ + {i; m n} ẋᵐẋⁿ, J the Jacobian of (2.2.2)."""
    t = sp.Symbol("t")
    q = [sp.Function(n)(t) for n in ("rho", "theta", "phi")]
    p = sp.symbols("r th ph", positive=True)
    cart = sp.Matrix([p[0] * sp.sin(p[1]) * sp.cos(p[2]), p[0] * sp.sin(p[1]) * sp.sin(p[2]),
                      p[0] * sp.cos(p[1])])
    J = cart.jacobian(p)
    g = sp.simplify(J.T * J)
    gamma = [[[sp.simplify(c) for c in row] for row in mat] for mat in christoffel(g, p)]
    at = dict(zip(p, q, strict=True))
    qd = [qi.diff(t) for qi in q]
    f = sp.Matrix([q[i].diff(t, 2) + sum(gamma[i][m][n].subs(at) * qd[m] * qd[n]
                                         for m in range(3) for n in range(3)) for i in range(3)])
    accel = cart.subs(at).diff(t, 2)
    ok = all(zero(e) for e in (accel - J.subs(at) * f))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.2", "2.2.3", "2.2.4"),
        evidence="in spherical coordinates, J fⁱ with fⁱ = ẍⁱ + {i; m n} ẋᵐẋⁿ (Christoffel "
                 "symbols from g = JᵀJ) equals the Cartesian acceleration d²x/dt² exactly "
                 "(sympy): fⁱ are the components of the acceleration, a contravariant vector",
    )


def spherical_map(t: sp.Symbol) -> tuple[list[sp.Expr], sp.Matrix]:
    """(ρ, θ, φ) as functions of t and the Cartesian point they name."""
    q = [sp.Function(n)(t) for n in ("rho", "theta", "phi")]
    return q, sp.Matrix([q[0] * sp.sin(q[1]) * sp.cos(q[2]), q[0] * sp.sin(q[1])
                         * sp.sin(q[2]), q[0] * sp.cos(q[1])])


@check("2.2.4")
def _velocity_chain_rule() -> Finding:
    t = sp.Symbol("t")
    q, cart = spherical_map(t)
    J = sp.Matrix(3, 3, lambda r, j: partial(cart[r], q[j]))
    ok = all(zero(e) for e in cart.diff(t) - J * sp.Matrix([qi.diff(t) for qi in q]))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.2", "2.2.3"),
        evidence="d x̄ʳ/dt = ∂x̄ʳ/∂xʲ vʲ for the spherical-to-Cartesian map (sympy)",
    )


@check("particle-movement.d6", "particle-movement.d8", "frenet-serret.d1")
def _squared_magnitudes() -> Finding:
    t = sp.Symbol("t")
    q, cart = spherical_map(t)
    J = sp.Matrix(3, 3, lambda r, j: partial(cart[r], q[j]))
    v = sp.Matrix([qi.diff(t) for qi in q])
    ok = zero((cart.diff(t).T * cart.diff(t))[0] - (v.T * (J.T * J) * v)[0])
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.4",),
        evidence="|dx/dt|² in Cartesian coordinates equals g_ij vⁱvʲ with g = JᵀJ in "
                 "spherical coordinates (sympy); the same quadratic form gives f² = g_ij fⁱfʲ "
                 "for the vector fⁱ of (2.2.5) and ds² = g_ij dxⁱdxʲ",
    )


@check("2.2.21")
def _kinetic_forms() -> Finding:
    c = general_lagrange()
    d = dimensions()
    return Finding(
        verdict=Verdict.HOLDS, method=Method.DIMENSION, uses=("particle-movement.d6",),
        evidence="v = ds/dt and v² = g_mn vᵐvⁿ (particle-movement.d6) make the four forms "
                 f"one; each has dimension {sp.simplify(d['energy'])} (T = {c.T} in the "
                 "sympy context)",
    )


@check("2.2.24", "2.2.26", "2.2.34")
def _euler_lagrange() -> Finding:
    c = general_lagrange()
    L = c.T - c.V
    ok = all(zero((partial(L, c.xd[r]).diff(c.t) - partial(L, c.x[r]))
                  - (partial(c.T, c.xd[r]).diff(c.t) - partial(c.T, c.x[r]) + partial(c.V, c.x[r])))
             for r in range(2))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.23", "2.2.20", "2.2.25"),
        evidence="with L = T − V and V independent of ẋ, d/dt ∂L/∂ẋʳ − ∂L/∂xʳ = "
                 "d/dt ∂T/∂ẋʳ − ∂T/∂xʳ + ∂V/∂xʳ (sympy), which vanishes exactly when "
                 "(2.2.23) holds with Q_r = −∂V/∂xʳ (2.2.20)",
    )


@check("variational.d16", "variational.i6", "variational.i7", "variational.i8", "ex19.i2")
def _energy_conservation() -> Finding:
    c = general_lagrange()
    f = acceleration(c)
    power = c.M * sum(c.g[i, j] * c.xd[i] * f[j] for i in range(2) for j in range(2))
    ok = zero(c.T.diff(c.t) - power)
    # on a motion, M g_ij f^j = −∂V/∂x^i: dT/dt = −dV/dt
    motion = sp.solve([c.M * sum(c.g[i, j] * f[j] for j in range(2)) + partial(c.V, c.x[i])
                       for i in range(2)], list(c.xdd), dict=True)[0]
    ok &= zero((c.T + c.V).diff(c.t).subs(motion))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.5", "2.2.21", "2.2.18", "2.2.20"),
        evidence="dT/dt = M g_ij ẋⁱ fʲ along any curve (sympy, general 2-D metric); on a "
                 "motion M g_ij fʲ = −∂V/∂xⁱ, and d(T + V)/dt = 0 there (sympy): T + V = h",
    )


@check("variational.i5", "ex19.i3")
def _newton_conservative() -> Finding:
    return Finding(
        verdict=Verdict.HOLDS, method=Method.SYMPY, uses=("2.2.18", "2.2.20"),
        evidence="(2.2.18) with (2.2.20): m f_i = Q_i = −∂V/∂xⁱ (the substitution checked in "
                 "variational.d16's derivation)",
    )
