"""Rigid bodies, the second half of §2.2: inertia tensor, angular momentum, direction cosines
and Euler angles, the angular-velocity tensor, Euler's equations and torque-free motion.

Index conventions are the book's: ℓ_ij are the direction cosines of (2.2.50),
x̄_i = ℓ_ji x_j (space components x, body components x̄); e_ijk is the permutation symbol.
Everything is numpy on batches where it matters; exact derivatives of the direction cosines
come from sympy.

Why one module of ~500 lines: the second half of §2.2 is one chain of definitions — inertia
tensor, direction cosines, Euler angles, angular velocity, Euler's equations, torque-free
motion — each used by the next; the clean-room reference keeps the chapter's order.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp
from scipy import integrate
from scipy.special import ellipj, ellipkinc

E = np.zeros((3, 3, 3))
E[0, 1, 2] = E[1, 2, 0] = E[2, 0, 1] = 1.0
E[0, 2, 1] = E[2, 1, 0] = E[1, 0, 2] = -1.0
"""The permutation symbol e_ijk."""


# --- systems of particles: (2.2.37)–(2.2.49) ----------------------------------------------


def inertia_tensor(masses: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """I_ij = Σ m (x_k x_k δ_ij − x_i x_j) (2.2.39), positions (n, 3) from the origin."""
    m, x = np.asarray(masses, float), np.asarray(positions, float)
    r2 = np.einsum("a,ak,ak->", m, x, x)
    return r2 * np.eye(3) - np.einsum("a,ai,aj->ij", m, x, x)


def centre_of_mass(masses: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """x̄_c = Σ m x / Σ m (exercise 13, discrete)."""
    m = np.asarray(masses, float)
    return m @ np.asarray(positions, float) / m.sum()


def continuous_body(
    density, bounds: tuple[tuple[float, float], ...]
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia tensor about the origin of a continuous body (the
    limit of (2.2.39) with m → ρ dτ, exercise 13) occupying the box ``bounds`` with density
    ``density(x, y, z)`` (zero outside the body), by scipy's adaptive cubature."""
    (x0, x1), (y0, y1), (z0, z1) = bounds

    def cube(f) -> float:
        return integrate.tplquad(
            lambda z, y, x: f(x, y, z) * density(x, y, z),
            x0,
            x1,
            y0,
            y1,
            z0,
            z1,
            epsabs=1e-13,
            epsrel=1e-12,
        )[0]

    mass = cube(lambda x, y, z: 1.0)
    first = np.array([cube(lambda *p, i=i: p[i]) for i in range(3)])
    second = np.array(
        [[cube(lambda *p, i=i, j=j: p[i] * p[j]) for j in range(3)] for i in range(3)]
    )
    inertia = np.trace(second) * np.eye(3) - second
    return mass, first / mass, inertia


def kinetic_energy(I: np.ndarray, w: np.ndarray) -> np.ndarray:
    """T = ½ I_ij ω_i ω_j (2.2.40), batched over ω (…, 3)."""
    return 0.5 * np.einsum("ij,...i,...j->...", I, w, w)


def kinetic_energy_of_particles(masses: np.ndarray, positions: np.ndarray, w: np.ndarray) -> float:
    """T = ½ Σ m e_ijk ω_j x_k e_imn ω_m x_n (2.2.38): the particles' own velocities ω × x."""
    v = np.einsum("ijk,j,ak->ai", E, w, positions)
    return 0.5 * float(np.einsum("a,ai,ai->", masses, v, v))


def angular_momentum(I: np.ndarray, w: np.ndarray) -> np.ndarray:
    """H_i = ω_j I_ji (2.2.42), batched over ω (…, 3)."""
    return np.einsum("...j,ji->...i", w, I)


def angular_momentum_of_particles(
    masses: np.ndarray, positions: np.ndarray, velocities: np.ndarray
) -> np.ndarray:
    """H_i = Σ m e_ijk x_j v_k (2.2.41)."""
    return np.einsum("a,ijk,aj,ak->i", masses, E, positions, velocities)


