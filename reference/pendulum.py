"""Examples 7 and 8 of §2.2: the simple and the compound pendulum.

Each system twice: as the book prints its equations (``*_printed``), and by the general
method of :mod:`dyncheck.reference.lagrange` from the particle positions (2.2.28) — the two
must agree. The general method also takes a rotational inertia I about each bob's centre
(T gains ½ I θ̇², θ absolute: the planar case of (2.2.40)), which the book's point masses
have not; it is how a model that cannot hold a point mass is predicted.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import sympy as sp

from dyncheck.reference.lagrange import LagrangianDynamics, SymbolicSystem, particle_energies
from dyncheck.reference.printed import PrintedDynamics


@cache
def simple_pendulum_symbolic() -> SymbolicSystem:
    """Example 7 from the bob's position (ℓ sin θ, −ℓ cos θ), plus ½ I θ̇²."""
    th, thd = sp.symbols("theta thetadot")
    m, l, g, inertia = sp.symbols("m l g I", positive=True)
    T, V = particle_energies([m], [(l * sp.sin(th), -l * sp.cos(th))], [th], [thd], g)
    return SymbolicSystem((th,), (thd,), (m, l, g, inertia), T + inertia * thd**2 / 2, V)


@cache
def compound_pendulum_symbolic() -> SymbolicSystem:
    """Example 8 from (2.2.27)–(2.2.28), plus ½ I₁ θ̇₁² + ½ I₂ θ̇₂²."""
    th1, th2, th1d, th2d = sp.symbols("theta1 theta2 theta1dot theta2dot")
    m1, m2, L1, L2, g, I1, I2 = sp.symbols("m1 m2 L1 L2 g I1 I2", positive=True)
    r1 = (L1 * sp.sin(th1), -L1 * sp.cos(th1))
    r2 = (r1[0] + L2 * sp.sin(th2), r1[1] - L2 * sp.cos(th2))
    T, V = particle_energies([m1, m2], [r1, r2], [th1, th2], [th1d, th2d], g)
    T = T + I1 * th1d**2 / 2 + I2 * th2d**2 / 2
    return SymbolicSystem((th1, th2), (th1d, th2d), (m1, m2, L1, L2, g, I1, I2), T, V)


@cache
def _simple_numeric(m: float, l: float, g: float, inertia: float) -> LagrangianDynamics:
    return simple_pendulum_symbolic().numeric({"m": m, "l": l, "g": g, "I": inertia})


@cache
def _compound_numeric(*values: float) -> LagrangianDynamics:
    names = ("m1", "m2", "L1", "L2", "g", "I1", "I2")
    return compound_pendulum_symbolic().numeric(dict(zip(names, values, strict=True)))


def simple_pendulum(
    m: float, l: float, g: float, *, inertia: tuple[float] = (0.0,)
) -> LagrangianDynamics:
    """General method for Example 7; ``inertia`` = (I,) about the bob's centre, kg·m²."""
    return _simple_numeric(m, l, g, inertia[0])


def compound_pendulum(
    m1: float, m2: float, L1: float, L2: float, g: float, *, inertia: tuple[float, float] = (0, 0)
) -> LagrangianDynamics:
    """General method for Example 8; ``inertia`` = (I₁, I₂) about the bobs' centres, kg·m²."""
    return _compound_numeric(m1, m2, L1, L2, g, *map(float, inertia))


def simple_pendulum_printed(m: float, l: float, g: float) -> PrintedDynamics:
    """Example 7 as printed: θ̈ + (g/ℓ) sin θ = 0 — Lagrange's equation divided by mℓ²;
    T = ½ mℓ²θ̇², V = mgℓ(1 − cos θ)."""

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        return a + (g / l) * np.sin(q)

    return PrintedDynamics(
        residual=residual,
        row_factors=np.array([m * l**2]),
        T=lambda q, v: 0.5 * m * l**2 * v[:, 0] ** 2,
        V=lambda q: m * g * l * (1 - np.cos(q[:, 0])),
    )


