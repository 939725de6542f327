"""Example 6 (the simple pulley, Atwood's machine) and exercise 17 (the pulley and mass system).

Depths are measured down from the fixed pulley's axle (the book's y of Example 6 grows
downward); pulleys are massless with radius a, each cord wrapping half a pulley (πa).

Example 6: masses m₁, m₂ at depths y₁ and y₂ = ℓ − y₁ (the book's y₁ + y₂ = ℓ); one
coordinate y₁. Exercise 17 (its figure is not in the text; the classic double Atwood machine):
the upper cord (length ℓ₁) runs from m₁ over the fixed pulley to the axle of a movable pulley
at depth y_P = ℓ₁ − πa − y₁; the lower cord (length ℓ₂) over the movable pulley carries m₂ and
m₃ at y₂ and ℓ₂ − πa − y₂ below its axle. Coordinates (y₁, y₂). Horizontally m₁ hangs at
x = −a, the movable pulley at +a, m₂ at 0 and m₃ at 2a (no effect on the motion).

Each system: the general method from the particle positions (2.2.25)–(2.2.26); the printed
equations (Example 6's; for exercise 17 the answer derived by hand, the book printing none);
and the cords as constraints on the free masses (:mod:`.constraints`) for the tension and for
a soft-constraint model.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

from dyncheck.reference.constraints import CordSystem, Softness
from dyncheck.reference.lagrange import LagrangianDynamics, SymbolicSystem, particle_energies
from dyncheck.reference.printed import PrintedDynamics
from dyncheck.reference.trajectory import solve_second_order


@cache
def atwood_symbolic() -> SymbolicSystem:
    """Example 6 from the positions (−a, −y₁) and (a, −(ℓ − y₁)) (y up for the energies)."""
    y1, y1d = sp.symbols("y1 y1dot")
    m1, m2, a, l, g = sp.symbols("m1 m2 a l g", positive=True)
    T, V = particle_energies([m1, m2], [(-a, -y1), (a, -(l - y1))], [y1], [y1d], g)
    return SymbolicSystem((y1,), (y1d,), (m1, m2, a, l, g), T, V)


def _compound_depths(y1, y2, a, l1, l2):
    """Depths of m₁, m₂, m₃ for book coordinates (y₁, y₂)."""
    yp = l1 - sp.pi * a - y1
    return y1, yp + y2, yp + l2 - sp.pi * a - y2


@cache
def compound_pulley_symbolic() -> SymbolicSystem:
    """Exercise 17 from the three masses' positions."""
    y1, y2, y1d, y2d = sp.symbols("y1 y2 y1dot y2dot")
    m1, m2, m3, a, l1, l2, g = sp.symbols("m1 m2 m3 a l1 l2 g", positive=True)
    z1, z2, z3 = _compound_depths(y1, y2, a, l1, l2)
    positions = [(-a, -z1), (0 * a, -z2), (2 * a, -z3)]
    T, V = particle_energies([m1, m2, m3], positions, [y1, y2], [y1d, y2d], g)
    return SymbolicSystem((y1, y2), (y1d, y2d), (m1, m2, m3, a, l1, l2, g), T, V)


def atwood_cords(m1: float, m2: float, g: float, rest: float, l: float) -> CordSystem:
    """Free masses at depths (y₁, ℓ − y₁), displacements from the rest depths (rest, ℓ − rest);
    the cord's length change is s₁ + s₂."""
    return CordSystem(
        np.array([m1, m2]),
        g,
        np.array([[1.0, 1.0]]),
        np.array([[1.0], [-1.0]]),
        np.array([-rest, rest]),
    )


def compound_cords(
    m1: float, m2: float, m3: float, g: float, rest: tuple[float, float]
) -> CordSystem:
    """Free masses at the depths of :func:`_compound_depths`, displacements from the rest
    state's. One constraint with the massless pulley eliminated: 2 s₁ + s₂ + s₃ = 0 (the
    lower cord's length change plus twice the upper's), so −f is the lower cord's tension and
    the upper cord carries twice it."""
    A = np.array([[1.0, 0.0], [-1.0, 1.0], [-1.0, -1.0]])
    return CordSystem(
        np.array([m1, m2, m3]), g, np.array([[2.0, 1.0, 1.0]]), A, -A @ np.asarray(rest, float)
    )


