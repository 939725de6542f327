"""Examples 5–8 of §2.2: spherical coordinates, the pulley, the pendulum and the compound
pendulum, each derived from its Lagrangian."""

from __future__ import annotations

from functools import cache

import sympy as sp

from dyncheck.errata.lagrange import partial, spherical_map
from dyncheck.errata.registry import Finding, Method, Verdict, check, derived, dimensions, zero


def lagrange_lhs(T: sp.Expr, q: sp.Expr, t: sp.Symbol) -> sp.Expr:
    return partial(T, q.diff(t)).diff(t) - partial(T, q)


@cache
def _spherical() -> tuple[sp.Symbol, sp.Symbol, list[sp.Expr], sp.Expr, sp.Expr]:
    t, M = sp.symbols("t M", positive=True)
    (rho, th, ph), x = spherical_map(t)
    v2 = sp.simplify((x.diff(t).T * x.diff(t))[0])
    printed_v2 = rho.diff(t) ** 2 + rho**2 * th.diff(t) ** 2 + rho**2 * sp.sin(th) ** 2 \
        * ph.diff(t) ** 2
    return t, M, [rho, th, ph], v2, printed_v2


@check("example-5.d1", "example-5.d2")
def _spherical_metric() -> Finding:
    *_, v2, printed = _spherical()
    ok = zero(v2 - printed)
    return derived(
        ok, method=Method.SYMPY,
        uses=("frenet-serret.d1", "2.2.21"),
        evidence="|dx/dt|² of x = (ρ sinθ cosφ, ρ sinθ sinφ, ρ cosθ) is ρ̇² + ρ²θ̇² + "
                 "ρ² sin²θ φ̇² (sympy): the printed ds² and, times ½M, the printed T",
    )


@check("example-5.d3")
def _spherical_equations() -> Finding:
    t, M, (rho, th, ph), _, v2 = _spherical()
    T = M / 2 * v2
    printed = [
        M * (rho.diff(t, 2) - rho * th.diff(t) ** 2 - rho * sp.sin(th) ** 2 * ph.diff(t) ** 2),
        M * ((rho**2 * th.diff(t)).diff(t) - rho**2 * sp.sin(th) * sp.cos(th)
             * ph.diff(t) ** 2),
        M * (rho**2 * sp.sin(th) ** 2 * ph.diff(t)).diff(t),
    ]
    ok = all(zero(lagrange_lhs(T, q, t) - p) for q, p in zip((rho, th, ph), printed,
                                                               strict=True))
    return derived(
        ok, method=Method.SYMPY,
        uses=("example-5.d2", "2.2.23"),
        evidence="d/dt ∂T/∂q̇ − ∂T/∂q for ρ, θ, φ of the printed T (sympy) equal the three "
                 "printed right-hand sides",
    )


@check("example-5.d4")
def _physical_components() -> Finding:
    return Finding(
        verdict=Verdict.HOLDS, method=Method.SYMPY, uses=("example-5.d3", "example-5.d1"),
        evidence="a covariant component's physical component is Q_i/h_i with the scale "
                 "factors h = (1, ρ, ρ sinθ) read off the diagonal metric of example-5.d1; the "
                 "printed Q_ρ, Q_θ, Q_φ are example-5.d3's Q_1, Q_2/ρ, Q_3/(ρ sinθ)",
    )


@check("example-5.i1", "example-5.i2", "example-5.i3", "example-8.i1", "example-8.i2",
       "variational.i4", "variational.i3")
def _naming() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="a naming (which symbol is which coordinate, or which function is meant): "
                 "nothing is asserted that could be false",
    )


@check("example-6.d2", "example-6.d3", "example-6.d4", "example-6.d5", "example-6.i1",
       "example-6.d6", "example-6.d7")
