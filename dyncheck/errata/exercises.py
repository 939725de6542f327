"""The results the exercises of §2.2 state (2–5, 18–20, 22, 25, 27, 28). An exercise's data
(a curve, a point, an instant) hold when they pose the problem the exercise asks — the curve
regular there, the points in general position, the claim decidable — and the check says what
the answer is."""

from __future__ import annotations

import sympy as sp

from dyncheck.errata.lagrange import (
    acceleration,
    christoffel,
    general_lagrange,
    partial,
    spherical_map,
)
from dyncheck.errata.registry import Finding, Method, Verdict, check, derived, dimensions, zero


def _vec(m: sp.Matrix) -> str:
    return "(" + ", ".join(str(sp.simplify(e)) for e in m) + ")"


@check("ex2.i1", "ex2.i2", "ex2.i3", "ex2.i4")
def _exercise_2() -> Finding:
    t = sp.Symbol("t", real=True)
    r = sp.Matrix([sp.sin(t) ** 2 / 2, t / 2 - sp.sin(2 * t) / 4, sp.sin(t)])
    rd = r.diff(t)
    unit_speed = zero((rd.T * rd)[0] - 1)
    T, dT = rd.subs(t, sp.pi), rd.diff(t).subs(t, sp.pi)  # unit speed: d/ds = d/dt
    kappa = sp.sqrt((dT.T * dT)[0])
    N = dT / kappa
    B = T.cross(N)
    return derived(
        unit_speed and kappa != 0, method=Method.SYMPY, uses=("2.2.8", "2.2.13"),
        evidence=f"the data pose the problem: the curve has unit speed (|r′|² = 1, sympy), so "
                 f"t is its arc length, and at t = π κ = {kappa} ≠ 0: T = {_vec(T)}, "
                 f"N = {_vec(N)}, B = T × N = {_vec(B)}",
    )


@check("ex3.i1", "ex3.i2", "ex3.i3", "ex3.i4")
def _exercise_3() -> Finding:
    t = sp.Symbol("t")
    roots = sp.solve(11 * t - 6 * t**2 + t**3 - 6, t)
    points = ", ".join(str((r, r**2, r**3)) for r in sorted(roots))
    return derived(
        len(set(roots)) == 3 and all(r.is_real for r in roots), method=Method.SYMPY,
        evidence="on the curve 11x − 6y + z − 6 = t³ − 6t² + 11t − 6 = "
                 f"{sp.factor(t**3 - 6 * t**2 + 11 * t - 6)}: the claim is true, the points "
                 f"are {points} (sympy)",
    )


@check("ex4.i1")
def _exercise_4() -> Finding:
    p = [sp.Matrix(v) for v in ((3, 0, 0), (0, 4, 0), (0, 0, 5))]
    normal = (p[1] - p[0]).cross(p[2] - p[0])
    unit = normal / normal.norm()
    return derived(
        normal != sp.zeros(3, 1), method=Method.SYMPY,
        evidence=f"notation for the parametrization asked for; the data pose the problem: "
                 f"P₁, P₂, P₃ are not collinear, the plane is x/3 + y/4 + z/5 = 1 with unit "
                 f"normal {_vec(unit)} (sympy)",
    )


@check("ex5.i1", "ex5.i2", "ex5.i3", "ex5.i4", "ex5.i5")
def _exercise_5() -> Finding:
    t = sp.Symbol("t", real=True)
    r = sp.Matrix([sp.sin(t), sp.cos(t), 2 * t / sp.pi])
    tangent = r.diff(t).subs(t, sp.pi / 4)
    return derived(
        tangent != sp.zeros(3, 1), method=Method.SYMPY,
        evidence=f"the helix is regular at t = π/4 (r′ = {_vec(tangent)} ≠ 0): the tangent "
                 "line r(π/4) + λ r′(π/4) exists. A curve has no tangent plane; the plane "
                 "through r(π/4) perpendicular to r′ (the normal plane) is presumably meant — "
                 "a wording matter, not a formula",
    )


@check("ex18.i1", "ex18.i6", "ex18.i7", "ex19.i4", "ex20.i1", "ex20.i2", "ex27.i1", "ex27.i2")
def _exercise_definitions() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="the exercise's definitions or notation (φ = ds/dt, the surface coordinates "
                 "u¹ = θ, u² = z, ẋⁱ = vⁱ, H = T + V as a function of x and p, a force field "
                 "and a curve); their consequences are checked",
    )


@check("ex18.i2")
def _arc_length() -> Finding:
    return Finding(
        verdict=Verdict.HOLDS, method=Method.SYMPY, uses=("frenet-serret.d1",),
        evidence="the positive root of ds² = g_mn dxᵐ dxⁿ (frenet-serret.d1, checked) along "
                 "a curve xⁱ(t); with φ = ds/dt the integral (2.2.35) is ∫ ds, the length",
    )


