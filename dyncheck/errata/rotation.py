"""Relative motion and angular velocity (2.2.50)–(2.2.63), Example 9's Euler angles, the tensor
forms of Euler's equations (2.2.64)–(2.2.69), exercises 23 and 30.

Direction cosines in time are taken exact: ℓ(t) = (I − S)⁻¹(I + S), the Cayley transform of a
skew S(t) with polynomial entries — a proper orthogonal matrix of rational functions whose
angular velocity changes in size and direction — so that every identity is decided by exact
rational arithmetic. ℓ_ij = ê_i · ē_j: column j of ℓ is the body axis ē_j on the space axes,
x = ℓ x̄ (2.2.50).

Every formula is decided on the same exact direction cosines, the Cayley frame of
:mod:`.cayley`; exercise 30's triads are in :mod:`.triads`.
"""

from __future__ import annotations

from functools import cache

import sympy as sp

from dyncheck.errata.cayley import R3, dual, frame, generic, instant, nil, vee
from dyncheck.errata.registry import (
    POINTS,
    Finding,
    Method,
    Verdict,
    check,
    derived,
    zero,
)
from dyncheck.errata.rigid import levi_civita


@check("2.2.50", "2.2.51")
def _direction_cosines() -> Finding:
    t, ell = frame()
    x = sp.Matrix([sp.Function(f"x{i}")(t) for i in (1, 2, 3)])
    ok = nil(ell.T * ell - sp.eye(3)) and nil(ell * ell.T - sp.eye(3))
    ok &= nil(x - ell * (ell.T * x)) and sp.cancel(ell.det()) == 1
    return derived(
        ok, method=Method.SYMPY,
        evidence="for ℓ(t) the Cayley transform of a skew S(t) (entries t, t²/2, 1 − t/3): "
                 "ℓ_ij ℓ_ik = δ_jk and ℓ_ij ℓ_kj = δ_ik exactly, det ℓ = 1, and x̄_i = ℓ_ji x_j "
                 "inverts x_i = ℓ_ij x̄_j for a general moving point (sympy); Example 9's "
                 "matrix satisfies (2.2.51) too (example-9.d4)",
    )


