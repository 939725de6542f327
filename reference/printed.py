"""Equations of motion exactly as the book prints them, made usable as dynamics.

A printed system is a residual E(x, ẋ, ẍ) = 0, linear in ẍ, usually Lagrange's equation
divided through by a factor per row ("simplifying", Examples 7 and 8). With the row factors
s_r stated, s_r E_r is Lagrange's form (2.2.23), so M = diag(s) ∂E/∂ẍ and h = diag(s) E(x, ẋ, 0),
and an applied generalized force τ enters as s_r E_r = τ_r.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

Residual = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class PrintedDynamics:
    """The book's printed residual E, its row factors s, and its printed T and V."""

    residual: Residual
    row_factors: np.ndarray
    T: Callable[[np.ndarray, np.ndarray], np.ndarray]
    V: Callable[[np.ndarray], np.ndarray]
    field: Callable[[np.ndarray], np.ndarray] | None = None
    """Generalized force Q_r(x) of an external field, applied like τ (not part of h)."""

    def field_force(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        return np.zeros_like(q, dtype=float) if self.field is None else self.field(q)

    @property
    def ndof(self) -> int:
        return self.row_factors.shape[0]

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """diag(s) ∂E/∂ẍ, read off column by column (E is linear in ẍ), shape (n, N, N)."""
        q = np.atleast_2d(q)
        v = np.zeros_like(q)
        e0 = self.residual(q, v, np.zeros_like(q))
        cols = [
            self.residual(q, v, np.broadcast_to(np.eye(self.ndof)[j], q.shape)) - e0
            for j in range(self.ndof)
        ]
        return self.row_factors[:, None] * np.stack(cols, -1)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        q, v = np.atleast_2d(q), np.atleast_2d(v)
        return self.row_factors * self.residual(q, v, np.zeros_like(q))

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        rhs = np.atleast_2d(tau) + self.field_force(q) - self.bias(q, v)
        return np.linalg.solve(self.mass_matrix(q), rhs[..., None])[..., 0]

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        q, v, a = np.atleast_2d(q), np.atleast_2d(v), np.atleast_2d(a)
        return self.row_factors * self.residual(q, v, a) - self.field_force(q)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.T(np.atleast_2d(q), np.atleast_2d(v))

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        return self.V(np.atleast_2d(q))