def _shortest_residuals() -> tuple[sp.Matrix, sp.Matrix]:
    """A straight line of the plane run at a varying speed, x = (t², 2t²): a shortest path.
    The printed and the corrected right-hand sides, as residuals ẍ + Γẋẋ − rhs (Γ = 0)."""
    t = sp.Symbol("t", positive=True)
    x = sp.Matrix([t**2, 2 * t**2])
    sd = sp.sqrt((x.diff(t).T * x.diff(t))[0])
    sdd = sd.diff(t)
    printed = x.diff(t, 2) - x.diff(t) * sdd
    corrected = x.diff(t, 2) - x.diff(t) * sdd / sd
    return printed.subs(t, 1), corrected.subs(t, 1)


@check("ex18.i3")
def _shortest_path() -> Finding:
    c = general_lagrange()
    Q = sum(c.g[m, n] * c.xd[m] * c.xd[n] for m in range(2) for n in range(2))
    phi = sp.sqrt(Q)  # ds/dt
    sd, sdd = phi, phi.diff(c.t)
    el = [partial(phi, c.xd[i]).diff(c.t) - partial(phi, c.x[i]) for i in range(2)]
    geo = acceleration(c)  # ẍⁱ + {i; j k} ẋʲẋᵏ
    # (2.2.36) for φ equals g_ik/ṡ (ẍᵏ + Γᵏ ẋẋ − ẋᵏ s̈/ṡ): the corrected line
    general = [el[i] - sum(c.g[i, k] / sd * (geo[k] - c.xd[k] * sdd / sd) for k in range(2))
               for i in range(2)]
    d = dimensions()
    lhs_dim, printed_dim = d["L"] / d["T"] ** 2, (d["L"] / d["T"]) * (d["L"] / d["T"] ** 2)
    printed, corrected = _shortest_residuals()
    return Finding(
        verdict=Verdict.ERRATUM, method=Method.SYMPY,
        uses=("2.2.36", "ex18.i1", "ex18.i2"),
        evidence="(2.2.36) for φ = ds/dt = (g_mn ẋᵐẋⁿ)^½, differentiated by sympy on a "
                 "general 2-D metric, is (g_ik/ṡ)(ẍᵏ + {k; j l}ẋʲẋˡ − ẋᵏ s̈/ṡ): the "
                 "right-hand side is ẋⁱ s̈/ṡ, not ẋⁱ s̈. The printed line is not homogeneous "
                 f"in dimension ({lhs_dim} against {printed_dim} for coordinates of length) "
                 "and a straight line of the plane run at varying speed, x = (t², 2t²), "
                 "fails it (residual at t = 1 "
                 f"{_vec(printed)}) while satisfying the corrected one. With t = s (ṡ = 1, "
                 "s̈ = 0) both reduce to the geodesic equations of part (c), which is why the "
                 "slip is invisible there",
        corrected=r"\ddot{x}^i + \left\{ \begin{matrix} i \\ j k \end{matrix} \right\} "
                  r"\dot{x}^j \dot{x}^k = \dot{x}^i \frac{d^2s/dt^2}{ds/dt}",
        effect="only at parameters other than arc length: the printed equations are not "
               "those of the shortest curves (they are not even invariant under t → 2t)",
        printed_residual=lambda: sum(e**2 for e in printed),
        corrected_residual=lambda: sum(e**2 for e in corrected) + sum(
            sp.simplify(r) for r in general),
    )


@check("ex18.i4", "ex18.i5")
def _geodesic() -> Finding:
    s = sp.Symbol("s")
    X, V = sp.symbols("X1 X2"), sp.symbols("V1 V2")
    g = sp.diag(1, sp.sin(X[0]) ** 2)  # the unit sphere, (θ, φ)
    gamma = christoffel(g, X)
    length = sp.sqrt(sum(g[m, n] * V[m] * V[n] for m in range(2) for n in range(2)))
    ok = True
    # at unit speed (t = s): the equator, a great circle, and the circle of latitude π/3
    for curve, is_geodesic in (((sp.pi / 2, s), True),
                               ((sp.pi / 3, s / sp.sin(sp.pi / 3)), False)):
        on = {**dict(zip(X, curve, strict=True)),
              **{V[i]: curve[i].diff(s) for i in range(2)}}
        ok &= zero(length.subs(on) - 1)
        el = [length.diff(V[i]).subs(on).diff(s) - length.diff(X[i]).subs(on)
              for i in range(2)]  # (2.2.36) for the length, part (b)
        printed = [curve[i].diff(s, 2) + sum(gamma[i][j][k].subs(on) * curve[j].diff(s)
                                             * curve[k].diff(s) for j in range(2)
                                             for k in range(2)) for i in range(2)]
        ok &= all(zero(el[i] - sum(g[i, k].subs(on) * printed[k] for k in range(2)))
                  for i in range(2))  # (b) at ṡ = 1, s̈ = 0 is g_ik times (c)'s left side
        ok &= all(zero(e) for e in printed) == is_geodesic
    return derived(
        ok, method=Method.SYMPY,
        uses=("ex18.i3", "2.2.36"),
        evidence="on the unit sphere, along two curves at unit speed (t = s: ṡ = 1, s̈ = 0), "
                 "the Euler–Lagrange expressions of the length are g_ik times the left sides "
                 "of the printed d²xⁱ/ds² + {i; j k} dxʲ/ds dxᵏ/ds = 0 — part (b) reduces to "
                 "(c) (the printed (b) gives the same here) — and these vanish on the equator, "
                 "a great circle, and not on the circle of latitude π/3 (sympy)",
    )


