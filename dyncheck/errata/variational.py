"""Work and potential (2.2.19)–(2.2.20) and the variational derivation (2.2.30)–(2.2.36)."""

from __future__ import annotations

from functools import cache

import sympy as sp

from dyncheck.errata.registry import Finding, Method, Verdict, check, derived, zero


@check("2.2.19", "2.2.20", "conservative.i1", "example-8.i3")
def _work() -> Finding:
    t = sp.Symbol("t", positive=True)
    x, y = sp.symbols("x y")
    V = x**2 * y + sp.sin(x)  # a potential; Q = −∇V (2.2.20)
    Q = sp.Matrix([-V.diff(x), -V.diff(y)])
    ok = True
    works = []
    for path in (sp.Matrix([t, t**2]), sp.Matrix([t**3, t])):  # two paths (0,0) → (1,1)
        at = {x: path[0], y: path[1]}
        velocity = path.diff(t)
        speed = sp.sqrt((velocity.T * velocity)[0])
        by_time = sp.integrate((Q.subs(at).T * velocity)[0], (t, 0, 1))
        by_arc = (Q.subs(at).T * (velocity / speed))[0] * speed  # Q_r dx^r/ds, ds = |ẋ|dt
        ok &= zero(by_arc - (Q.subs(at).T * velocity)[0])
        works.append(by_time)
    ok &= zero(works[0] - works[1])
    ok &= zero(works[0] + (V.subs({x: 1, y: 1}) - V.subs({x: 0, y: 0})))  # V = −W
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.18",),
        evidence="for Q = −∇V with V = x²y + sin x and two paths from (0, 0) to (1, 1): "
                 "Q_r dxʳ/ds ds = Q_r vʳ dt pointwise, the work is the same on both paths, "
                 "and W = −(V(P₁) − V(P₀)) (sympy)",
    )


@cache
def _variation() -> tuple[sp.Symbol, sp.Symbol, sp.Expr, sp.Expr, sp.Expr, sp.Matrix]:
    """L = ½ a(x) ẋ² − V(x) with general a, V; a general curve x(t) and variation η(t)."""
    t, eps = sp.symbols("t epsilon")
    x, eta = sp.Function("x")(t), sp.Function("eta")(t)
    X, Xd = sp.symbols("X Xd")
    a, V = sp.Function("a"), sp.Function("V")
    L = a(X) * Xd**2 / 2 - V(X)
    return t, eps, x, eta, L, sp.Matrix([X, Xd])


@check("variational.d8", "variational.d9", "2.2.31", "2.2.32", "2.2.33", "2.2.36")
def _variational_steps() -> Finding:
    t, eps, x, eta, L, (X, Xd) = _variation()
    Lbar = L.subs({X: x + eps * eta, Xd: x.diff(t) + eps * eta.diff(t)}, simultaneous=True)
    on = {X: x, Xd: x.diff(t)}
    dLx, dLv = L.diff(X).subs(on), L.diff(Xd).subs(on)
    first = sp.series(Lbar, eps, 0, 2).removeO()
    ok = zero(first - (L.subs(on) + eps * (dLx * eta + dLv * eta.diff(t))))  # d8
    ok &= zero(Lbar.diff(eps).subs(eps, 0) - (dLx * eta + dLv * eta.diff(t)))  # d9, (2.2.31)
    by_parts = dLx * eta + (dLv * eta).diff(t) - dLv.diff(t) * eta  # (2.2.32)'s integrand
    ok &= zero(by_parts - (dLx * eta + dLv * eta.diff(t)))
    ok &= zero((dLx * eta - dLv.diff(t) * eta) - eta * (dLx - dLv.diff(t)))  # (2.2.33)
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.30", "variational.d3"),
        evidence="for L = ½a(x)ẋ² − V(x) with general a, V, x(t), η(t): the first-order term "
                 "of L(x + εη, ẋ + εη̇) is ∂L/∂x η + ∂L/∂ẋ η̇ (sympy series), which is "
                 "dI/dε at 0 under the integral; integrating ∂L/∂ẋ η̇ by parts leaves the "
                 "boundary term [∂L/∂ẋ η], zero by the end conditions, and the integrand "
                 "η(∂L/∂x − d/dt ∂L/∂ẋ); the fundamental lemma gives (2.2.34), and the same "
                 "steps with φ for L give (2.2.36)",
    )


@check("variational.d2", "variational.d3", "2.2.30", "variational.d6", "variational.d7",
       "variational.i1", "variational.i2", "2.2.35")
def _posed() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="the variational problem as posed (the family of curves, the end conditions, "
                 "the integral, the condition of stationarity and the point ε = 0 where it is "
                 "taken): definitions; the steps derived from them are checked",
    )
