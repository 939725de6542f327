"""The checks of §2.2's formulas: for each inventory id, a sympy derivation from the formulas
it is derived from (its chain of custody), a dimensional check, or the reason it cannot be
checked. Each check ends in a :class:`Finding`; an erratum carries the corrected form and a
residual that vanishes for it and not for the printed one (both evaluated here, and by the
tests).

Notation of the derivations: a 2-dimensional space with a general metric g_jk(x¹, x²) and a
general potential V(x¹, x²) (the results are identities in N; N = 2 is the smallest case with
every term), curves x^k(τ) as sympy functions; in dimensional checks M (mass), L (length),
T (time) and Θ (the unit of a curve parameter τ that need not be time).
"""

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


def _derived(ok: bool, **evidence: object) -> Finding:
    """A derivation's finding: ``holds`` when it came out, else ``erratum`` (then the check
    must be rewritten to carry the corrected form — the tests demand it)."""
    return Finding(verdict=Verdict.HOLDS if ok else Verdict.ERRATUM, **evidence)  # type: ignore[arg-type]


def zero(expr: sp.Expr) -> bool:
    return sp.simplify(expr) == 0


# --- the action integral (stationary action, geodesics of 2m(h - V) g) ----------------------


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
    return _derived(
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


def _dims() -> dict[str, sp.Expr]:
    M, L, T, Th = sp.symbols("M L T Θ", positive=True)
    energy = M * L**2 / T**2
    phi = sp.sqrt(M * energy * (L / Th) ** 2)
    return {"M": M, "L": L, "T": T, "Θ": Th, "energy": energy, "phi": phi}


@check("action-integral.i3")
def _action_time_change() -> Finding:
    """On the motion, T + V = h gives g_jk (dxʲ/dt)(dxᵏ/dt) = 2(h − V)/m; with
    ẋ = (dx/dt)(dt/dτ), φ = 2(h − V) dt/dτ."""
    a = _action()
    d = _dims()
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
    return _derived(
        ok, method=Method.SYMPY,
        uses=("action-integral.d5", "action-integral.i3", "action-integral.i1"),
        evidence="the corrected Euler–Lagrange line, with d/dτ = (dt/dτ) d/dt, "
                 "dt/dτ = φ/(2(h − V)) and T + V = h, divided by dt/dτ, equals the printed "
                 "m d/dt(g_ik dxᵏ/dt) − (m/2) ∂g_jk/∂xⁱ (dxʲ/dt)(dxᵏ/dt) + ∂V/∂xⁱ (sympy, "
                 "general 2-D metric and potential) — which is (2.2.24) with (2.2.22)",
    )


@check("action-integral.d1")
def _action_line_element() -> Finding:
    d = _dims()
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
    d = _dims()
    ok = zero(a.phi**2 - 2 * a.m * (a.h - a.V) * a.Q)
    return _derived(
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


def findings(ids: list[str]) -> dict[str, Finding]:
    """Each id's finding (PENDING where no check is written yet)."""
    out = {}
    for ident in ids:
        fn = CHECKS.get(ident)
        out[ident] = fn() if fn else Finding(verdict=Verdict.PENDING, method=Method.NONE,
                                             evidence="no check written yet")
    return out


# --- Lagrange's equations on a general metric (2.2.5, 2.2.21–2.2.26, exercises 8–11) ---------


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


@cache
def _lagrange() -> _Lagrange:
    t, M = sp.symbols("t M", positive=True)
    x = tuple(sp.Function(f"x{i + 1}")(t) for i in range(2))
    xd = tuple(xi.diff(t) for xi in x)
    xdd = tuple(xi.diff(t, 2) for xi in x)
    p = sp.symbols("p1 p2")
    g11, g12, g22, V = (sp.Function(n)(*p) for n in ("g11", "g12", "g22", "V"))
    g_p = sp.Matrix([[g11, g12], [g12, g22]])
    ginv = g_p.inv()
    gamma_p = tuple(tuple(tuple(
        sum(ginv[i, r] * (g_p[r, m].diff(p[n]) + g_p[r, n].diff(p[m]) - g_p[m, n].diff(p[r]))
            for r in range(2)) / 2 for n in range(2)) for m in range(2)) for i in range(2))
    at = dict(zip(p, x, strict=True))
    g = g_p.subs(at)
    gamma = tuple(tuple(tuple(c.subs(at) for c in row) for row in mat) for mat in gamma_p)
    T = M / 2 * sum(g[m, n] * xd[m] * xd[n] for m in range(2) for n in range(2))
    return _Lagrange(t, M, x, xd, xdd, g, V.subs(at), T, gamma)


def _d(expr: sp.Expr, var: sp.Expr) -> sp.Expr:
    """∂expr/∂var for var a coordinate x(t) or a velocity ẋ(t), the others held fixed."""
    s = sp.Dummy()
    return expr.subs(var, s).diff(s).subs(s, var)


def _acceleration(c: _Lagrange) -> list[sp.Expr]:
    """fⁱ of (2.2.5): ẍⁱ + {i; m n} ẋᵐ ẋⁿ."""
    return [c.xdd[i] + sum(c.gamma[i][m][n] * c.xd[m] * c.xd[n] for m in range(2)
                           for n in range(2)) for i in range(2)]


@check("2.2.22", "ex8.i1", "ex9.i1", "ex10.i1")
def _lagrange_derivatives() -> Finding:
    c = _lagrange()
    ok = True
    for r in range(2):
        p_r = _d(c.T, c.xd[r])
        ok &= zero(p_r - c.M * sum(c.g[r, m] * c.xd[m] for m in range(2)))
        dg = [sum(_d(c.g[r, m], c.x[n]) * c.xd[n] for n in range(2)) for m in range(2)]
        ok &= zero(p_r.diff(c.t) - c.M * sum(c.g[r, m] * c.xdd[m] + dg[m] * c.xd[m]
                                             for m in range(2)))
        ok &= zero(_d(c.T, c.x[r]) - c.M / 2 * sum(_d(c.g[m, n], c.x[r]) * c.xd[m] * c.xd[n]
                                                    for m in range(2) for n in range(2)))
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.21",),
        evidence="∂T/∂ẋʳ, d/dt ∂T/∂ẋʳ and ∂T/∂xʳ of T = ½ M g_mn ẋᵐẋⁿ, differentiated by "
                 "sympy on a general 2-D metric along a general curve, equal the three printed "
                 "lines (the exercises 8–10 state the same three results)",
    )


@check("2.2.23")
def _lagrange_form() -> Finding:
    c = _lagrange()
    f = _acceleration(c)
    ok = all(zero(_d(c.T, c.xd[r]).diff(c.t) - _d(c.T, c.x[r])
                  - c.M * sum(c.g[r, i] * f[i] for i in range(2))) for r in range(2))
    return _derived(
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
    ginv = g.inv()
    gamma = [[[sp.simplify(sum(ginv[i, r] * (g[r, m].diff(p[n]) + g[r, n].diff(p[m])
                                             - g[m, n].diff(p[r])) for r in range(3)) / 2)
               for n in range(3)] for m in range(3)] for i in range(3)]
    at = dict(zip(p, q, strict=True))
    qd = [qi.diff(t) for qi in q]
    f = sp.Matrix([q[i].diff(t, 2) + sum(gamma[i][m][n].subs(at) * qd[m] * qd[n]
                                         for m in range(3) for n in range(3)) for i in range(3)])
    accel = cart.subs(at).diff(t, 2)
    ok = all(zero(e) for e in (accel - J.subs(at) * f))
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.2", "2.2.3", "2.2.4"),
        evidence="in spherical coordinates, J fⁱ with fⁱ = ẍⁱ + {i; m n} ẋᵐẋⁿ (Christoffel "
                 "symbols from g = JᵀJ) equals the Cartesian acceleration d²x/dt² exactly "
                 "(sympy): fⁱ are the components of the acceleration, a contravariant vector",
    )


def _spherical_map(t: sp.Symbol) -> tuple[list[sp.Expr], sp.Matrix]:
    """(ρ, θ, φ) as functions of t and the Cartesian point they name."""
    q = [sp.Function(n)(t) for n in ("rho", "theta", "phi")]
    return q, sp.Matrix([q[0] * sp.sin(q[1]) * sp.cos(q[2]), q[0] * sp.sin(q[1])
                         * sp.sin(q[2]), q[0] * sp.cos(q[1])])


@check("2.2.4")
def _velocity_chain_rule() -> Finding:
    t = sp.Symbol("t")
    q, cart = _spherical_map(t)
    J = sp.Matrix(3, 3, lambda r, j: _d(cart[r], q[j]))
    ok = all(zero(e) for e in cart.diff(t) - J * sp.Matrix([qi.diff(t) for qi in q]))
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.2", "2.2.3"),
        evidence="d x̄ʳ/dt = ∂x̄ʳ/∂xʲ vʲ for the spherical-to-Cartesian map (sympy)",
    )