def _rotation(axis: int, angle: sp.Expr) -> sp.Matrix:
    """Rodrigues' active rotation by ``angle`` about the coordinate axis ``axis``."""
    n = sp.Matrix([int(i == axis) for i in R3])
    cross = sp.Matrix([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return sp.cos(angle) * sp.eye(3) + sp.sin(angle) * cross + (1 - sp.cos(angle)) * n * n.T


@cache
def _euler() -> tuple[tuple[sp.Expr, ...], list[sp.Matrix], sp.Matrix]:
    """Example 9's three printed matrices and their printed product, the angles as functions
    of t."""
    t = sp.Symbol("t", real=True)
    ph, th, ps = (sp.Function(n)(t) for n in ("phi", "theta", "psi"))
    c, s = sp.cos, sp.sin
    printed = [sp.Matrix([[c(ph), s(ph), 0], [-s(ph), c(ph), 0], [0, 0, 1]]),
               sp.Matrix([[1, 0, 0], [0, c(th), s(th)], [0, -s(th), c(th)]]),
               sp.Matrix([[c(ps), s(ps), 0], [-s(ps), c(ps), 0], [0, 0, 1]])]
    product = sp.Matrix([
        [c(ps) * c(ph) - c(th) * s(ph) * s(ps), c(ps) * s(ph) + c(th) * c(ph) * s(ps),
         s(ps) * s(th)],
        [-s(ps) * c(ph) - c(th) * s(ph) * c(ps), -s(ps) * s(ph) + c(th) * c(ph) * c(ps),
         c(ps) * s(th)],
        [s(th) * s(ph), -s(th) * c(ph), c(th)]])
    return (t, ph, th, ps), printed, product


def _trig_nil(m: sp.Matrix) -> bool:
    """Every entry is 0 identically: rates become free symbols, then cos and sin of each angle
    the rational functions of u = tan(angle/2) (Weierstrass) — exact, and fast to cancel."""
    (t, *angles), _, _ = _euler()
    for e in m:
        e = e.subs({a.diff(t): sp.Dummy() for a in angles})
        for a in angles:
            u = sp.Dummy()
            e = e.subs({sp.cos(a): (1 - u**2) / (1 + u**2), sp.sin(a): 2 * u / (1 + u**2)})
        if sp.cancel(sp.together(e)) != 0:
            return False
    return True


@check("example-9.d1", "example-9.d2", "example-9.d3")
def _axis_rotations() -> Finding:
    (_, ph, th, ps), printed, _ = _euler()
    # new axes ŷ_i = R ê_i; a point's new coordinates y_i = ŷ_i · x: the matrix is Rᵀ
    ok = all(_trig_nil(m - _rotation(axis, angle).T)
             for m, (axis, angle) in zip(printed, ((2, ph), (0, th), (2, ps)), strict=True))
    return derived(
        ok, method=Method.SYMPY,
        evidence="turning the axes by ϕ about x₃, by θ about y₁, by ψ about y′₃ (Rodrigues' "
                 "rotation R of the basis vectors), a fixed point's new coordinates are "
                 "y = Rᵀx: the three printed matrices (sympy)",
    )


@check("example-9.d4")
def _euler_matrix() -> Finding:
    _, printed, product = _euler()
    composed = printed[2] * printed[1] * printed[0]
    ok = _trig_nil(composed - product) and _trig_nil(product * product.T - sp.eye(3))
    ok &= _trig_nil(sp.Matrix([product.det() - 1]))
    return derived(
        ok, method=Method.SYMPY, uses=("example-9.d1", "example-9.d2", "example-9.d3"),
        evidence="the product of the three printed rotations (ψ)(θ)(ϕ) equals the printed "
                 "matrix entry by entry; it is orthogonal with determinant 1, so its entries "
                 "ℓ_ji satisfy (2.2.51) (exercise 16) (sympy)",
    )


@check("relative-motion.i2", "relative-motion.i3", "2.2.52", "2.2.61")
def _velocity_names() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="definitions: the names v_i(S), v̄_i(S̄) of the velocity components, the "
                 "velocity in S as dx_i/dt, and the angular velocity tensor as the dual of "
                 "ω_i; their consequences are checked ((2.2.56)–(2.2.63))",
    )


@cache
def _motion() -> dict[str, sp.Matrix | sp.Symbol]:
    """A point moving in S (general functions x_i(t)) seen from the rotating S̄, every vector
    on the space axes ê_i (the body axes ē_j are ℓ's columns)."""
    t, ell = frame()[0], generic()
    x = sp.Matrix([sp.Function(f"x{i}")(t) for i in (1, 2, 3)])
    xbar = ell.T * x
    return {"t": t, "ell": ell, "dell": ell.diff(t), "x": x, "xbar": xbar,
            "v": x.diff(t),  # velocity relative to S, as a vector
            "V": ell * xbar.diff(t)}  # velocity relative to S̄: Σ (dx̄_j/dt) ē_j


_SWAP = ("(2.2.56)–(2.2.59) and v_m(S̄) = 0 for a point fixed in the body "
         "(relative-motion.i6) fix what the symbols mean: the letter's bar names the axes the "
         "components are taken on, the argument the frame the velocity is relative to — "
         "v_i(S̄) = ℓ_ij dx̄_j/dt are the velocity relative to S̄ on the space axes. With a "
         "rotating ℓ(t) and a general moving point (sympy): ")


@check("2.2.53")
def _body_velocity() -> Finding:
    k = _motion()
    printed_vec = k["xbar"].diff(k["t"])  # Σ (dx̄_i/dt) ê_i on the space axes

    def printed() -> sp.Expr:
        return _sample(printed_vec - k["V"])

    def corrected() -> sp.Expr:
        return _sample(k["ell"] * k["xbar"].diff(k["t"]) - k["V"])

    return Finding(
        verdict=Verdict.NOTATION, method=Method.SYMPY,
        evidence="the components dx̄_i/dt are taken on the body axes, so V = (dx̄_i/dt) ē_i. "
                 "The file prints the body basis like the space basis (also where the two "
                 "are introduced: 'S̄ … the basis vectors ê_i, while … S has the basis vectors "
                 "ê_i'): read literally, (dx̄_i/dt) ê_i is another vector (residual ≠ 0 for a "
                 "rotating frame, sympy). The bar on ê is lost; the mathematics after it is "
                 "unaffected",
        corrected=r"\vec{V} = \bar{v}_i(\bar{S}) \hat{\bar{e}}_i = \frac{d\bar{x}_i}{dt} "
                  r"\hat{\bar{e}}_i",
        printed_residual=printed, corrected_residual=corrected,
    )


def _sample(vec: sp.Matrix) -> sp.Expr:
    """Σ of the squared entries for the point path x = (1 + t, t², 2 − t), exactly at t = 1
    (a rational number: 0 exactly when the two vectors agree there)."""
    k = _motion()
    t = k["t"]
    path = {sp.Function(f"x{i}")(t): p for i, p in zip((1, 2, 3), (1 + t, t**2, 2 - t),
                                                         strict=True)}
    at = vec.subs(path).doit().xreplace(instant(sp.Integer(1))).subs(t, 1)
    return sp.nsimplify(sum(e**2 for e in at))


@check("2.2.54")
def _velocity_in_body_components() -> Finding:
    k = _motion()
    v_of_sbar = k["ell"] * k["xbar"].diff(k["t"])  # v_i(S̄) of (2.2.56)

    def printed() -> sp.Expr:
        return _sample(v_of_sbar - k["v"])

    def corrected() -> sp.Expr:
        return _sample(v_of_sbar - k["V"])

    return Finding(
        verdict=Verdict.NOTATION, method=Method.SYMPY, uses=("2.2.56", "2.2.59"),
        evidence=_SWAP + "v_i(S̄) ê_i is V, not v (v − v_i(S̄) ê_i = −ℓ̇ x̄ ≠ 0). The printed "
                 "(2.2.54) and (2.2.55) swap v and V — the sentence before them ('represent "
                 "V in the S frame and v in the S̄ frame') matches the corrected pair; nothing "
                 "after uses them",
        corrected=r"\vec{V} = v_1(\bar{S}) \hat{e}_1 + v_2(\bar{S}) \hat{e}_2 + v_3(\bar{S}) "
                  r"\hat{e}_3",
        printed_residual=printed, corrected_residual=corrected,
    )


@check("2.2.55")
def _space_velocity_in_body_axes() -> Finding:
    k = _motion()
    vbar_of_s = k["ell"].T * k["v"]  # v̄_i(S) of (2.2.56)

    def printed() -> sp.Expr:
        return _sample(vbar_of_s - k["V"])  # Σ v̄_i(S) ê_i

    def corrected() -> sp.Expr:
        return _sample(k["ell"] * vbar_of_s - k["v"])  # Σ v̄_i(S) ē_i

    return Finding(
        verdict=Verdict.NOTATION, method=Method.SYMPY, uses=("2.2.56",),
        evidence=_SWAP + "v̄_i(S) = ℓ_ji ẋ_j are v's components on the body axes, so "
                 "v̄_i(S) ē_i = v; the printed v̄_i(S) ê_i is neither v nor V (residual ≠ 0). "
                 "Two slips: V for v (as in (2.2.54)) and the lost bar on ē",
        corrected=r"\vec{v} = \bar{v}_1(S) \hat{\bar{e}}_1 + \bar{v}_2(S) \hat{\bar{e}}_2 + "
                  r"\bar{v}_3(S) \hat{\bar{e}}_3",
        printed_residual=printed, corrected_residual=corrected,
    )


@check("2.2.56", "2.2.57", "2.2.58", "2.2.59", "2.2.60")
def _velocity_transformations() -> Finding:
    k = _motion()
    ell, dell, x, xbar, t = k["ell"], k["dell"], k["x"], k["xbar"], k["t"]
    xd, xbd = x.diff(t), xbar.diff(t)
    ebar = [ell[:, j] for j in R3]
    vbar_s = sp.Matrix([(ebar[i].T * xd)[0] for i in R3])  # v's components on ē_i
    v_sbar = sum((xbd[j] * ebar[j] for j in R3), sp.zeros(3, 1))  # V on ê_i
    ok = nil(vbar_s - sp.Matrix([sum(ell[j, i] * xd[j] for j in R3) for i in R3]))  # 2.2.56
    ok &= nil(v_sbar - sp.Matrix([sum(ell[i, j] * xbd[j] for j in R3) for i in R3]))
    ok &= nil(xbd - (ell.T * xd + dell.T * x))  # (2.2.57)
    xb = sp.Matrix([sp.Function(f"xb{i}")(t) for i in (1, 2, 3)])  # a general x̄(t)
    ok &= nil((ell * xb).diff(t) - (ell * xb.diff(t) + dell * xb))  # (2.2.58)
    ok &= nil(v_sbar - (xd + ell * dell.T * x))  # (2.2.59): ℓ_mi ℓ̇_ji x_j
    ok &= nil(vbar_s - (xbd + ell.T * dell * xbar))  # (2.2.60): ℓ_im ℓ̇_ij x̄_j
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.50", "2.2.51"),
        evidence="for ℓ(t) rotating and a point on a general path x(t) (sympy, exact): the "
                 "projections of v on the body axes are ℓ_ji ẋ_j and V on the space axes is "
                 "ℓ_ij dx̄_j/dt (2.2.56); differentiating (2.2.50) gives (2.2.57), (2.2.58); "
                 "multiplied by ℓ_mi, ℓ_im with (2.2.51) they are (2.2.59), (2.2.60)",
    )