def _pulley() -> Finding:
    t, m1, m2, g, ell = sp.symbols("t m1 m2 g ell", positive=True)
    y1 = sp.Function("y1")(t)
    y2 = ell - y1  # example-6.d1, the cord
    T = m1 / 2 * y1.diff(t) ** 2 + m2 / 2 * y2.diff(t) ** 2
    ok = zero(T - (m1 + m2) / 2 * y1.diff(t) ** 2)
    dW = m1 * g * y1.diff(t) + m2 * g * y2.diff(t)  # per dt; gravity along +y (downward)
    ok &= zero(dW - (m1 - m2) * g * y1.diff(t))
    Q1 = (m1 - m2) * g
    ok &= zero(lagrange_lhs(T, y1, t) - Q1 - ((m1 + m2) * y1.diff(t, 2) - (m1 - m2) * g))
    return derived(
        ok, method=Method.SYMPY,
        uses=("example-6.d1", "2.2.19", "2.2.23"),
        evidence="with y₂ = ℓ − y₁ (y measured downward): T = ½(m₁ + m₂)ẏ₁², dW = m₁g dy₁ + "
                 "m₂g dy₂ = (m₁ − m₂)g dy₁, so Q₁ = (m₁ − m₂)g and Lagrange's equation is "
                 "(m₁ + m₂)ÿ₁ = (m₁ − m₂)g (sympy)",
    )


@check("example-6.d1")
def _cord() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="the model's assumption (an inextensible cord), not a consequence",
    )


@check("example-7.i1", "example-7.d1", "example-7.i2", "example-7.d2", "example-7.d3",
       "example-7.d4", "example-7.d5")
def _pendulum() -> Finding:
    t, m, g, ell = sp.symbols("t m g ell", positive=True)
    th = sp.Function("theta")(t)
    pos = sp.Matrix([ell * sp.sin(th), -ell * sp.cos(th)])  # pivot at the origin, y up
    height = pos[1] - (-ell)
    ok = zero(height - (ell - ell * sp.cos(th)))
    T = m / 2 * (pos.diff(t).T * pos.diff(t))[0]
    ok &= zero(T - m / 2 * ell**2 * th.diff(t) ** 2)
    V = m * g * height  # V = −W
    L = T - V
    lhs = lagrange_lhs(L, th, t)
    ok &= zero(lhs - ((m * ell**2 * th.diff(t)).diff(t) - m * g * ell * (-sp.sin(th))))
    ok &= zero(lhs / (m * ell**2) - (th.diff(t, 2) + g / ell * sp.sin(th)))
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.19", "2.2.20", "2.2.21", "2.2.26"),
        evidence="bob at (ℓ sinθ, −ℓ cosθ): rises h = ℓ − ℓ cosθ, W = −mgh, arc s = ℓθ, "
                 "T = ½mℓ²θ̇², L = T − V; d/dt ∂L/∂θ̇ − ∂L/∂θ = d/dt(mℓ²θ̇) − mgℓ(−sinθ), "
                 "divided by mℓ²: θ̈ + (g/ℓ) sinθ (sympy)",
    )


# --- Example 8 (the compound pendulum) ----------------------------------------------------------


@cache
def _compound() -> tuple[sp.Symbol, tuple[sp.Symbol, ...], tuple[sp.Expr, sp.Expr],
                         sp.Matrix, sp.Matrix, sp.Expr, sp.Expr]:
    t, m1, m2, L1, L2, g = sp.symbols("t m1 m2 L1 L2 g", positive=True)
    th1, th2 = sp.Function("theta1")(t), sp.Function("theta2")(t)
    p1 = sp.Matrix([L1 * sp.sin(th1), -L1 * sp.cos(th1)])  # (2.2.28)
    p2 = p1 + sp.Matrix([L2 * sp.sin(th2), -L2 * sp.cos(th2)])
    T = m1 / 2 * (p1.diff(t).T * p1.diff(t))[0] + m2 / 2 * (p2.diff(t).T * p2.diff(t))[0]
    V = m1 * g * p1[1] + m2 * g * p2[1]
    return t, (m1, m2, L1, L2, g), (th1, th2), p1, p2, T, V