@check("particle-movement.d6", "particle-movement.d8", "frenet-serret.d1")
def _squared_magnitudes() -> Finding:
    t = sp.Symbol("t")
    q, cart = _spherical_map(t)
    J = sp.Matrix(3, 3, lambda r, j: _d(cart[r], q[j]))
    v = sp.Matrix([qi.diff(t) for qi in q])
    ok = zero((cart.diff(t).T * cart.diff(t))[0] - (v.T * (J.T * J) * v)[0])
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.4",),
        evidence="|dx/dt|² in Cartesian coordinates equals g_ij vⁱvʲ with g = JᵀJ in "
                 "spherical coordinates (sympy); the same quadratic form gives f² = g_ij fⁱfʲ "
                 "for the vector fⁱ of (2.2.5) and ds² = g_ij dxⁱdxʲ",
    )


@check("2.2.21")
def _kinetic_forms() -> Finding:
    c = _lagrange()
    d = _dims()
    return Finding(
        verdict=Verdict.HOLDS, method=Method.DIMENSION, uses=("particle-movement.d6",),
        evidence="v = ds/dt and v² = g_mn vᵐvⁿ (particle-movement.d6) make the four forms "
                 f"one; each has dimension {sp.simplify(d['energy'])} (T = {c.T} in the "
                 "sympy context)",
    )