@check("relative-motion.d13", "2.2.65", "2.2.66")
def _duality() -> Finding:
    w = sp.Matrix(sp.symbols("w1:4"))
    a, b, c = sp.symbols("a b c")
    skew = sp.Matrix([[0, a, b], [-a, 0, c], [-b, -c, 0]])
    ok = all(zero(e) for e in vee(dual(w)) - w) and all(zero(e) for e in
                                                            dual(vee(skew)) - skew)
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.61",),
        evidence="ω_mn = e_imn ω_i and ω_i = ½ e_ijk ω_jk are inverse maps between vectors and "
                 "skew tensors: both compositions are the identity for general components "
                 "(sympy, the e–δ identity e_ijk e_mjk = 2δ_im); the same pair defines H_jk "
                 "and M_jk",
    )


@check("relative-motion.i4", "relative-motion.i5", "relative-motion.i6", "relative-motion.i7",
       "relative-motion.d14", "2.2.62", "2.2.63")
def _angular_velocity() -> Finding:
    t, ell = frame()[0], generic()
    dell = ell.diff(t)
    omega = ell * dell.T  # ω_mj = ℓ_mi ℓ̇_ji (relative-motion.d14)
    ok = nil(omega + omega.T)  # skew, by differentiating (2.2.51)
    w = vee(omega)
    ok &= nil(dual(w) - omega)
    xbar = sp.Matrix(sp.symbols("c1:4"))  # a point fixed in the body
    x = ell * xbar
    xd = x.diff(t)
    eps = levi_civita
    ok &= nil(xd - sp.Matrix([sum(eps(i, j, k) * w[j] * x[k] for j in R3 for k in R3)
                               for i in R3]))  # i4
    ok &= nil(xd + omega * x)  # i5 and d14
    ok &= nil(ell * xbar.diff(t))  # i6: v(S̄) = ℓ dx̄/dt = 0
    ok &= nil(xd + ell * dell.T * x)  # i7
    bar = ell.T * omega * ell  # first line of (2.2.62)
    lines = [sp.Matrix(3, 3, lambda m, n: sum(ell[i, m] * ell[j, n] * ell[i, s] * dell[j, s]
                                               for i in R3 for j in R3 for s in R3)),
             sp.Matrix(3, 3, lambda m, n: sum(int(m == s) * ell[j, n] * dell[j, s]
                                               for j in R3 for s in R3)),
             sp.Matrix(3, 3, lambda m, n: sum(ell[j, n] * dell[j, m] for j in R3))]
    ok &= all(nil(bar - line) for line in lines)
    k = _motion()  # (2.2.63) for a point on a general path
    ok &= nil(k["V"] - (k["v"] + omega * k["x"]))
    ok &= nil(ell.T * k["v"] - (k["xbar"].diff(t) + bar.T * k["xbar"]))
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.51", "2.2.59", "2.2.60", "2.2.61"),
        evidence="with ω_mj = ℓ_mi ℓ̇_ji for the rotating ℓ(t) (sympy, exact): ω is skew; for "
                 "a point fixed in the body ẋ_i = e_ijk ω_j x_k = −ω_mk x_k with ω_i = "
                 "½ e_ijk ω_jk, v_m(S̄) = 0 and (2.2.59) reads 0 = v_m(S) + ℓ_mi ℓ̇_ji x_j; "
                 "the four lines of (2.2.62) are equal; (2.2.63) holds for a point on a "
                 "general path",
    )


