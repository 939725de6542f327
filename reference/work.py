"""Work and energy: the work line integral (2.2.19), conservative forces (2.2.20), kinetic
energy (2.2.21) and the energy constant (exercise 19)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import sympy as sp
from scipy.integrate import quad

from dyncheck.reference.curves import Curve


def work(force: Callable[..., sp.Expr | list], curve: Curve, t0: float, t1: float) -> float:
    """W = ∫ Q_r (dxʳ/dt) dt (2.2.19), Q_r the covariant force components as sympy
    expressions of the curve's coordinates (``force(*q)`` → list of N expressions)."""
    Q = sp.Matrix(force(*curve.cs.q)).subs(dict(zip(curve.cs.q, curve.x, strict=True)))
    power = sp.lambdify(curve.t, (Q.T * curve.velocity)[0, 0], "numpy")
    value, _ = quad(lambda t: float(power(t)), t0, t1, epsabs=1e-13, epsrel=1e-13, limit=200)
    return value


def conservative_force(V: sp.Expr, q: tuple[sp.Symbol, ...]) -> Callable[..., list]:
    """Q_r = −∂V/∂xʳ (2.2.20)."""

    def force(*args: sp.Symbol) -> list[sp.Expr]:
        subs = dict(zip(q, args, strict=True))
        return [-sp.diff(V, qi).subs(subs) for qi in q]

    return force


def kinetic_energy(curve: Curve, mass: float, t0: float) -> float:
    """T = ½ M g_mn ẋᵐ ẋⁿ (2.2.21) at t0."""
    return float(0.5 * mass * curve.evaluate(curve.speed**2, t0))


def energy_drift(T: np.ndarray, V: np.ndarray) -> float:
    """max |(T + V) − (T + V)₀| relative to max |T| + max |V| (exercise 19)."""
    E = T + V
    return float(np.abs(E - E[0]).max() / (np.abs(T).max() + np.abs(V).max()))