def principal_axes(I: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (ascending) and axes (columns): I = A diag(moments) Aᵀ."""
    return np.linalg.eigh(I)


# --- direction cosines and Euler angles: (2.2.50)–(2.2.51), Example 9, exercises 16, 26 ------


def _r3(a: float) -> np.ndarray:
    """The book's rotation of axes about the third axis by a (Example 9's first matrix)."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def _r1(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def _r2(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def euler_matrix_printed(phi: float, theta: float, psi: float) -> np.ndarray:
    """Example 9's combined matrix exactly as printed: x̄ = A x, so ℓ = Aᵀ (2.2.50)."""
    cf, sf, ct, st, cp, sp_ = (np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta),
                               np.cos(psi), np.sin(psi))  # fmt: skip
    return np.array(
        [
            [cp * cf - ct * sf * sp_, cp * sf + ct * cf * sp_, sp_ * st],
            [-sp_ * cf - ct * sf * cp, -sp_ * sf + ct * cf * cp, cp * st],
            [st * sf, -st * cf, ct],
        ]
    )


def euler_matrix_product(phi: float, theta: float, psi: float) -> np.ndarray:
    """Example 9 as the product of its three rotations: about x₃ by φ, about y₁ by θ, about
    y'₃ by ψ — A = R₃(ψ) R₁(θ) R₃(φ)."""
    return _r3(psi) @ _r1(theta) @ _r3(phi)


def pitch_roll_yaw_matrix(pitch: float, roll: float, yaw: float) -> np.ndarray:
    """Exercise 26: pitch about the lateral (y) axis of the fixed axes, then roll about the
    pitched longitudinal (x) axis, then yaw about the rolled normal (z) axis; body
    components x = A X of the fixed ones, A = R_z(yaw) R_x(roll) R_y(pitch) (each a rotation
    of axes, as in Example 9)."""
    return _r3(yaw) @ _r1(roll) @ _r2(pitch)


def euler_angles_from_matrix(A: np.ndarray, *, tol: float = 1e-9) -> np.ndarray:
    """(φ, θ, ψ) of Example 9 from its matrix A: θ = arccos A₃₃ ∈ [0, π], φ = atan2(A₃₁, −A₃₂),
    ψ = atan2(A₁₃, A₂₃). At θ = 0 or π (gimbal lock) only φ ± ψ is defined: ValueError."""
    A = np.asarray(A, float)
    theta = float(np.arccos(np.clip(A[2, 2], -1.0, 1.0)))
    if np.sin(theta) < tol:
        raise ValueError(
            f"Euler angles at gimbal lock (theta = {theta:.6g}): phi and psi are not "
            "separately defined when the body's x3 axis is along the space x3 axis"
        )
    return np.array([np.arctan2(A[2, 0], -A[2, 1]), theta, np.arctan2(A[0, 2], A[1, 2])])


def direction_cosines(phi: float, theta: float, psi: float) -> np.ndarray:
    """ℓ_ij of (2.2.50) for Example 9's angles (ℓ = Aᵀ)."""
    return euler_matrix_printed(phi, theta, psi).T


@cache
def _direction_cosine_rate_fn():
    f, t, p = sp.symbols("phi theta psi")
    df, dt_, dp = sp.symbols("dphi dtheta dpsi")
    cf, sf, ct, st, cp, sp_ = sp.cos(f), sp.sin(f), sp.cos(t), sp.sin(t), sp.cos(p), sp.sin(p)
    A = sp.Matrix(
        [
            [cp * cf - ct * sf * sp_, cp * sf + ct * cf * sp_, sp_ * st],
            [-sp_ * cf - ct * sf * cp, -sp_ * sf + ct * cf * cp, cp * st],
            [st * sf, -st * cf, ct],
        ]
    )
    ell = A.T
    rate = ell.diff(f) * df + ell.diff(t) * dt_ + ell.diff(p) * dp
    return sp.lambdify((f, t, p, df, dt_, dp), rate, modules="numpy")