def _four(inertia: sp.Matrix) -> list[list[list[list[sp.Expr]]]]:
    """I_mnst = ½ e_jmn e_ist I_ij (2.2.64)."""
    e = levi_civita
    return [[[[sum(e(j, m, n) * e(i, s, t) * inertia[i, j] for i in R3 for j in R3) / 2
               for t in R3] for s in R3] for n in R3] for m in R3]


def _contract(four: list, tensor: sp.Matrix) -> sp.Matrix:
    """I_ijst ω_st."""
    return sp.Matrix(3, 3, lambda i, j: sum(four[i][j][s][t] * tensor[s, t] for s in R3
                                            for t in R3))


@cache
def _inertia() -> sp.Matrix:
    a, b, c, d, e, f = sp.symbols("I11 I22 I33 I12 I13 I23")
    return sp.Matrix([[a, d, e], [d, b, f], [e, f, c]])


@check("2.2.64", "2.2.67", "euler-equations.d5", "2.2.68")
def _tensor_forms() -> Finding:
    inertia = _inertia()
    four = _four(inertia)
    back = sp.Matrix(3, 3, lambda i, j: sum(
        four[p][q][r][s] * levi_civita(i, p, q) * levi_civita(j, r, s)
        for p in R3 for q in R3 for r in R3 for s in R3) / 2)
    ok = all(zero(x) for x in back - inertia)
    w = sp.Matrix(sp.symbols("w1:4"))
    H = inertia.T * w  # (2.2.42): H_i = ω_j I_ji
    ok &= all(zero(x) for x in dual(H) - _contract(four, dual(w)))  # d5
    t = sp.Symbol("t")
    Hf = sp.Matrix([sp.Function(f"H{i}")(t) for i in (1, 2, 3)])
    Mf = sp.Matrix([sp.Function(f"M{i}")(t) for i in (1, 2, 3)])
    ok &= all(zero(x) for x in dual(Hf).diff(t) - dual(Mf) - dual(Hf.diff(t) - Mf))
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.42", "2.2.49", "2.2.61", "2.2.65", "2.2.66"),
        evidence="for a general symmetric I (sympy): the second form of (2.2.64) recovers I_ij "
                 "from the first; e_imn ω_j I_ji = I_mnst ω_st with ω_st = e_ist ω_i, so "
                 "H_mn = I_mnst ω_st; d/dt(e_rij H_r) − e_rij M_r = e_rij (dH_r/dt − M_r), so "
                 "(2.2.49) ⇔ (2.2.67) ⇔ (2.2.68)",
    )


