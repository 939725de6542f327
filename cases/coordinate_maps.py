"""Maps between the book's generalized coordinates and an engine's joint coordinates.

A map is x̄ = x̄(x) in the notation of (2.2.2): x are the book's coordinates, x̄ the engine's.
Quantities cross it by the book's transformation laws (applied in ``dyncheck.coordinates``):
velocities as contravariant vectors (2.2.4), generalized forces as covariant vectors, the mass
matrix as a covariant 2-tensor, accelerations with the second-derivative term of (2.2.5).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LinearMap:
    """x̄ = A x + c. Batched: q has shape (n, nb); results (n, ne) or (n, ne, nb).

    A linear map has constant Jacobian ∂x̄/∂x = A and no second-derivative term.
    """

    matrix: tuple[tuple[float, ...], ...]
    offset: tuple[float, ...]
    description: str

    @property
    def A(self) -> np.ndarray:
        return np.asarray(self.matrix, dtype=float)

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return q @ self.A.T + np.asarray(self.offset)

    def to_book(self, qe: np.ndarray) -> np.ndarray:
        return np.linalg.solve(self.A, (qe - np.asarray(self.offset)).T).T

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """∂x̄ʳ/∂xʲ of (2.2.4), shape (n, ne, nb)."""
        return np.broadcast_to(self.A, (q.shape[0], *self.A.shape))

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(∂²x̄ʳ/∂xᵐ∂xⁿ) vᵐ vⁿ, the term an acceleration picks up under the map; zero here."""
        return np.zeros((q.shape[0], self.A.shape[0]))