def direction_cosine_rates(angles: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """ℓ̇_ij along an Euler-angle motion, exact (sympy derivative of Example 9's matrix)."""
    return np.asarray(_direction_cosine_rate_fn()(*angles, *rates), float)


def angular_velocity_tensor_space(ell: np.ndarray, ell_dot: np.ndarray) -> np.ndarray:
    """ω_mj = ℓ_mi ℓ̇_ji: space components of the angular-velocity tensor, from
    0 = v_m(S) + ℓ_mi ℓ̇_ji x_j ((2.2.59) with v_m(S̄) = 0)."""
    return np.einsum("mi,ji->mj", ell, ell_dot)


def angular_velocity_tensor_body(ell: np.ndarray, ell_dot: np.ndarray) -> np.ndarray:
    """ω̄_mn = ℓ_jn ℓ̇_jm (2.2.62): body components."""
    return np.einsum("jn,jm->mn", ell, ell_dot)


def dual_vector(w_tensor: np.ndarray) -> np.ndarray:
    """ω_i from ω_mn = e_imn ω_i (2.2.61): ω_i = ½ e_imn ω_mn."""
    return 0.5 * np.einsum("imn,mn->i", E, w_tensor)


def euler_angle_rates_to_body(angles: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """Exercise 23 as printed: body components of ω from the Euler-angle rates,
    ω_x = θ̇ cos ψ + φ̇ sin θ sin ψ, ω_y = −θ̇ sin ψ + φ̇ sin θ cos ψ, ω_z = ψ̇ + φ̇ cos θ."""
    _, theta, psi = angles
    dphi, dtheta, dpsi = rates
    return np.array(
        [
            dtheta * np.cos(psi) + dphi * np.sin(theta) * np.sin(psi),
            -dtheta * np.sin(psi) + dphi * np.sin(theta) * np.cos(psi),
            dpsi + dphi * np.cos(theta),
        ]
    )


def relative_velocity_space(
    v_body_frame: np.ndarray, w_space: np.ndarray, x: np.ndarray
) -> np.ndarray:
    """v_m(S̄) = v_m(S) + ω_mj x_j, the first of (2.2.63), solved for v_m(S)."""
    return v_body_frame - w_space @ x


# --- Euler's equations: (2.2.64)–(2.2.72) ------------------------------------------------


def inertia_fourth_order(I: np.ndarray) -> np.ndarray:
    """I_mnst = ½ e_jmn e_ist I_ij (2.2.64)."""
    return 0.5 * np.einsum("jmn,ist,ij->mnst", E, E, I)


def inertia_from_fourth_order(I4: np.ndarray) -> np.ndarray:
    """I_ij = ½ I_pqrs e_ipq e_jrs, the inverse relation of (2.2.64)."""
    return 0.5 * np.einsum("pqrs,ipq,jrs->ij", I4, E, E)


def dual_tensor(h: np.ndarray) -> np.ndarray:
    """H_jk = e_ijk H_i ((2.2.65), (2.2.66))."""
    return np.einsum("ijk,...i->...jk", E, h)


def euler_residual(I: np.ndarray, w: np.ndarray, dw: np.ndarray) -> np.ndarray:
    """Ī_im dω̄_i/dt − e_tmj Ī_ij ω̄_i ω̄_t (2.2.70); equals the body moment M̄_m."""
    return np.einsum("im,...i->...m", I, dw) - np.einsum("tmj,ij,...i,...t->...m", E, I, w, w)


def euler_residual_printed(I: np.ndarray, w: np.ndarray, dw: np.ndarray) -> np.ndarray:
    """(2.2.71) exactly as printed, component by component."""
    w1, w2, w3 = np.moveaxis(np.asarray(w, float), -1, 0)
    a1, a2, a3 = np.moveaxis(np.asarray(dw, float), -1, 0)
    (I11, I12, I13), (I21, I22, I23), (I31, I32, I33) = I
    r1 = (
        I11 * a1 + I21 * a2 + I31 * a3
        + (I13 * w1 + I23 * w2 + I33 * w3) * w2
        - (I12 * w1 + I22 * w2 + I32 * w3) * w3
    )  # fmt: skip
    r2 = (
        I12 * a1 + I22 * a2 + I32 * a3
        + (I11 * w1 + I21 * w2 + I31 * w3) * w3
        - (I13 * w1 + I23 * w2 + I33 * w3) * w1
    )  # fmt: skip
    r3 = (
        I13 * a1 + I23 * a2 + I33 * a3
        + (I12 * w1 + I22 * w2 + I32 * w3) * w1
        - (I11 * w1 + I21 * w2 + I31 * w3) * w2
    )  # fmt: skip
    return np.stack([r1, r2, r3], -1)


def euler_residual_principal(moments: np.ndarray, w: np.ndarray, dw: np.ndarray) -> np.ndarray:
    """(2.2.72) as printed, principal axes: I₁ω̇₁ + (I₃ − I₂)ω₂ω₃, cyclic."""
    I1, I2, I3 = moments
    w1, w2, w3 = np.moveaxis(np.asarray(w, float), -1, 0)
    a1, a2, a3 = np.moveaxis(np.asarray(dw, float), -1, 0)
    return np.stack(
        [
            I1 * a1 + (I3 - I2) * w2 * w3,
            I2 * a2 + (I1 - I3) * w3 * w1,
            I3 * a3 + (I2 - I1) * w1 * w2,
        ],
        -1,
    )


def angular_acceleration(I: np.ndarray, w: np.ndarray, M: np.ndarray) -> np.ndarray:
    """dω̄/dt from (2.2.70): Ī dω̄ = M̄ + e_tmj Ī_ij ω̄_i ω̄_t (body components)."""
    rhs = np.asarray(M, float) + np.einsum("tmj,ij,...i,...t->...m", E, I, w, w)
    return np.linalg.solve(I.T, rhs[..., None])[..., 0]


def euler_fourth_order_residual(I: np.ndarray, w: np.ndarray, dw: np.ndarray) -> np.ndarray:
    """(2.2.69) with ω̄_rk = e_irk ω̄_i: Ī_pqrk dω̄_rk/dt + (δ_αu δ_pv δ_βq + δ_pα δ_βu δ_qv)
    Ī_αβrk ω̄_rk ω̄_uv, a skew tensor equal to M̄_pq; contracting with ½ e_mpq gives (2.2.70)."""
    I4 = inertia_fourth_order(I)
    W, dW = dual_tensor(w), dual_tensor(dw)
    first = np.einsum("pqrk,...rk->...pq", I4, dW)
    # δ_αu δ_pv δ_βq term: Ī_uqrk ω̄_rk ω̄_up ; δ_pα δ_βu δ_qv term: Ī_purk ω̄_rk ω̄_uq
    second = np.einsum("uqrk,...rk,...up->...pq", I4, W, W) + np.einsum(
        "purk,...rk,...uq->...pq", I4, W, W
    )
    return first + second


# --- torque-free motion: the closed form by Jacobi elliptic functions --------------------


@dataclass(frozen=True)
class TorqueFree:
    """ω(t) of a torque-free asymmetric body in principal axes, I₁ < I₂ < I₃, from ω(0):
    with 2T = Σ Iᵢωᵢ² and H² = Σ Iᵢ²ωᵢ² (both conserved, (2.2.40), (2.2.49)), and for
    H² > 2T I₂ (else axes 1 and 3 swap roles, with ω₂ → −ω₂ to keep the equations' form):

        ω₁ = A₁ cn u,  ω₂ = A₂ sn u,  ω₃ = ±A₃ dn u,   u = u₀ + u̇ t,
        A₁² = (2T I₃ − H²)/(I₁(I₃ − I₁)),  A₂² = (2T I₃ − H²)/(I₂(I₃ − I₂)),
        A₃² = (H² − 2T I₁)/(I₃(I₃ − I₁)),  m = k² = (I₂ − I₁)(2T I₃ − H²)/((I₃ − I₂)(H² − 2T I₁)),

    u̇ = ±(I₃ − I₁)A₁A₃/(I₂A₂) from the second of (2.2.72) (the sign of ω₃), and u₀ the
    incomplete elliptic integral F(am u₀ | m) with am u₀ = atan2(ω₂/A₂, ω₁/A₁). Substituting
    into (2.2.72) verifies it with the identities sn' = cn dn, cn' = −sn dn, dn' = −m sn cn.
    """

    moments: tuple[float, float, float]
    w0: tuple[float, float, float]

    def __post_init__(self) -> None:
        I1, I2, I3 = self.moments
        if not 0 < I1 < I2 < I3:
            raise ValueError("moments must satisfy 0 < I1 < I2 < I3 (an asymmetric body)")

    def _setup(self):
        I = np.array(self.moments, float)
        w = np.array(self.w0, float)
        twoT, H2 = float(I @ w**2), float(I**2 @ w**2)
        swap = H2 < twoT * I[1]
        if swap:
            I, w = I[::-1].copy(), np.array([w[2], -w[1], w[0]])
        I1, I2, I3 = I
        A1 = np.sqrt((twoT * I3 - H2) / (I1 * (I3 - I1)))
        A2 = np.sqrt((twoT * I3 - H2) / (I2 * (I3 - I2)))
        A3 = np.sqrt((H2 - twoT * I1) / (I3 * (I3 - I1)))
        m = (I2 - I1) * (twoT * I3 - H2) / ((I3 - I2) * (H2 - twoT * I1))
        s3 = np.sign(w[2]) or 1.0
        rate = s3 * (I3 - I1) * A1 * A3 / (I2 * A2)
        u0 = ellipkinc(np.arctan2(w[1] / A2, w[0] / A1), m)
        return swap, (A1, A2, A3 * s3), m, u0, rate

    def omega(self, t: np.ndarray) -> np.ndarray:
        """Body components ω(t), shape (len(t), 3)."""
        swap, (A1, A2, A3), m, u0, rate = self._setup()
        sn, cn, dn, _ = ellipj(u0 + rate * np.asarray(t, float), m)
        w = np.column_stack([A1 * cn, A2 * sn, A3 * dn])
        return np.column_stack([w[:, 2], -w[:, 1], w[:, 0]]) if swap else w

    @property
    def parameter(self) -> float:
        """m = k² of the elliptic functions (after the swap, if any)."""
        return float(self._setup()[2])

    @property
    def rate(self) -> float:
        """u̇, the rate of the elliptic functions' argument u = u₀ + u̇ t."""
        return float(self._setup()[4])


# --- a rigid body on a ball joint at its centre of mass, in Euler angles ------------------

INERTIA_NAMES = ("I11", "I22", "I33", "I12", "I13", "I23")


def _inertia_matrix(I11, I22, I33, I12, I13, I23):
    return [[I11, I12, I13], [I12, I22, I23], [I13, I23, I33]]


@cache
def rigid_ball_symbolic():
    """The general method for a body turning about its fixed centre of mass: T = ½ Ī_ij ω̄_i ω̄_j
    (2.2.40) with ω̄ of exercise 23 in Example 9's angles (φ, θ, ψ), V = 0 (gravity acts at the
    fixed point); Lagrange's equations (2.2.26) derived exactly."""
    from dyncheck.reference.lagrange import SymbolicSystem

    f, t, p = sp.symbols("phi theta psi")
    df, dt_, dp = sp.symbols("phidot thetadot psidot")
    params = sp.symbols(" ".join(INERTIA_NAMES), real=True)
    w = sp.Matrix(
        [
            dt_ * sp.cos(p) + df * sp.sin(t) * sp.sin(p),
            -dt_ * sp.sin(p) + df * sp.sin(t) * sp.cos(p),
            dp + df * sp.cos(t),
        ]
    )
    I = sp.Matrix(_inertia_matrix(*params))
    T = sp.expand((w.T * I * w)[0, 0] / 2)
    return SymbolicSystem((f, t, p), (df, dt_, dp), params, T, sp.Integer(0), simplify=False)


def rigid_ball(**inertia: float):
    """Numeric general method for the body with inertia components ``I11 … I23`` (kg m²)."""
    return rigid_ball_symbolic().numeric({k: inertia[k] for k in INERTIA_NAMES})


def body_angular_velocity(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """ω̄ of exercise 23 at Euler-angle states, batched (n, 3)."""
    return _ex23(np.atleast_2d(q), np.atleast_2d(v))[0]


def _ex23(q: np.ndarray, v: np.ndarray, a: np.ndarray | None = None):
    """ω̄ (exercise 23) and, given the angle accelerations, dω̄/dt, batched."""
    _, th, ps = np.moveaxis(q, -1, 0)
    dphi, dth, dps = np.moveaxis(v, -1, 0)
    st, ct, sp_, cp = np.sin(th), np.cos(th), np.sin(ps), np.cos(ps)
    w = np.stack([dth * cp + dphi * st * sp_, -dth * sp_ + dphi * st * cp, dps + dphi * ct], -1)
    if a is None:
        return w, None
    a1, a2, a3 = np.moveaxis(a, -1, 0)
    dw = np.stack(
        [
            a2 * cp - dth * sp_ * dps + a1 * st * sp_ + dphi * (ct * dth * sp_ + st * cp * dps),
            -a2 * sp_ - dth * cp * dps + a1 * st * cp + dphi * (ct * dth * cp - st * sp_ * dps),
            a3 + a1 * ct - dphi * st * dth,
        ],
        -1,
    )
    return w, dw


def rigid_ball_printed(*, principal: bool = False, **inertia: float):
    """Euler's equations as printed — (2.2.71), or (2.2.72) in principal axes — with exercise
    23's kinematics: the generalized force on (φ, θ, ψ) is Jᵀ M̄ (virtual work of the body
    moment M̄ through δω̄ = J δq), J = ∂ω̄/∂q̇ of exercise 23; T = ½ Ī ω̄ ω̄ (2.2.40), V = 0."""
    from dyncheck.reference.printed import PrintedDynamics

    I = np.array(_inertia_matrix(*(inertia[k] for k in INERTIA_NAMES)), float)

    def jacobian(q: np.ndarray) -> np.ndarray:
        eye = np.eye(3)
        return np.stack([_ex23(q, np.broadcast_to(e, q.shape))[0] for e in eye], -1)

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        w, dw = _ex23(q, v, a)
        if principal:
            if np.any(I - np.diag(np.diag(I))):
                raise ValueError("(2.2.72) needs principal axes: products of inertia are not 0")
            moments = euler_residual_principal(np.diag(I), w, dw)
        else:
            moments = euler_residual_printed(I, w, dw)
        return np.einsum("nij,ni->nj", jacobian(q), moments)

    return PrintedDynamics(
        residual=residual,
        row_factors=np.ones(3),
        T=lambda q, v: kinetic_energy(I, _ex23(q, v)[0]),
        V=lambda q: np.zeros(len(q)),
    )


@cache
def rigid_free_symbolic():
    """A free body: T = ½ m ẋ·ẋ + ½ Ī ω̄ ω̄ (translation of the centre of mass (2.2.48) and
    rotation about it (2.2.40)), V = m g x₃; coordinates (x₁, x₂, x₃, φ, θ, ψ)."""
    from dyncheck.reference.lagrange import SymbolicSystem

    ball = rigid_ball_symbolic()
    x = sp.symbols("x1 x2 x3")
    xd = sp.symbols("x1dot x2dot x3dot")
    m, g = sp.symbols("m g", positive=True)
    T = ball.T + m * sum(c**2 for c in xd) / 2
    return SymbolicSystem(
        (*x, *ball.q), (*xd, *ball.qd), (*ball.params, m, g), T, m * g * x[2], simplify=False
    )


def rigid_free(m: float, g: float, **inertia: float):
    """Numeric general method for the free body."""
    values = {k: inertia[k] for k in INERTIA_NAMES} | {"m": m, "g": g}
    return rigid_free_symbolic().numeric(values)


def rigid_free_printed(m: float, g: float, **inertia: float):
    """(2.2.48) for the centre of mass, m ẍ = F + m g (gravity −x₃), with Euler's equations
    (2.2.71) and exercise 23 for the rotation: residual (m ẍ + m g e₃, Jᵀ(Euler))."""
    from dyncheck.reference.printed import PrintedDynamics

    rot = rigid_ball_printed(**inertia)

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        lin = m * a[:, :3] + np.array([0.0, 0.0, m * g])
        return np.concatenate([lin, rot.residual(q[:, 3:], v[:, 3:], a[:, 3:])], -1)

    return PrintedDynamics(
        residual=residual,
        row_factors=np.ones(6),
        T=lambda q, v: 0.5 * m * np.sum(v[:, :3] ** 2, -1) + rot.T(q[:, 3:], v[:, 3:]),
        V=lambda q: m * g * q[:, 2],
    )