def _moved(L: sp.Matrix, four: list) -> list:
    """ℓ_ip ℓ_jq ℓ_sr ℓ_tk F_pqrk, one index at a time."""
    out = four
    for axis in range(4):
        def mode(idx: tuple[int, ...], src: list = out, ax: int = axis) -> sp.Expr:
            return sum(L[idx[ax], p] * _get(src, (*idx[:ax], p, *idx[ax + 1:])) for p in R3)
        out = [[[[mode((i, j, s, t)) for t in R3] for s in R3] for j in R3] for i in R3]
    return out


def _get(four: list, idx: tuple[int, ...]) -> sp.Expr:
    return four[idx[0]][idx[1]][idx[2]][idx[3]]


@check("euler-equations.d7", "euler-equations.d8", "2.2.69")
def _body_axes() -> Finding:
    t, ell = frame()[0], generic()
    dell = ell.diff(t)
    ibar = _inertia()  # constant in the body axes
    four_bar = _four(ibar)
    wbar = dell.T * ell  # (2.2.62): ω̄_mn = ℓ_jn ℓ̇_jm
    inner = _contract(four_bar, wbar)  # Ī_αβrk ω̄_rk
    rate = (ell * inner * ell.T).diff(t)  # d/dt(ℓ_iα ℓ_jβ Ī_αβrk ω̄_rk)
    dwbar = wbar.diff(t)
    delta = sp.KroneckerDelta
    ok = True
    for at in POINTS:
        L, dL, W, dW, inner_at, rate_at = (m.xreplace(instant(at)) for m in (
            ell, dell, wbar, dwbar, inner, rate))
        w = L * dL.T  # ω_mj = ℓ_mi ℓ̇_ji
        four = _four(L * ibar * L.T)  # (2.2.64) in the space axes
        moved = _moved(L, four_bar)  # d7: I_ijst = ℓ_ip ℓ_jq ℓ_sr ℓ_tk Ī_pqrk
        ok &= all(sp.expand(_get(moved, ix) - _get(four, ix)) == 0
                  for ix in ((i, j, s, k) for i in R3 for j in R3 for s in R3 for k in R3))
        ok &= all(sp.expand(e) == 0 for e in L.T * w * L - W)  # d7: ω̄ = ℓᵀωℓ
        # d8: ℓ_ip ℓ_jq applied to (2.2.68), I_ijst ω_st = ℓ_iα ℓ_jβ Ī_αβrk ω̄_rk
        ok &= all(sp.expand(e) == 0 for e in L * inner_at * L.T - _contract(four, w))
        lhs_d8 = L.T * rate_at * L
        lhs_69 = sp.Matrix(3, 3, lambda p, q, W=W, dW=dW: sum(
            four_bar[p][q][r][k] * dW[r, k] for r in R3 for k in R3) + sum(
            (delta(al, u) * delta(p, v) * delta(be, q) + delta(p, al) * delta(be, u)
             * delta(q, v)) * four_bar[al][be][r][k] * W[r, k] * W[u, v]
            for al in R3 for be in R3 for r in R3 for k in R3 for u in R3 for v in R3))
        ok &= all(sp.expand(e) == 0 for e in lhs_69 - lhs_d8)
    return derived(
        ok, method=Method.SYMPY, uses=("2.2.62", "2.2.64", "2.2.68"),
        evidence="with a general constant symmetric Ī in the body axes and the rotating ℓ(t) "
                 "(exact, at t = 1/3, 1, 2): I_ijst built by (2.2.64) from I = ℓĪℓᵀ equals "
                 "ℓ_ip ℓ_jq ℓ_sr ℓ_tk Ī_pqrk (e_ijk is invariant under proper rotations), "
                 "ω̄ = ℓᵀωℓ; I_ijst ω_st = ℓ_iα ℓ_jβ Ī_αβrk ω̄_rk, so (2.2.68) becomes the "
                 "printed ℓℓ d/dt(…) = M̄; expanding it with ℓ_ip ℓ̇_iα = ω̄_αp gives (2.2.69) "
                 "term by term (sympy)",
    )


