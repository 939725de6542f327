"""A particle in generalized coordinates: kinematics (2.2.3)–(2.2.5), Lagrange's form
(2.2.21)–(2.2.23), Example 5, Hamilton's equations (exercises 20, 22), geodesics (exercise 18)
and the action integral's line element ds² = 2m(h − V) g_jk dxʲ dxᵏ.

Batched: q, v, a of shape (n, N). ``cs`` is a :class:`CoordinateSystem`.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from dyncheck.reference.coordinates import CoordinateSystem, cylindrical, spherical
from dyncheck.reference.derivations import lambdified
from dyncheck.reference.lagrange import LagrangianDynamics, SymbolicSystem
from dyncheck.reference.printed import PrintedDynamics


def speed_squared(cs: CoordinateSystem, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v² = g_ij vⁱ vʲ."""
    return np.einsum("nij,ni,nj->n", cs.numeric.metric(q), v, v)


def transform_velocity(
    src: CoordinateSystem,
    dst: CoordinateSystem,
    q_src: np.ndarray,
    q_dst: np.ndarray,
    v_src: np.ndarray,
) -> np.ndarray:
    """(2.2.4): v̄ʳ = (∂x̄ʳ/∂xʲ) vʲ, with ∂x̄/∂x = (∂x̄/∂X)(∂X/∂x) through Cartesian X;
    ``q_dst`` is the same point in the barred coordinates."""
    cart = np.einsum("nkj,nj->nk", src.numeric.jacobian(q_src), v_src)
    return np.linalg.solve(dst.numeric.jacobian(q_dst), cart[..., None])[..., 0]