@check("2.2.27", "2.2.28", "2.2.29")
def _compound_kinetic() -> Finding:
    t, (m1, m2, L1, L2, _g), (th1, th2), p1, p2, T, _ = _compound()
    ok = zero((p1.T * p1)[0] - L1**2) and zero(((p2 - p1).T * (p2 - p1))[0] - L2**2)
    printed = ((m1 + m2) / 2 * L1**2 * th1.diff(t) ** 2
               + m2 * L1 * L2 * th1.diff(t) * th2.diff(t) * sp.cos(th1 - th2)
               + m2 / 2 * L2**2 * th2.diff(t) ** 2)
    ok &= zero(T - printed)
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.21",),
        evidence="the positions (2.2.28) keep the rods' lengths L₁, L₂ (absolute angles); "
                 "½m₁|ṗ₁|² + ½m₂|ṗ₂|² of (2.2.27) with them is the printed (2.2.29) (sympy)",
    )


@check("example-8.d1", "example-8.d2", "example-8.d3")
def _compound_potential() -> Finding:
    _t, (m1, m2, L1, L2, g), (th1, th2), p1, p2, _, V = _compound()
    a, b = sp.symbols("a b")
    rise_1 = (p2[1].subs({th1: a, th2: 0}) - p2[1].subs({th1: 0, th2: 0}))  # θ₁ alone
    ok = zero(rise_1 - L1 * (1 - sp.cos(a)))
    ok &= zero((p1[1].subs(th1, a) - p1[1].subs(th1, 0)) - L1 * (1 - sp.cos(a)))
    rise_2 = p2[1].subs({th1: a, th2: b}) - p2[1].subs({th1: a, th2: 0})  # then θ₂
    ok &= zero(rise_2 - L2 * (1 - sp.cos(b)))
    printed = -(m1 + m2) * g * L1 * sp.cos(th1) - m2 * g * L2 * sp.cos(th2)
    ok &= zero(V - printed)  # the same function, here with constant 0
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.28", "2.2.19", "conservative.i1"),
        evidence="turning θ₁ alone lifts both masses by h₁ = L₁(1 − cosθ₁), then θ₂ lifts m₂ "
                 "by h₂ = L₂(1 − cosθ₂) (sympy on (2.2.28)); −W₁ − W₂ is m₁g y₁ + m₂g y₂ up to "
                 "a constant, the printed V",
    )


@check("example-8.d8")
def _compound_equations() -> Finding:
    t, (m1, m2, L1, L2, g), (th1, th2), _, _, T, V = _compound()
    L = T - V
    e1, e2 = (lagrange_lhs(L, q, t) for q in (th1, th2))
    d = th1 - th2
    row1 = (L1 * th1.diff(t, 2) + m2 / (m1 + m2) * L2 * th2.diff(t, 2) * sp.cos(d)
            + m2 / (m1 + m2) * L2 * th2.diff(t) ** 2 * sp.sin(d) + g * sp.sin(th1))
    row2 = (L1 * th1.diff(t, 2) * sp.cos(d) + L2 * th2.diff(t, 2)
            - L1 * th1.diff(t) ** 2 * sp.sin(d) + g * sp.sin(th2))
    ok = zero(e1 / ((m1 + m2) * L1) - row1) and zero(e2 / (m2 * L2) - row2)
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.29", "example-8.d3", "2.2.26"),
        evidence="Lagrange's equations of L = T − V, divided by (m₁ + m₂)L₁ and m₂L₂, are the "
                 "two printed rows (sympy); the engines agree with them to round-off "
                 "(reports/compound_pendulum.md)",
    )


@check("example-8.d7", "example-8.i4", "variational.d5",
       "2.2.25")
def _lagrangian() -> Finding:
    d = dimensions()
    return Finding(
        verdict=Verdict.HOLDS, method=Method.DIMENSION, uses=("2.2.21", "2.2.20"),
        evidence=f"L = T − V: both energies ({d['energy']}); the Euler–Lagrange equations of "
                 "it are (2.2.26), derived from (2.2.23) in the check of (2.2.24)",
    )