@check("euler-equations.i1")
def _principal_axes() -> Finding:
    inertia = sp.Matrix([[2, 1, 0], [1, 2, 0], [0, 0, 3]])
    basis = [v / v.norm() for _, _, vs in inertia.eigenvects() for v in vs]
    ell = sp.Matrix.hstack(*basis)
    bar = sp.simplify(ell.T * inertia * ell)
    ok = all(bar[i, j] == 0 for i in R3 for j in R3 if i != j)
    return derived(
        ok, method=Method.SYMPY,
        evidence="a symmetric I has an orthonormal eigenbasis (the spectral theorem); on it "
                 "Ī = ℓᵀIℓ has I_ij = 0 for i ≠ j (sympy, on I = [[2,1,0],[1,2,0],[0,0,3]]); "
                 "Euler's equations on such axes are checked as (2.2.72)",
    )


@check("ex23.d1", "ex23.d2", "ex23.d3")
def _euler_rates() -> Finding:
    (t, ph, th, ps), _, product = _euler()
    ell = product.T  # x̄ = ℓᵀx (2.2.50)
    wbar = ell.diff(t).T * ell  # (2.2.62)
    body = vee(wbar)
    independent = ell.T * ell.diff(t)  # ℓᵀℓ̇ = [ω]× on the body axes
    c, s = sp.cos, sp.sin
    printed = sp.Matrix([th.diff(t) * c(ps) + ph.diff(t) * s(th) * s(ps),
                         -th.diff(t) * s(ps) + ph.diff(t) * s(th) * c(ps),
                         ps.diff(t) + ph.diff(t) * c(th)])
    ok = _trig_nil(body - printed) and _trig_nil(
        sp.Matrix([independent[2, 1], independent[0, 2], independent[1, 0]]) - printed)
    return derived(
        ok, method=Method.SYMPY, uses=("example-9.d4", "2.2.62", "relative-motion.d13"),
        evidence="from Example 9's matrix with ϕ, θ, ψ functions of t: the body components "
                 "ω̄_i = ½ e_ijk ω̄_jk of ω̄_mn = ℓ_jn ℓ̇_jm (2.2.62), and independently the "
                 "entries of ℓᵀℓ̇ = [ω]×, are the three printed ω_x, ω_y, ω_z (sympy)",
    )
