"""Rigid bodies: particles, inertia and momenta (2.2.37)–(2.2.49) and Euler's equations
(2.2.70)–(2.2.72)."""

from __future__ import annotations

from functools import cache

import sympy as sp

from dyncheck.errata.registry import Finding, Method, Verdict, check, derived, zero


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


def levi_civita(i: int, j: int, k: int) -> int:
    return int(sp.LeviCivita(i, j, k))


@check("2.2.37", "2.2.38", "rigid-body.d3", "2.2.39", "2.2.40")
def _rigid_kinetic() -> Finding:
    ms, xs, w, inertia = _particles()
    ok = True
    T_sum = 0
    for m, x in zip(ms, xs, strict=True):
        v = sp.Matrix([sum(levi_civita(i, j, k) * w[j] * x[k] for j in range(3) for k in range(3))
                       for i in range(3)])
        ok &= all(zero(e) for e in v - w.cross(x))
        T_sum += m / 2 * (v.T * v)[0]
        edelta = m / 2 * ((w.T * w)[0] * (x.T * x)[0] - ((w.T * x)[0]) ** 2)
        ok &= zero(m / 2 * (v.T * v)[0] - edelta)
    ok &= zero(T_sum - (w.T * inertia * w)[0] / 2)
    return derived(
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
    return derived(
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
    return derived(
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
                         - sum(levi_civita(tt, m, j) * inertia[i, j] * w[i] * w[tt]
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
    return derived(
        ok, method=Method.SYMPY,
        uses=("2.2.49", "2.2.42"),
        evidence="(2.2.70) expanded equals I ω̇ + ω × (I ω), Euler's equations in body axes "
                 "(from (2.2.49) with H = I ω); the printed rows (2.2.71) equal (2.2.70) for a "
                 "symmetric I, and with I diagonal they are the printed (2.2.72) (sympy)",
    )
