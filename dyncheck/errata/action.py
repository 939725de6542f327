"""The action integral (stationary action; geodesics of 2m(h − V) g): its partial
derivatives, Euler–Lagrange line and change of parameter."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from dyncheck.errata.registry import Finding, Method, Verdict, check, derived, dimensions, zero


@dataclass(frozen=True)
class _Action:
    tau: sp.Symbol
    m: sp.Symbol
    h: sp.Symbol
    x: tuple[sp.Function, ...]
    xd: tuple[sp.Symbol, ...]
    xs: tuple[sp.Symbol, ...]
    g: sp.Matrix
    V: sp.Expr
    phi: sp.Expr
    Q: sp.Expr
    """g_jk ẋ^j ẋ^k (in the point symbols xs, xd)."""


@cache
def _action() -> _Action:
    tau, m, h = sp.symbols("tau m h", positive=True)
    xs = sp.symbols("x1 x2")
    xd = sp.symbols("xd1 xd2")
    g11, g12, g22, V = (sp.Function(n)(*xs) for n in ("g11", "g12", "g22", "V"))
    g = sp.Matrix([[g11, g12], [g12, g22]])
    Q = sum(g[j, k] * xd[j] * xd[k] for j in range(2) for k in range(2))
    phi = sp.sqrt(2 * m) * sp.sqrt((h - V) * Q)
    x = tuple(sp.Function(f"x{i + 1}")(tau) for i in range(2))
    return _Action(tau, m, h, x, xd, xs, g, V, phi, Q)


def _on_curve(a: _Action, expr: sp.Expr) -> sp.Expr:
    subs = {a.xd[i]: a.x[i].diff(a.tau) for i in range(2)}
    subs |= {a.xs[i]: a.x[i] for i in range(2)}
    return expr.subs(subs)


@check("action-integral.d4")
def _action_partials() -> Finding:
    a = _action()
    dphi_dxd = [a.phi.diff(a.xd[i]) for i in range(2)]
    printed_xd = [2 * a.m / a.phi * (a.h - a.V) * sum(a.g[i, k] * a.xd[k] for k in range(2))
                  for i in range(2)]
    printed_x = [2 * a.m / (2 * a.phi) * (a.h - a.V) * a.Q.diff(a.xs[i])
                 - 2 * a.m / (2 * a.phi) * a.V.diff(a.xs[i]) * a.Q for i in range(2)]
    ok = all(zero(dphi_dxd[i] - printed_xd[i]) and zero(a.phi.diff(a.xs[i]) - printed_x[i])
             for i in range(2))
    return derived(
        ok, method=Method.SYMPY,
        uses=("action-integral.d3",),
        evidence="∂φ/∂ẋⁱ and ∂φ/∂xⁱ of φ = √(2m) {(h − V) g_jk ẋʲ ẋᵏ}^½ differentiated by "
                 "sympy on a general 2-D metric and potential equal both printed lines",
    )


def _el_residual(a: _Action, last: sp.Expr) -> list[sp.Expr]:
    """(2.2.36) for φ minus the printed form with ``last`` as the coefficient of
    ∂V/∂xⁱ g_jk ẋʲẋᵏ (d/dτ read for the printed d/dt)."""
    out = []
    for i in range(2):
        true = _on_curve(a, a.phi.diff(a.xd[i])).diff(a.tau) - _on_curve(a, a.phi.diff(a.xs[i]))
        bracket = 2 * a.m / a.phi * (a.h - a.V) * sum(a.g[i, k] * a.xd[k] for k in range(2))
        printed = (_on_curve(a, bracket).diff(a.tau)
                   - _on_curve(a, 2 * a.m / (2 * a.phi) * (a.h - a.V) * a.Q.diff(a.xs[i]))
                   + _on_curve(a, last * a.V.diff(a.xs[i]) * a.Q))
        out.append(true - printed)
    return out


@check("action-integral.d5")
def _action_euler_lagrange() -> Finding:
    a = _action()

    def printed() -> sp.Expr:
        return sp.simplify(_el_residual(a, 2 * a.m / a.phi)[0])

    def corrected() -> sp.Expr:
        return sp.simplify(_el_residual(a, 2 * a.m / (2 * a.phi))[0])

    return Finding(
        verdict=Verdict.ERRATUM, method=Method.SYMPY,
        uses=("2.2.36", "action-integral.d3", "action-integral.d4"),
        evidence="(2.2.36) with φ is d/dτ(∂φ/∂ẋⁱ) − ∂φ/∂xⁱ; with the printed ∂φ/∂xⁱ "
                 "(action-integral.d4, which holds) its last term is +(2m/2φ) ∂V/∂xⁱ g_jk ẋʲẋᵏ. "
                 "The printed coefficient 2m/φ is twice that: the residual (2.2.36) − printed "
                 "is −(m/φ) ∂V/∂xⁱ g_jk ẋʲẋᵏ, not 0; with 2m/2φ it is 0 (sympy, general 2-D "
                 "metric and potential). Also d/dt is printed where the variable is τ "
                 "(ẋᵏ = dxᵏ/dτ): a notation slip the corrected form fixes.",
        corrected=r"\frac{d}{d\tau}\left[\frac{2m}{\phi}(h-V)g_{ik}\dot{x}^k\right]"
                  r"-\frac{2m}{2\phi}(h-V)\frac{\partial g_{jk}}{\partial x^i}\dot{x}^j\dot{x}^k"
                  r"+\frac{2m}{2\phi}\frac{\partial V}{\partial x^i}g_{jk}\dot{x}^j\dot{x}^k=0",
        effect="the potential's force is doubled: with the printed form the extremals are the "
               "motions under 2V, not V (the next line, which is right, does not follow)",
        printed_residual=printed, corrected_residual=corrected,
    )


@check("action-integral.i3")
def _action_time_change() -> Finding:
    """On the motion, T + V = h gives g_jk (dxʲ/dt)(dxᵏ/dt) = 2(h − V)/m; with
    ẋ = (dx/dt)(dt/dτ), φ = 2(h − V) dt/dτ."""
    a = _action()
    d = dimensions()
    rate = sp.Symbol("r", positive=True)  # dt/dτ
    # on the motion: Q = g ẋẋ = (2(h − V)/m) r²
    phi_on_motion = a.phi.subs(a.Q, 2 * (a.h - a.V) / a.m * rate**2)
    solved = sp.solve(sp.Eq(sp.Symbol("phi", positive=True), sp.simplify(phi_on_motion)), rate)
    printed_dim = sp.simplify(sp.sqrt(d["M"] * d["phi"]) / sp.sqrt(d["energy"]))
    corrected_dim = sp.simplify(d["phi"] / d["energy"])
    expected = d["T"] / d["Θ"]

    def printed() -> sp.Expr:
        return sp.simplify(printed_dim / expected - 1)

    def corrected() -> sp.Expr:
        return sp.simplify(corrected_dim / expected - 1)

    return Finding(
        verdict=Verdict.ERRATUM, method=Method.DIMENSION,
        uses=("action-integral.d3", "action-integral.i1", "2.2.21"),
        evidence=f"dt/dτ must have the dimension T/Θ. On the motion T + V = h gives "
                 f"g_jk (dxʲ/dt)(dxᵏ/dt) = 2(h − V)/m, so φ = 2(h − V) dt/dτ (sympy solves "
                 f"dt/dτ = {solved[0] if solved else '?'}), of dimension {corrected_dim}. The "
                 f"printed √(mφ)/√(2(h − V)) has dimension {printed_dim}: not a rate of time. "
                 "With the corrected rate the corrected Euler–Lagrange line becomes the printed "
                 "final equation (action-integral.d6) exactly.",
        corrected=r"\frac{dt}{d\tau} = \frac{\phi}{2(h-V)}",
        printed_residual=printed, corrected_residual=corrected,
    )


@check("action-integral.d6")
def _action_final() -> Finding:
    """The corrected d5 with dt/dτ = φ/(2(h − V)) divided by dt/dτ is the printed line."""
    a = _action()
    t = sp.Symbol("t")
    y = tuple(sp.Function(f"y{i + 1}")(t) for i in range(2))  # x(t)
    yd = [yi.diff(t) for yi in y]
    at = {a.xs[i]: y[i] for i in range(2)}
    g = a.g.subs(at)
    V = a.V.subs(at)
    Qt = sum(g[j, k] * yd[j] * yd[k] for j in range(2) for k in range(2))
    r = sp.Symbol("r", positive=True)  # dt/dτ, eliminated below
    phi = 2 * (a.h - V) * r
    ok = True
    for i in range(2):
        # corrected d5, each τ-derivative d/dτ = r d/dt, ẋ = r ẏ, on the energy surface
        bracket = 2 * a.m / phi * (a.h - V) * sum(g[i, k] * r * yd[k] for k in range(2))
        d5 = (r * bracket.diff(t)
              - 2 * a.m / (2 * phi) * (a.h - V) * sum(
                  a.g[j, k].diff(a.xs[i]).subs(at) * r**2 * yd[j] * yd[k]
                  for j in range(2) for k in range(2))
              + 2 * a.m / (2 * phi) * a.V.diff(a.xs[i]).subs(at) * r**2 * Qt)
        printed = (a.m * sum(g[i, k] * yd[k] for k in range(2)).diff(t)
                   - a.m / 2 * sum(a.g[j, k].diff(a.xs[i]).subs(at) * yd[j] * yd[k]
                                   for j in range(2) for k in range(2))
                   + a.V.diff(a.xs[i]).subs(at))
        energy = {a.h: V + a.m / 2 * Qt}  # T + V = h on the motion
        ok &= zero((d5 / r - printed).subs(energy))
    return derived(
        ok, method=Method.SYMPY,
        uses=("action-integral.d5", "action-integral.i3", "action-integral.i1"),
        evidence="the corrected Euler–Lagrange line, with d/dτ = (dt/dτ) d/dt, "
                 "dt/dτ = φ/(2(h − V)) and T + V = h, divided by dt/dτ, equals the printed "
                 "m d/dt(g_ik dxᵏ/dt) − (m/2) ∂g_jk/∂xⁱ (dxʲ/dt)(dxᵏ/dt) + ∂V/∂xⁱ (sympy, "
                 "general 2-D metric and potential) — which is (2.2.24) with (2.2.22)",
    )


@check("action-integral.d1")
def _action_line_element() -> Finding:
    d = dimensions()
    dim = sp.simplify(d["M"] * d["energy"] * d["L"] ** 2)
    return Finding(
        verdict=Verdict.HOLDS, method=Method.DIMENSION, uses=("2.2.21",),
        evidence=f"a definition (Jacobi's metric); its square has dimension {dim} (action² = "
                 "(M L² T⁻¹)²) — consistent with A = ∫ds being an action (d2); tested as a "
                 "geodesic of the Kepler case in tests/reference/test_particle.py",
    )


@check("action-integral.d2", "action-integral.d3")
def _action_integral() -> Finding:
    a = _action()
    d = dimensions()
    ok = zero(a.phi**2 - 2 * a.m * (a.h - a.V) * a.Q)
    return derived(
        ok, method=Method.DIMENSION,
        uses=("action-integral.d1",),
        evidence=f"A = ∫ ds with ds² of action-integral.d1 and ds = φ dτ: φ² = 2m(h − V) g "
                 f"ẋẋ (sympy); φ dτ has dimension {sp.simplify(d['phi'] * d['Θ'])} "
                 "(an action, M L² T⁻¹)",
    )


@check("action-integral.i1")
def _energy_constant() -> Finding:
    return Finding(
        verdict=Verdict.HOLDS, method=Method.SYMPY, uses=("variational.i8",),
        evidence="the energy constant of variational.i8 (derived there), named h",
    )


@check("action-integral.i2")
def _tau_dot() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="a notation: the dot means d/dτ in this subsection (the source of the "
                 "d/dt-for-d/dτ slip in action-integral.d5)",
    )
