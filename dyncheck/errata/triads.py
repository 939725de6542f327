"""Exercise 30 and the moving triads: Givens rotations, a fixed axis, a triad moving with a
body and one that is not the body's — on the exact Cayley frame (:mod:`.cayley`)."""

from __future__ import annotations

from functools import cache

import sympy as sp

from dyncheck.errata.cayley import frame, vee
from dyncheck.errata.registry import (
    DIGITS,
    POINTS,
    Finding,
    Method,
    Verdict,
    check,
    derived,
    negligible,
    zero,
)


@check("ex30.i1", "ex30.i2", "ex30.i7", "ex30.i11", "ex30.i15")
def _exercise_30_givens() -> Finding:
    return Finding(
        verdict=Verdict.NOT_CHECKABLE, method=Method.NONE,
        evidence="the exercise's definitions (the position on the fixed axis, ω = dθ/dt, "
                 "ê₃ = ê₁ × ê₂, ω = αê₃ − βê₁, a point's components x, y, z); their "
                 "consequences are checked",
    )


@check("ex30.i3", "ex30.i4", "ex30.i5")
def _fixed_axis() -> Finding:
    t = sp.Symbol("t")
    theta = sp.Function("theta")(t)
    h, r0, th = sp.symbols("h r_0 th")
    e = sp.Matrix([0, 0, 1])
    e_r = sp.Matrix([sp.cos(th), sp.sin(th), 0])  # ⊥ ê, turned by θ about it
    ok = all(zero(x) for x in e_r.diff(th) - e.cross(e_r))  # (a)
    r = (h * e + r0 * e_r).subs(th, theta)
    w = theta.diff(t) * e  # i3: d(θê)/dt with ê constant
    ok &= all(zero(x) for x in (theta * e).diff(t) - w)
    ok &= all(zero(x) for x in r.diff(t) - r0 * e_r.diff(th).subs(th, theta) * theta.diff(t))
    ok &= all(zero(x) for x in r.diff(t) - w.cross(r))  # (b): ω × hê = 0
    return derived(
        ok, method=Method.SYMPY,
        evidence="ê_R = cosθ ê_a + sinθ ê_b ⊥ ê: dê_R/dθ = ê × ê_R, d(θê)/dt = θ̇ê, and each "
                 "link of the printed chain to ω × r (ω × hê = 0) (sympy)",
    )


@cache
def _triad() -> dict[str, sp.Expr | sp.Matrix]:
    """Case 2 of exercise 30 built on the rotating ℓ(t): ê₁ fixed in the body, ê₂ along
    dê₁/dt, ê₃ = ê₁ × ê₂; ω of the exercise and the body's angular velocity ω_b (ℓ̇ℓᵀ)."""
    t, ell = frame()
    e1 = ell[:, 0]
    d1 = e1.diff(t)
    alpha = sp.sqrt((d1.T * d1)[0])
    e2 = d1 / alpha
    e3 = e1.cross(e2)
    beta = (e2.T * e3.diff(t))[0]
    body = vee(ell * ell.diff(t).T)  # ω_b: ẋ = ω_b × x for body points (relative-motion.i4)
    r = ell * sp.Matrix([sp.Rational(1, 2), 2, -1])  # a point fixed in the body
    return {"t": t, "e1": e1, "e2": e2, "e3": e3, "alpha": alpha, "beta": beta,
            "w": alpha * e3 - beta * e1, "body": body, "r": r}


def _small(vec: sp.Matrix | sp.Expr, at: sp.Expr) -> sp.Expr:
    """|vec|² at t = ``at`` to DIGITS digits, 0 when negligible (the entries are algebraic)."""
    k = _triad()
    entries = vec if isinstance(vec, sp.MatrixBase) else sp.Matrix([vec])
    value = sp.N(sum(e**2 for e in entries.subs(k["t"], at)), DIGITS)
    return sp.Integer(0) if negligible(value) else value