def compound_pendulum_printed(
    m1: float, m2: float, L1: float, L2: float, g: float
) -> PrintedDynamics:
    """Example 8 as printed (absolute angles)::

        L₁θ̈₁ + m₂/(m₁+m₂) L₂θ̈₂ cos(θ₁−θ₂) + m₂/(m₁+m₂) L₂θ̇₂² sin(θ₁−θ₂) + g sin θ₁ = 0
        L₁θ̈₁ cos(θ₁−θ₂) + L₂θ̈₂ − L₁θ̇₁² sin(θ₁−θ₂) + g sin θ₂ = 0

    the Lagrange equations divided by (m₁+m₂)L₁ and m₂L₂; T is (2.2.29) and
    V = −(m₁+m₂)gL₁ cos θ₁ − m₂gL₂ cos θ₂.
    """
    mu = m2 / (m1 + m2)

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        d = q[:, 0] - q[:, 1]
        e1 = (
            L1 * a[:, 0]
            + mu * L2 * a[:, 1] * np.cos(d)
            + mu * L2 * v[:, 1] ** 2 * np.sin(d)
            + g * np.sin(q[:, 0])
        )
        e2 = (
            L1 * a[:, 0] * np.cos(d)
            + L2 * a[:, 1]
            - L1 * v[:, 0] ** 2 * np.sin(d)
            + g * np.sin(q[:, 1])
        )
        return np.stack([e1, e2], -1)

    def kinetic(q: np.ndarray, v: np.ndarray) -> np.ndarray:  # (2.2.29)
        return (
            0.5 * (m1 + m2) * L1**2 * v[:, 0] ** 2
            + m2 * L1 * L2 * v[:, 0] * v[:, 1] * np.cos(q[:, 0] - q[:, 1])
            + 0.5 * m2 * L2**2 * v[:, 1] ** 2
        )

    return PrintedDynamics(
        residual=residual,
        row_factors=np.array([(m1 + m2) * L1, m2 * L2]),
        T=kinetic,
        V=lambda q: -(m1 + m2) * g * L1 * np.cos(q[:, 0]) - m2 * g * L2 * np.cos(q[:, 1]),
    )


@cache
def spherical_pendulum_symbolic() -> SymbolicSystem:
    """Exercise 28 from the bob's position ℓ(sin φ sin θ, sin φ cos θ, cos φ) (z down, so
    V = −m g z), plus ½ I (φ̇² + sin²φ θ̇²): the bob's rotational inertia I about its centre
    for the swing rotation ω⊥ = r̂ × ṙ̂ (a point mass has no spin degree of freedom)."""
    ph, th, phd, thd = sp.symbols("phi theta phidot thetadot")
    m, l, g, inertia = sp.symbols("m l g I", positive=True)
    r = (l * sp.sin(ph) * sp.sin(th), l * sp.sin(ph) * sp.cos(th), l * sp.cos(ph))
    rdot = [sp.diff(c, ph) * phd + sp.diff(c, th) * thd for c in r]
    T = m * sum(c**2 for c in rdot) / 2 + inertia * (phd**2 + sp.sin(ph) ** 2 * thd**2) / 2
    return SymbolicSystem((ph, th), (phd, thd), (m, l, g, inertia), sp.expand(T), -m * g * r[2])


@cache
def _spherical_numeric(m: float, l: float, g: float, inertia: float) -> LagrangianDynamics:
    return spherical_pendulum_symbolic().numeric({"m": m, "l": l, "g": g, "I": inertia})


def spherical_pendulum(
    m: float,
    l: float,
    g: float,
    *,
    inertia: tuple[float] = (0.0,),
) -> LagrangianDynamics:
    """General method for exercise 28; ``inertia`` = (I,) about the bob's centre, kg·m²."""
    return _spherical_numeric(m, l, g, inertia[0])


def spherical_pendulum_printed(m: float, l: float, g: float) -> PrintedDynamics:
    """Exercise 28 as printed, coordinates (φ, θ)::

        d/dt(sin²φ θ̇) = 0        φ̈ − θ̇² sin φ cos φ + (g/ℓ) sin φ = 0

    both Lagrange's equations divided by mℓ² (the first with d/dt expanded); the exercise
    prints no T or V: T = ½mℓ²(φ̇² + sin²φ θ̇²), V = −mgℓ cos φ, as its Lagrangian implies."""

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        s, c = np.sin(q[:, 0]), np.cos(q[:, 0])
        e_phi = a[:, 0] - v[:, 1] ** 2 * s * c + (g / l) * s
        e_theta = 2 * s * c * v[:, 0] * v[:, 1] + s**2 * a[:, 1]
        return np.stack([e_phi, e_theta], -1)

    return PrintedDynamics(
        residual=residual,
        row_factors=np.array([m * l**2, m * l**2]),
        T=lambda q, v: 0.5 * m * l**2 * (v[:, 0] ** 2 + np.sin(q[:, 0]) ** 2 * v[:, 1] ** 2),
        V=lambda q: -m * g * l * np.cos(q[:, 0]),
    )