@check("ex18.i8", "ex18.i9", "ex18.i10")
def _cylinder() -> Finding:
    a, H = sp.symbols("a H", positive=True)
    th, z = sp.symbols("theta z")
    g = sp.Matrix([[a**2, 0], [0, 1]])  # ds² = a² dθ² + dz² on the cylinder
    coords = (th, z)
    flat = all(g[i, j].diff(coords[k]) == 0 for i in range(2) for j in range(2)
               for k in range(2))  # every Christoffel symbol vanishes
    # the geodesics are then θ, z linear in s; the one from (0, 0) to (±π, H):
    lengths = [sp.sqrt(a**2 * dth**2 + H**2) for dth in (sp.pi, -sp.pi)]
    ok = flat and all(zero(length - sp.sqrt(a**2 * sp.pi**2 + H**2)) for length in lengths)
    return derived(
        ok, method=Method.SYMPY, uses=("ex18.i5",),
        evidence="the cylinder's metric a²dθ² + dz² has constant components, so every "
                 "Christoffel symbol vanishes and the geodesics (ex18.i5) are θ, z linear in "
                 "s; the one from θ = 0, z = 0 to θ = π, z = H (either way round) has length "
                 "√(a²π² + H²) (sympy)",
    )


@check("ex19.i1")
def _kinetic_energy() -> Finding:
    return Finding(
        verdict=Verdict.HOLDS, method=Method.SYMPY, uses=("particle-movement.d6", "2.2.21"),
        evidence="T = ½mv² with v² = g_ij vⁱvʲ (particle-movement.d6, checked by sympy)",
    )


@check("ex20.i3", "ex20.i4", "ex20.i5", "ex20.i6", "ex22.i1", "ex22.i2", "ex22.i3", "ex22.i4")
def _hamilton() -> Finding:
    c = general_lagrange()
    ginv = c.g.inv()
    p = [c.M * sum(c.g[i, j] * c.xd[j] for j in range(2)) for i in range(2)]
    ok = all(zero(partial(c.T, c.xd[i]) - p[i]) for i in range(2))  # p_i = ∂T/∂ẋⁱ
    P = sp.symbols("P1 P2")
    X = sp.symbols("X1 X2")
    at = dict(zip(c.x, X, strict=True))
    H = sum(ginv[i, j].subs(at) * P[i] * P[j] for i in range(2) for j in range(2)) / (2 * c.M) \
        + c.V.subs(at)
    on = {**{X[i]: c.x[i] for i in range(2)}, **{P[i]: p[i] for i in range(2)}}
    ok &= zero(H.subs(on) - (c.T + c.V))  # H = T + V in terms of p
    ok &= all(zero(H.diff(P[i]).subs(on) - c.xd[i]) for i in range(2))  # dxⁱ/dt = ∂H/∂p_i
    L = c.T - c.V
    ok &= all(zero(H.diff(X[i]).subs(on) + partial(L, c.x[i])) for i in range(2))  # ex22 (b)
    motion = sp.solve([partial(L, c.xd[i]).diff(c.t) - partial(L, c.x[i]) for i in range(2)],
                      list(c.xdd), dict=True)[0]  # Lagrange's equations (2.2.26)
    ok &= all(zero((p[i].diff(c.t) + H.diff(X[i]).subs(on)).subs(motion)) for i in range(2))
    # (a): p is covariant — in spherical coordinates p equals Jᵀ times the Cartesian momentum
    t, m = sp.symbols("t m", positive=True)
    q, cart = spherical_map(t)
    J = sp.Matrix(3, 3, lambda r, j: partial(cart[r], q[j]))
    qd = sp.Matrix([qi.diff(t) for qi in q])
    ok &= all(zero(e) for e in m * (J.T * J) * qd - J.T * (m * cart.diff(t)))
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.21", "2.2.26"),
        evidence="on a general 2-D metric and potential (sympy): p_i = M g_ij ẋʲ = ∂T/∂ẋⁱ; "
                 "H = g^{ij}p_ip_j/(2M) + V equals T + V at that p; ∂H/∂p_i = ẋⁱ; "
                 "∂H/∂xⁱ = −∂L/∂xⁱ (p and ẋ held in turn); on a motion (Lagrange's "
                 "equations) dp_i/dt = −∂H/∂xⁱ. In spherical coordinates m g_ij ẋʲ = Jᵀ(mẋ) "
                 "(J = ∂x_cart/∂q): p transforms as a covariant vector",
    )