def acceleration(cs: CoordinateSystem, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """(2.2.5): fⁱ = ẍⁱ + {i; m n} ẋᵐ ẋⁿ, the intrinsic derivative of the velocity."""
    return a + np.einsum("nimk,nm,nk->ni", cs.numeric.christoffel(q), v, v)


def physical_components(cs: CoordinateSystem, q: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """Physical components √g_(ii) Aⁱ of a contravariant vector (orthogonal systems;
    exercises 6, 7)."""
    g = cs.numeric.metric(q)
    off = g - np.einsum("nii->ni", g)[..., None] * np.eye(cs.dim)
    if np.abs(off).max() > 1e-12 * np.abs(g).max():
        raise ValueError(f"{cs.name}: physical components need an orthogonal system")
    return np.sqrt(np.einsum("nii->ni", g)) * vec


def frame_rotation_squared(cs: CoordinateSystem) -> sp.Expr:
    """|ω|² of the orthonormal triad along the coordinate lines (a body carried by the
    coordinates turns with it): from the named systems' triads — cylindrical ω = θ̇ e_z,
    spherical ω = φ̇ e_z + θ̇ e_φ (so |ω|² = θ̇² + φ̇²); Cartesian ω = 0."""
    d = [sp.Symbol(f"{s.name}dot") for s in cs.q]
    return {
        "cartesian": sp.Integer(0),
        "cylindrical": d[1] ** 2,
        "spherical": d[1] ** 2 + d[2] ** 2,
    }[cs.name]


@cache
def particle_symbolic(cs: CoordinateSystem, central: bool = False) -> SymbolicSystem:
    """T = ½ M g_ij ẋⁱ ẋʲ (2.2.21) + ½ I |ω|² (a body turning with the coordinate triad,
    I = 0 for the book's particle), V = M g z (gravity along −z, (2.2.20)); with ``central``,
    an inverse-square attraction toward the origin as an external field V_f = −μM/|x|
    (exercise 25)."""
    M, g, mu, inertia = sp.symbols("M g mu I", positive=True)
    qd = tuple(sp.Symbol(f"{s.name}dot") for s in cs.q)
    v = sp.Matrix(qd)
    T = (M * (v.T * cs.metric * v)[0, 0] + inertia * frame_rotation_squared(cs)) / 2
    r = sp.sqrt(sp.trigsimp(sp.expand(sum(e**2 for e in cs.x))))
    field = -mu * M / r if central else 0
    return SymbolicSystem(cs.q, qd, (M, g, mu, inertia), sp.expand(T), M * g * cs.x[2], field)


def particle(
    cs: CoordinateSystem,
    M: float,
    g: float = 0.0,
    *,
    mu: float = 0.0,
    inertia: tuple[float] = (0.0,),
) -> LagrangianDynamics:
    """The general method (2.2.22)–(2.2.26) for a particle of mass M in ``cs``, under gravity
    g along −z and (if μ > 0) the central attraction of exercise 25 as an applied field."""
    return particle_symbolic(cs, mu > 0).numeric({"M": M, "g": g, "mu": mu, "I": inertia[0]})


def lagrange_form(cs: CoordinateSystem, M: float, g: float) -> PrintedDynamics:
    """(2.2.23) written with the metric and Christoffel symbols: M g_ri fⁱ = Q_r with fⁱ of
    (2.2.5) and Q_r = −∂V/∂xʳ = −M g ∂z/∂xʳ; T = ½ M g_ij ẋⁱ ẋʲ, V = M g z. Uses the
    system's closed-form symbols where it has them."""
    num = cs.numeric
    christoffel = _closed_christoffel(cs)
    dz = num.jacobian

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        f = a + np.einsum("nimk,nm,nk->ni", christoffel(q), v, v)
        return M * np.einsum("nri,ni->nr", num.metric(q), f) + M * g * dz(q)[:, 2, :]

    return PrintedDynamics(
        residual=residual,
        row_factors=np.ones(cs.dim),
        T=lambda q, v: 0.5 * M * speed_squared(cs, q, v),
        V=lambda q: M * g * num.position(q)[:, 2],
    )


def _closed_christoffel(cs: CoordinateSystem) -> Callable[[np.ndarray], np.ndarray]:
    if cs.closed_christoffel is None:
        return cs.numeric.christoffel
    n = cs.dim
    exprs = [e for a in cs.closed_form_christoffel() for b in a for e in b]
    fns = [lambdified(cs.q, e, "numpy", cse=False) for e in exprs]

    def evaluate(q: np.ndarray) -> np.ndarray:
        cols = [np.broadcast_to(np.asarray(f(*q.T), float), q.shape[:1]) for f in fns]
        return np.stack(cols, -1).reshape(q.shape[0], n, n, n)

    return evaluate


def example5_printed(M: float, g: float = 0.0, mu: float = 0.0) -> PrintedDynamics:
    """Example 5 exactly as printed, spherical (ρ, θ, φ), with d/dt expanded:

        Q₁ = M[ρ̈ − ρθ̇² − ρ sin²θ φ̇²]
        Q₂ = M[d/dt(ρ²θ̇) − ρ² sin θ cos θ φ̇²]
        Q₃ = M[d/dt(ρ² sin²θ φ̇)]

    with Q_r = −∂V/∂xʳ for V = M g ρ cos θ (gravity along −z) and, if μ > 0, the central
    attraction Q = (−μM/ρ², 0, 0) applied as an external field (exercise 25)."""

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        rho, th = q[:, 0], q[:, 1]
        rd, thd, phd = v.T
        s, c = np.sin(th), np.cos(th)
        e1 = M * (a[:, 0] - rho * thd**2 - rho * s**2 * phd**2)
        e2 = M * (2 * rho * rd * thd + rho**2 * a[:, 1] - rho**2 * s * c * phd**2)
        e3 = M * (
            2 * rho * rd * s**2 * phd + 2 * rho**2 * s * c * thd * phd + rho**2 * s**2 * a[:, 2]
        )
        gravity = np.stack([M * g * c, -M * g * rho * s, np.zeros_like(rho)], -1)  # ∂V/∂x
        return np.stack([e1, e2, e3], -1) + gravity

    def central(q: np.ndarray) -> np.ndarray:
        out = np.zeros_like(q, dtype=float)
        out[:, 0] = -mu * M / q[:, 0] ** 2
        return out

    return PrintedDynamics(
        residual=residual,
        row_factors=np.ones(3),
        T=lambda q, v: (
            0.5
            * M
            * (
                v[:, 0] ** 2
                + q[:, 0] ** 2 * v[:, 1] ** 2
                + q[:, 0] ** 2 * np.sin(q[:, 1]) ** 2 * v[:, 2] ** 2
            )
        ),
        V=lambda q: M * g * q[:, 0] * np.cos(q[:, 1]),
        field=central if mu > 0 else None,
    )


def example5_physical(q: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Example 5's physical components (Q_ρ, Q_θ, Q_φ) = (Q₁, Q₂/ρ, Q₃/(ρ sin θ))."""
    return np.stack([Q[:, 0], Q[:, 1] / q[:, 0], Q[:, 2] / (q[:, 0] * np.sin(q[:, 1]))], -1)


# --- Hamilton's equations (exercises 20, 22) -------------------------------------------------


def momentum(cs: CoordinateSystem, M: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The Legendre map p_i = ∂T/∂ẋⁱ = M g_ij ẋʲ (a covariant vector)."""
    return M * np.einsum("nij,nj->ni", cs.numeric.metric(q), v)


@cache
def _hamiltonian_rhs(cs: CoordinateSystem) -> Callable[..., np.ndarray]:
    """(∂H/∂p, −∂H/∂x) for H = (1/2M) g^ij p_i p_j + V, V = M g z, derived exactly."""
    M, g = sp.symbols("M g", positive=True)
    p = sp.symbols(f"p0:{cs.dim}")
    pv = sp.Matrix(p)
    H = (pv.T * cs.inverse_metric * pv)[0, 0] / (2 * M) + M * g * cs.x[2]
    rhs = [sp.diff(H, pi) for pi in p] + [-sp.diff(H, qi) for qi in cs.q]
    return sp.lambdify((*cs.q, *p, M, g), rhs, "numpy")


def hamilton_rhs(
    cs: CoordinateSystem, M: float, g: float, q: np.ndarray, p: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """dx/dt = ∂H/∂p, dp/dt = −∂H/∂x (exercise 20(d)) at one state, shapes (N,)."""
    out = _hamiltonian_rhs(cs)(*q, *p, M, g)
    out = np.array([np.broadcast_to(np.asarray(o, float), ()) for o in out])
    return out[: cs.dim], out[cs.dim :]


def solve_hamilton(
    cs: CoordinateSystem,
    M: float,
    g: float,
    q0: np.ndarray,
    p0: np.ndarray,
    t: np.ndarray,
    rtol: float = 1e-12,
) -> tuple[np.ndarray, np.ndarray]:
    n = cs.dim

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        dq, dp = hamilton_rhs(cs, M, g, y[:n], y[n:])
        return np.concatenate([dq, dp])

    sol = solve_ivp(
        rhs,
        (t[0], t[-1]),
        np.concatenate([q0, p0]),
        method="DOP853",
        t_eval=t,
        rtol=rtol,
        atol=rtol,
    )
    return sol.y[:n].T, sol.y[n:].T


# --- Geodesics (exercise 18) and the action integral ----------------------------------------


def geodesic_rhs(christoffel: Callable[[np.ndarray], np.ndarray]):
    """d²xⁱ/ds² + {i; j k} dxʲ/ds dxᵏ/ds = 0 (exercise 18(c)) as a first-order system."""

    def rhs(_s: float, y: np.ndarray) -> np.ndarray:
        n = y.shape[0] // 2
        x, u = y[:n], y[n:]
        return np.concatenate([u, -np.einsum("imk,m,k->i", christoffel(x[None])[0], u, u)])

    return rhs


def curve_length(
    metric: Callable[[np.ndarray], np.ndarray], x: np.ndarray, u: np.ndarray, s: np.ndarray
) -> float:
    """∫ √(g_mn ẋᵐ ẋⁿ) ds along samples of a curve (exercise 18(a)); trapezoid on ``s``."""
    speed = np.sqrt(np.einsum("nij,ni,nj->n", metric(x), u, u))
    return float(np.trapezoid(speed, s))


def jacobi_residual(
    cs: CoordinateSystem, M: float, g: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, h: float
) -> np.ndarray:
    """On a trajectory of energy h, the part of ẍ + {Γ of G} ẋ ẋ orthogonal to ẋ, for
    G_jk = 2M(h − V) g_jk: zero when the trajectory is a (non-affinely parametrised) geodesic
    of the action's line element ds² = 2m(h − V) g_jk dxʲ dxᵏ. Shape (n, N)."""
    G = _jacobi_christoffel(cs)(q, M, g, h)
    r = a + np.einsum("nimk,nm,nk->ni", G, v, v)
    gm = cs.numeric.metric(q)
    along = np.einsum("nij,ni,nj->n", gm, r, v) / np.einsum("nij,ni,nj->n", gm, v, v)
    return r - along[:, None] * v


@cache
def _jacobi_christoffel(cs: CoordinateSystem):
    M, g, h = sp.symbols("M g h", positive=True)
    factor = 2 * M * (h - M * g * cs.x[2])
    G = cs.metric * factor
    Gi = G.inv()
    n, q = cs.dim, cs.q
    first = [
        [
            [
                (sp.diff(G[i, m], q[k]) + sp.diff(G[i, k], q[m]) - sp.diff(G[m, k], q[i])) / 2
                for k in range(n)
            ]
            for m in range(n)
        ]
        for i in range(n)
    ]
    second = [
        sum(Gi[i, j] * first[j][m][k] for j in range(n))
        for i in range(n)
        for m in range(n)
        for k in range(n)
    ]
    fns = [sp.lambdify((*q, M, g, h), e, "numpy", cse=True) for e in second]

    def evaluate(qv: np.ndarray, Mv: float, gv: float, hv: float) -> np.ndarray:
        cols = [np.broadcast_to(np.asarray(f(*qv.T, Mv, gv, hv), float), qv.shape[:1]) for f in fns]
        return np.stack(cols, -1).reshape(qv.shape[0], n, n, n)

    return evaluate


SYSTEMS = {"spherical": spherical, "cylindrical": cylindrical}