@dataclass(frozen=True)
class CordDynamics:
    """The general method in the book's coordinates together with the cords: M, h, inverse
    dynamics and energies from Lagrange's equations; forward dynamics and the tensions from
    the cords' solve — exact (equal to Lagrange's, tested) or, with ``softness``, the soft
    model's at the same states. ``free`` integrates the free masses (off the cords' manifold
    when soft)."""

    lagrange: LagrangianDynamics
    cords: CordSystem
    softness: Softness | None = None

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        return self.lagrange.mass_matrix(q)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.lagrange.bias(q, v)

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Unchanged by the cords' model: τ = Aᵀ(M_s s̈ − m g) annihilates any cord force."""
        return self.lagrange.inverse(q, v, a)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.lagrange.kinetic_energy(q, v)

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        return self.lagrange.potential_energy(q)

    def field_force(self, q: np.ndarray) -> np.ndarray:
        return self.lagrange.field_force(q)

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        if self.softness is None:
            return self.lagrange.forward(q, v, tau)
        return self.cords.acceleration(q, v, tau, self.softness)

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The cords' tensions, N, shape (n, nc)."""
        return self.cords.tension(q, v, tau, self.softness)

    @property
    def polynomial_degree(self) -> int | None:
        """With the cords exact, ẍ is constant: q(t) is a quadratic in t, integrated exactly
        by every Runge–Kutta method of order ≥ 2. The soft model's is not polynomial."""
        return 2 if self.softness is None else None

    def free(self, s: np.ndarray, sd: np.ndarray) -> np.ndarray:
        """s̈ of the free masses at free states (τ = 0), the model's own solve."""
        zero = np.zeros_like(np.atleast_2d(s))
        return self.cords.solve(s, sd, zero, self.softness)[0]

    def free_trajectory(
        self, q0: np.ndarray, v0: np.ndarray, t: np.ndarray, rtol: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Free coordinates s(t) and the cords' violation C s(t) from the book state
        (q0, v0) (on the cords), by DOP853 on the free masses: the model's own motion,
        also where a soft model lets the masses leave the cords' manifold."""
        s0, sd0 = self.cords.to_free(q0, v0)
        s, _ = solve_second_order(
            lambda x, xd: self.free(x[None], xd[None])[0], s0[0], sd0[0], t, rtol, rtol
        )
        return s, s @ self.cords.C.T

    def trajectory(self, q0: np.ndarray, v0: np.ndarray, t: np.ndarray, rtol: float) -> np.ndarray:
        """q(t), book coordinates (least squares from the free masses' motion)."""
        s, _ = self.free_trajectory(q0, v0, t, rtol)
        return self.cords.to_book(s - self.cords.b)


def atwood(
    m1: float,
    m2: float,
    a: float,
    l: float,
    g: float,
    rest: float,
    *,
    softness: Softness | None = None,
) -> CordDynamics:
    """General method for Example 6 with its cord; ``rest`` is the rest depth y₁ (m)."""
    values = {"m1": m1, "m2": m2, "a": a, "l": l, "g": g}
    return CordDynamics(
        atwood_symbolic().numeric(values),
        atwood_cords(m1, m2, g, rest, l),
        softness,
    )


def compound_pulley(
    m1: float,
    m2: float,
    m3: float,
    a: float,
    l1: float,
    l2: float,
    g: float,
    rest: tuple[float, float],
    *,
    softness: Softness | None = None,
) -> CordDynamics:
    """General method for exercise 17 with its cords; ``rest`` = rest (y₁, y₂), m."""
    values = {"m1": m1, "m2": m2, "m3": m3, "a": a, "l1": l1, "l2": l2, "g": g}
    return CordDynamics(
        compound_pulley_symbolic().numeric(values),
        compound_cords(m1, m2, m3, g, rest),
        softness,
    )


def atwood_printed(m1: float, m2: float, g: float) -> PrintedDynamics:
    """Example 6 as printed: (m₁ + m₂) ÿ₁ = (m₁ − m₂) g, T = ½(m₁ + m₂) ẏ₁², and V from
    dW = (m₁ − m₂) g dy₁: V = −(m₁ − m₂) g y₁ (datum y₁ = 0)."""

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        return (m1 + m2) * a - (m1 - m2) * g

    return PrintedDynamics(
        residual=residual,
        row_factors=np.array([1.0]),
        T=lambda q, v: 0.5 * (m1 + m2) * v[:, 0] ** 2,
        V=lambda q: -(m1 - m2) * g * q[:, 0],
    )


def compound_pulley_printed(m1: float, m2: float, m3: float, g: float) -> PrintedDynamics:
    """Exercise 17 answered by hand (the book prints no answer): with
    T = ½ m₁ẏ₁² + ½ m₂(ẏ₂ − ẏ₁)² + ½ m₃(ẏ₁ + ẏ₂)² and dW = g[(m₁ − m₂ − m₃) dy₁ + (m₂ − m₃) dy₂],

        (m₁ + m₂ + m₃) ÿ₁ + (m₃ − m₂) ÿ₂ = (m₁ − m₂ − m₃) g
        (m₃ − m₂) ÿ₁ + (m₂ + m₃) ÿ₂ = (m₂ − m₃) g.
    """

    def residual(q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        e1 = (m1 + m2 + m3) * a[:, 0] + (m3 - m2) * a[:, 1] - (m1 - m2 - m3) * g
        e2 = (m3 - m2) * a[:, 0] + (m2 + m3) * a[:, 1] - (m2 - m3) * g
        return np.stack([e1, e2], -1)

    def kinetic(q: np.ndarray, v: np.ndarray) -> np.ndarray:
        y1d, y2d = v[:, 0], v[:, 1]
        return 0.5 * (m1 * y1d**2 + m2 * (y2d - y1d) ** 2 + m3 * (y1d + y2d) ** 2)

    return PrintedDynamics(
        residual=residual,
        row_factors=np.array([1.0, 1.0]),
        T=kinetic,
        V=lambda q: -g * ((m1 - m2 - m3) * q[:, 0] + (m2 - m3) * q[:, 1]),
    )