@check("ex25.i1", "ex25.i2", "ex25.i3")
def _kepler() -> Finding:
    t, G, M = sp.symbols("t G M", positive=True)
    r = sp.Matrix([sp.Function(f"r{i}")(t) for i in (1, 2, 3)])
    norm = sp.sqrt((r.T * r)[0])
    newton = {r[i].diff(t, 2): -G * M * r[i] / norm**3 for i in range(3)}  # m r̈ = F
    ok = all(zero(e) for e in r.cross(r.diff(t)).diff(t).subs(newton))
    d = dimensions()
    G_dim = d["L"] ** 3 / (d["M"] * d["T"] ** 2)
    force = sp.simplify(G_dim * d["M"] ** 2 / d["L"] ** 2)
    ok &= force == d["M"] * d["L"] / d["T"] ** 2
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.18",),
        evidence=f"GMm/r² is a force ({force}, with G in L³/(M T²)); with m r̈ = −GMm r/r³, "
                 "d/dt(r × ṙ) = ṙ × ṙ + r × r̈ = 0 (sympy), so r × v = h is constant",
    )


@check("ex27.i3", "ex27.d1", "ex27.d2")
def _work_energy() -> Finding:
    t, m = sp.symbols("t m", positive=True)
    x = sp.Matrix([sp.Function(f"x{i}")(t) for i in (1, 2, 3)])
    F = m * x.diff(t, 2)  # Newton's law along C
    ok = all(zero((m * x[i].diff(t) ** 2 / 2).diff(t) - F[i] * x[i].diff(t)) for i in range(3))
    v2 = (x.diff(t).T * x.diff(t))[0]
    ok &= zero((m * v2 / 2).diff(t) - (F.T * x.diff(t))[0])
    path = sp.Matrix([t, t**2, sp.sin(t)])  # one curve, end points t = 0 and t = 2
    force = m * path.diff(t, 2)
    line = sp.integrate((force.T * path.diff(t))[0], (t, 0, 2))  # ∫ F_i dxⁱ along C
    speed2 = (path.diff(t).T * path.diff(t))[0]
    ok &= zero(line - m / 2 * (speed2.subs(t, 2) - speed2.subs(t, 0)))
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.18",),
        evidence="with m ẍ_i = F_i along a general curve: d/dt(½m ẋ_i²) = F_i ẋ_i for each i "
                 "and their sum d/dt(½mv²) = F_i ẋⁱ (sympy); on the curve (t, t², sin t) the "
                 "line integral ∫F_i dxⁱ from t = 0 to 2 equals ½mv² between its ends",
    )


@check("ex28.d1")
def _spherical_pendulum() -> Finding:
    t, m, g, ell = sp.symbols("t m g ell", positive=True)
    ph, th = sp.Function("phi")(t), sp.Function("theta")(t)
    pos = ell * sp.Matrix([sp.sin(ph) * sp.sin(th), sp.sin(ph) * sp.cos(th), sp.cos(ph)])
    L = m / 2 * (pos.diff(t).T * pos.diff(t))[0] + m * g * pos[2]  # z down: V = −mgz
    e_th = partial(L, th.diff(t)).diff(t) - partial(L, th)
    e_ph = partial(L, ph.diff(t)).diff(t) - partial(L, ph)
    ok = zero(e_th - m * ell**2 * (sp.sin(ph) ** 2 * th.diff(t)).diff(t))
    ok &= zero(e_ph / (m * ell**2) - (ph.diff(t, 2) - th.diff(t) ** 2 * sp.sin(ph)
                                      * sp.cos(ph) + g / ell * sp.sin(ph)))
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.26",),
        evidence="bob at ℓ(sinϕ sinθ, sinϕ cosθ, cosϕ), z down (ϕ from the z axis, θ from "
                 "the y axis), L = ½m|ṙ|² + mgz: Lagrange's equations are mℓ² times the two "
                 "printed ones (sympy); the engines integrate them in the run "
                 "(reports/spherical_pendulum.md)",
    )