@check("2.2.24", "2.2.26", "2.2.34")
def _euler_lagrange() -> Finding:
    c = _lagrange()
    L = c.T - c.V
    ok = all(zero((_d(L, c.xd[r]).diff(c.t) - _d(L, c.x[r]))
                  - (_d(c.T, c.xd[r]).diff(c.t) - _d(c.T, c.x[r]) + _d(c.V, c.x[r])))
             for r in range(2))
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.23", "2.2.20", "2.2.25"),
        evidence="with L = T − V and V independent of ẋ, d/dt ∂L/∂ẋʳ − ∂L/∂xʳ = "
                 "d/dt ∂T/∂ẋʳ − ∂T/∂xʳ + ∂V/∂xʳ (sympy), which vanishes exactly when "
                 "(2.2.23) holds with Q_r = −∂V/∂xʳ (2.2.20)",
    )


@check("variational.d16", "variational.i6", "variational.i7", "variational.i8", "ex19.i2")
def _energy_conservation() -> Finding:
    c = _lagrange()
    f = _acceleration(c)
    power = c.M * sum(c.g[i, j] * c.xd[i] * f[j] for i in range(2) for j in range(2))
    ok = zero(c.T.diff(c.t) - power)
    # on a motion, M g_ij f^j = −∂V/∂x^i: dT/dt = −dV/dt
    motion = sp.solve([c.M * sum(c.g[i, j] * f[j] for j in range(2)) + _d(c.V, c.x[i])
                       for i in range(2)], list(c.xdd), dict=True)[0]
    ok &= zero((c.T + c.V).diff(c.t).subs(motion))
    return _derived(
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


# --- Examples 5–7 -----------------------------------------------------------------------------


def _lagrange_lhs(T: sp.Expr, q: sp.Expr, t: sp.Symbol) -> sp.Expr:
    return _d(T, q.diff(t)).diff(t) - _d(T, q)


@cache
def _spherical() -> tuple[sp.Symbol, sp.Symbol, list[sp.Expr], sp.Expr, sp.Expr]:
    t, M = sp.symbols("t M", positive=True)
    (rho, th, ph), x = _spherical_map(t)
    v2 = sp.simplify((x.diff(t).T * x.diff(t))[0])
    printed_v2 = rho.diff(t) ** 2 + rho**2 * th.diff(t) ** 2 + rho**2 * sp.sin(th) ** 2 \
        * ph.diff(t) ** 2
    return t, M, [rho, th, ph], v2, printed_v2


@check("example-5.d1", "example-5.d2")
def _spherical_metric() -> Finding:
    *_, v2, printed = _spherical()
    ok = zero(v2 - printed)
    return _derived(
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
    ok = all(zero(_lagrange_lhs(T, q, t) - p) for q, p in zip((rho, th, ph), printed,
                                                               strict=True))
    return _derived(
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
    ok &= zero(_lagrange_lhs(T, y1, t) - Q1 - ((m1 + m2) * y1.diff(t, 2) - (m1 - m2) * g))
    return _derived(
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
    lhs = _lagrange_lhs(L, th, t)
    ok &= zero(lhs - ((m * ell**2 * th.diff(t)).diff(t) - m * g * ell * (-sp.sin(th))))
    ok &= zero(lhs / (m * ell**2) - (th.diff(t, 2) + g / ell * sp.sin(th)))
    return _derived(
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
    return _derived(
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
    return _derived(
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
    e1, e2 = (_lagrange_lhs(L, q, t) for q in (th1, th2))
    d = th1 - th2
    row1 = (L1 * th1.diff(t, 2) + m2 / (m1 + m2) * L2 * th2.diff(t, 2) * sp.cos(d)
            + m2 / (m1 + m2) * L2 * th2.diff(t) ** 2 * sp.sin(d) + g * sp.sin(th1))
    row2 = (L1 * th1.diff(t, 2) * sp.cos(d) + L2 * th2.diff(t, 2)
            - L1 * th1.diff(t) ** 2 * sp.sin(d) + g * sp.sin(th2))
    ok = zero(e1 / ((m1 + m2) * L1) - row1) and zero(e2 / (m2 * L2) - row2)
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.29", "example-8.d3", "2.2.26"),
        evidence="Lagrange's equations of L = T − V, divided by (m₁ + m₂)L₁ and m₂L₂, are the "
                 "two printed rows (sympy); the engines agree with them to round-off "
                 "(reports/compound_pendulum.md)",
    )


@check("example-8.d7", "example-8.i4", "variational.d5",
       "2.2.25")
def _lagrangian() -> Finding:
    d = _dims()
    return Finding(
        verdict=Verdict.HOLDS, method=Method.DIMENSION, uses=("2.2.21", "2.2.20"),
        evidence=f"L = T − V: both energies ({d['energy']}); the Euler–Lagrange equations of "
                 "it are (2.2.26), derived from (2.2.23) in the check of (2.2.24)",
    )


# --- rigid bodies: particles, inertia, momenta (2.2.37)–(2.2.49), Euler's equations ----------


@cache
def _particles() -> tuple[list[sp.Symbol], list[sp.Matrix], sp.Matrix, sp.Matrix]:
    """Two particles of masses m_a at positions x_a, and ω (general symbols)."""
    ms = list(sp.symbols("m_a m_b", positive=True))
    xs = [sp.Matrix(sp.symbols(f"x{a}_1:4")) for a in "ab"]
    w = sp.Matrix(sp.symbols("w1:4"))
    inertia = sum((m * ((x.T * x)[0] * sp.eye(3) - x * x.T) for m, x in zip(ms, xs,
                                                                           strict=True)),
                  sp.zeros(3, 3))
    return ms, xs, w, inertia


def _eps(i: int, j: int, k: int) -> int:
    return int(sp.LeviCivita(i, j, k))


@check("2.2.37", "2.2.38", "rigid-body.d3", "2.2.39", "2.2.40")
def _rigid_kinetic() -> Finding:
    ms, xs, w, inertia = _particles()
    ok = True
    T_sum = 0
    for m, x in zip(ms, xs, strict=True):
        v = sp.Matrix([sum(_eps(i, j, k) * w[j] * x[k] for j in range(3) for k in range(3))
                       for i in range(3)])
        ok &= all(zero(e) for e in v - w.cross(x))
        T_sum += m / 2 * (v.T * v)[0]
        edelta = m / 2 * ((w.T * w)[0] * (x.T * x)[0] - ((w.T * x)[0]) ** 2)
        ok &= zero(m / 2 * (v.T * v)[0] - edelta)
    ok &= zero(T_sum - (w.T * inertia * w)[0] / 2)
    return _derived(
        ok, method=Method.SYMPY,
        evidence="for two particles at general positions: e_ijk ω_j x_k = (ω × r)_i, "
                 "½ Σ m V_iV_i = ½ Σ m (ω_mω_m x_kx_k − ω_nω_k x_kx_n) (the e–δ identity) "
                 "= ½ I_ij ω_iω_j with I of (2.2.39) (sympy)",
    )


@check("2.2.41", "2.2.42")
def _rigid_momentum() -> Finding:
    ms, xs, w, inertia = _particles()
    H = sum((m * x.cross(w.cross(x)) for m, x in zip(ms, xs, strict=True)), sp.zeros(3, 1))
    ok = all(zero(e) for e in H - inertia.T * w)
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.37", "2.2.39"),
        evidence="Σ m x × (ω × x) = ω_j I_ji for two particles at general positions (sympy)",
    )


@check("2.2.44", "rigid-body.d10", "2.2.45", "2.2.46", "2.2.47", "2.2.48", "2.2.49")
def _momentum_laws() -> Finding:
    t = sp.Symbol("t")
    ms = sp.symbols("m_a m_b", positive=True)
    xs = [sp.Matrix([sp.Function(f"x{a}{i}")(t) for i in range(1, 4)]) for a in "ab"]
    F = [sp.Matrix(sp.symbols(f"F{a}_1:4")) for a in "ab"]
    newton = {x[i].diff(t, 2): f[i] / m for m, x, f in zip(ms, xs, F, strict=True)
              for i in range(3)}  # (2.2.43)
    G = sum((m * x.diff(t) for m, x in zip(ms, xs, strict=True)), sp.zeros(3, 1))
    H = sum((m * x.cross(x.diff(t)) for m, x in zip(ms, xs, strict=True)), sp.zeros(3, 1))
    Mom = sum((x.cross(f) for x, f in zip(xs, F, strict=True)), sp.zeros(3, 1))
    ok = all(zero(e) for e in G.diff(t).subs(newton) - (F[0] + F[1]))
    ok &= all(zero(e) for e in H.diff(t).subs(newton) - Mom)
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.43",),
        evidence="with m ẍ = F for each particle (2.2.43): dG/dt = Σ F and d/dt Σ m x × ẋ = "
                 "Σ x × F (ẋ × ẋ = 0) for two particles on general paths (sympy) — the sums, "
                 "cross products and restatements (2.2.44)–(2.2.49)",
    )


@check("2.2.18", "2.2.43")
def _newton() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="Newton's second law: the chapter's axiom, from which the rest is derived",
    )


@check("rigid-body.i1", "rigid-body.i2", "rigid-body.i3", "rigid-body.i4", "2.2.3",
       "frenet-serret.i1", "velocity-acceleration.i1", "work.i2", "relative-motion.i1")
def _definition() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="a definition (it names a quantity); its uses are checked where they occur",
    )


@check("2.2.70", "2.2.71", "2.2.72")
def _euler_equations() -> Finding:
    t = sp.Symbol("t")
    w = sp.Matrix([sp.Function(f"w{i}")(t) for i in range(1, 4)])
    a, b, c, d, e, f = sp.symbols("I11 I22 I33 I12 I13 I23")
    inertia = sp.Matrix([[a, d, e], [d, b, f], [e, f, c]])
    newton_euler = inertia * w.diff(t) + w.cross(inertia * w)  # = M in body axes
    indexed = sp.Matrix([sum(inertia[i, m] * w[i].diff(t) for i in range(3))
                         - sum(_eps(tt, m, j) * inertia[i, j] * w[i] * w[tt]
                               for tt in range(3) for j in range(3) for i in range(3))
                         for m in range(3)])  # (2.2.70)
    ok = all(zero(x) for x in newton_euler - indexed)
    Iw = [sum(inertia[i, j] * w[i] for i in range(3)) for j in range(3)]
    rows = sp.Matrix([
        sum(inertia[i, 0] * w[i].diff(t) for i in range(3)) + Iw[2] * w[1] - Iw[1] * w[2],
        sum(inertia[i, 1] * w[i].diff(t) for i in range(3)) + Iw[0] * w[2] - Iw[2] * w[0],
        sum(inertia[i, 2] * w[i].diff(t) for i in range(3)) + Iw[1] * w[0] - Iw[0] * w[1],
    ])  # (2.2.71) as printed
    ok &= all(zero(x) for x in rows - indexed)
    principal = {d: 0, e: 0, f: 0}
    printed_72 = sp.Matrix([a * w[0].diff(t) + (c - b) * w[1] * w[2],
                            b * w[1].diff(t) + (a - c) * w[2] * w[0],
                            c * w[2].diff(t) + (b - a) * w[0] * w[1]])
    ok &= all(zero(x) for x in rows.subs(principal) - printed_72)
    return _derived(
        ok, method=Method.SYMPY,
        uses=("2.2.49", "2.2.42"),
        evidence="(2.2.70) expanded equals I ω̇ + ω × (I ω), Euler's equations in body axes "
                 "(from (2.2.49) with H = I ω); the printed rows (2.2.71) equal (2.2.70) for a "
                 "symmetric I, and with I diagonal they are the printed (2.2.72) (sympy)",
    )


# --- Frenet–Serret: (2.2.6)–(2.2.17), exercises 21 and 29 --------------------------------------

FRENET_POINTS = (sp.Rational(1, 3), sp.Integer(1), sp.Integer(2))
"""Parameter values of the twisted cubic (t, t², t³) where the identities are evaluated."""
DIGITS = 50


@cache
def _frenet(plane: bool = False) -> dict[str, sp.Matrix | sp.Expr]:
    """T, N, B, κ, τ and their s-derivatives of the twisted cubic (the parabola if ``plane``),
    built from the definitions (2.2.8), (2.2.13) alone."""
    t = sp.Symbol("t", positive=True)
    r = sp.Matrix([t, t**2, 0 if plane else t**3])
    speed = sp.sqrt((r.diff(t).T * r.diff(t))[0])
    T = r.diff(t) / speed
    dT = T.diff(t) / speed  # δ/δs = d/ds in Cartesian axes, ds = |r'| dt
    kappa = sp.sqrt((dT.T * dT)[0])
    N = dT / kappa
    dN = N.diff(t) / speed
    tb = dN + kappa * T  # (2.2.12)
    cross = T.cross(N)
    tau = (tb.T * cross)[0]  # τ with the sign that makes (2.2.13)'s B = T × N
    B = cross
    return {"t": t, "r": r, "speed": speed, "T": T, "dT": dT, "kappa": kappa, "N": N,
            "dN": dN, "tb": tb, "tau": tau, "B": B, "dB": B.diff(t) / speed}


def _vanishes(expr: sp.Expr | sp.Matrix, plane: bool = False) -> bool:
    """|expr| < 10⁻⁴⁰ at every point of FRENET_POINTS, evaluated to DIGITS digits."""
    f = _frenet(plane)
    values = expr if isinstance(expr, sp.MatrixBase) else sp.Matrix([expr])
    return all(abs(sp.N(v.subs(f["t"], p), DIGITS)) < sp.Float(10) ** -40
               for p in FRENET_POINTS for v in values)


def _dot(a: sp.Matrix, b: sp.Matrix) -> sp.Expr:
    return (a.T * b)[0]


FRENET_STEPS: dict[str, Callable[[dict], sp.Expr | sp.Matrix]] = {
    "2.2.6": lambda f: _dot(f["T"], f["T"]) - 1,
    "frenet-serret.d9": lambda f: _dot(f["T"], f["T"]) - 1,
    "frenet-serret.d3": lambda f: 2 * _dot(f["dT"], f["T"]),
    "2.2.7": lambda f: _dot(f["T"], f["dT"]),
    "2.2.8": lambda f: _dot(f["N"], f["N"]) - 1,
    "2.2.9": lambda f: _dot(f["T"], f["N"]),
    "frenet-serret.d7": lambda f: _dot(f["T"], f["dN"]) + _dot(f["dT"], f["N"]),
    "2.2.10": lambda f: sp.Matrix([_dot(f["T"], f["dN"]) + _dot(f["dT"], f["N"]),
                                   _dot(f["T"], f["dN"]) + f["kappa"]]),
    "2.2.11": lambda f: _dot(f["T"], f["tb"]),
    "2.2.12": lambda f: _dot(f["T"], f["tb"]),
    "frenet-serret.i3": lambda f: _dot(f["N"], f["N"]) - 1,
    "frenet-serret.d12": lambda f: _dot(f["N"], f["dN"]),
    "frenet-serret.d13": lambda f: _dot(f["N"], f["tb"]),
    "2.2.13": lambda f: f["tb"] / f["tau"] - f["B"],
    "frenet-serret.d15": lambda f: f["B"] - f["T"].cross(f["N"]),
    "2.2.14": lambda f: f["dB"] + f["tau"] * f["N"],
    "2.2.15": lambda f: sp.Matrix([*(f["dT"] - f["kappa"] * f["N"]),
                                   *(f["dN"] - f["tau"] * f["B"] + f["kappa"] * f["T"]),
                                   *(f["dB"] + f["tau"] * f["N"])]),
    "ex21.i1": lambda f: f["dT"] - f["kappa"] * f["N"],
    "ex21.i2": lambda f: f["dN"] - f["tau"] * f["B"] + f["kappa"] * f["T"],
    "ex21.i3": lambda f: f["B"] - f["T"].cross(f["N"]),
    "ex29.d1": lambda f: sp.Matrix([
        *(f["dT"] - (f["tau"] * f["T"] + f["kappa"] * f["B"]).cross(f["T"])),
        *(f["dN"] - (f["tau"] * f["T"] + f["kappa"] * f["B"]).cross(f["N"])),
        *(f["dB"] - (f["tau"] * f["T"] + f["kappa"] * f["B"]).cross(f["B"]))]),
    "2.2.16": lambda f: f["r"].diff(f["t"]) - f["T"] * f["speed"],
    "2.2.17": lambda f: f["r"].diff(f["t"], 2) - (f["speed"].diff(f["t"]) * f["T"]
                                                   + f["kappa"] * f["speed"] ** 2 * f["N"]),
}


def _frenet_finding(ident: str) -> Callable[[], Finding]:
    def run() -> Finding:
        ok = _vanishes(FRENET_STEPS[ident](_frenet()))
        return _derived(
            ok, method=Method.NUMERIC,
            uses=("2.2.8", "2.2.13"),
            evidence="on the twisted cubic (t, t², t³), T, N, B, κ, τ built from the "
                     "definitions (2.2.8) and (2.2.13) alone (sympy, exact), the relation's "
                     f"residual is below 1e-40 at t = 1/3, 1, 2 ({DIGITS} digits). In "
                     "Cartesian axes δ/δs = d/ds; a tensor relation that holds in one "
                     "coordinate system holds in all",
        )

    run.__name__ = run.__qualname__ = f"frenet_{ident}"
    return run


for _ident in FRENET_STEPS:
    check(_ident)(_frenet_finding(_ident))


@check("frenet-serret.i4")
def _plane_curve() -> Finding:
    ok = _vanishes(_frenet(plane=True)["tau"], plane=True) and not _vanishes(_frenet()["tau"])
    return _derived(
        ok, method=Method.NUMERIC,
        uses=("2.2.13",),
        evidence="τ of the parabola (t, t², 0) vanishes; τ of the twisted cubic does not",
    )


@check("frenet-serret.i2", "ex29.i1", "particle-movement.d2", "2.2.1", "2.2.2",
       "variational.d1", "work.i1")
def _definition_of_name() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="a definition or the statement of what is given (a curve, a map, a name)",
    )


# --- work and the variational derivation: (2.2.19)–(2.2.20), (2.2.30)–(2.2.36) ----------------


@check("2.2.19", "2.2.20", "conservative.i1")
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
    return _derived(
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
    return _derived(
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