@check("ex30.i6", "ex30.i8", "ex30.i9", "ex30.i10", "ex30.i12", "ex30.i13", "ex30.i14")
def _moving_triad() -> Finding:
    k = _triad()
    t, e1, e2, e3, w = k["t"], k["e1"], k["e2"], k["e3"], k["w"]
    relations = [e1.diff(t) - k["alpha"] * e2, e3.diff(t) - k["beta"] * e2,
                 e2 - e3.cross(e1), e2.diff(t) - (k["alpha"] * e3 - k["beta"] * e1).cross(e2),
                 e1.diff(t) - w.cross(e1), e2.diff(t) - w.cross(e2), e3.diff(t) - w.cross(e3)]
    ok = all(_small(rel, at) == 0 for rel in relations for at in POINTS)
    alphas = [sp.N(k["alpha"].subs(t, at), 4) for at in POINTS]
    betas = [sp.N(k["beta"].subs(t, at), 4) for at in POINTS]
    return derived(
        ok, method=Method.NUMERIC,
        evidence="ê₁ a body axis of the rotating ℓ(t), ê₂ = (dê₁/dt)/α, ê₃ = ê₁ × ê₂: each "
                 "relation's residual is below 1e-40 at t = 1/3, 1, 2 (50 digits). The "
                 "exercise's words 'for some constant α' and 'constant β' are too strong: "
                 f"here α = {', '.join(map(str, alphas))} and β = "
                 f"{', '.join(map(str, betas))} at those instants; nothing in (a)–(d) uses "
                 "constancy",
    )


@check("ex30.i16")
def _triad_is_not_the_body() -> Finding:
    k = _triad()
    t, r, w, e1 = k["t"], k["r"], k["w"], k["e1"]
    spin = (k["body"].T * e1)[0] + k["beta"]  # λ: the body's spin about ê₁ less −β

    def printed() -> sp.Expr:
        return _small(r.diff(t) - w.cross(r), sp.Integer(1))

    def corrected() -> sp.Expr:
        return _small(r.diff(t) - (w + spin * e1).cross(r), sp.Integer(1))

    return Finding(
        verdict=Verdict.ERRATUM, method=Method.NUMERIC, uses=("ex30.i12", "ex30.i15"),
        evidence="ω = αê₃ − βê₁ is the angular velocity of the triad (ê₁, ê₂, ê₃), and ê₂, "
                 "defined by the motion of ê₁, is not fixed in the body unless the body "
                 "turns about an axis fixed in it: dr/dt = ω × r holds for x, y, z constant "
                 "on the triad, not for 'an arbitrary point within the rigid body'. For a "
                 "point fixed in the body of the rotating ℓ(t), |dr/dt − ω × r|² ≠ 0 at t = 1 "
                 "(50 digits); the motion of ê₁ cannot see the spin about ê₁, and the body's "
                 "angular velocity is ω + λê₁ with λ = ω_b·ê₁ + β — with it the residual is "
                 "0 (below 1e-40)",
        corrected=r"\frac{d\vec{r}}{dt} = (\vec{\omega} + \lambda\hat{e}_1) \times \vec{r}, "
                  r"\quad \lambda = \vec{\omega}_b\cdot\hat{e}_1 + \beta "
                  r"\text{ (}\lambda = 0\text{ when } \hat{e}_2, \hat{e}_3 \text{ are fixed in "
                  r"the body)}",
        effect="a body point's velocity from the printed ω misses the spin about ê₁: for the "
               "point (½, 2, −1) of the rotating ℓ(t) at t = 1, |dr/dt − ω × r| = "
               f"{sp.N(sp.sqrt(printed()), 3)} against |dr/dt| = "
               f"{sp.N(sp.sqrt(_small(r.diff(t), sp.Integer(1))), 3)}",
        printed_residual=printed, corrected_residual=corrected,
    )
