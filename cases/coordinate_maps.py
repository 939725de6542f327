"""Maps between the book's generalized coordinates and an engine's joint coordinates.

A map is x̄ = x̄(x) in the notation of (2.2.2): x are the book's coordinates, x̄ the engine's.
Quantities cross it by the book's transformation laws (applied in ``dyncheck.coordinates``):
velocities as contravariant vectors (2.2.4), generalized forces as covariant vectors, the mass
matrix as a covariant 2-tensor, accelerations with the second-derivative term of (2.2.5).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np


class CoordinateMap(Protocol):
    """x̄(x) with its Jacobian and second-derivative term, all batched."""

    description: str

    def to_engine(self, q: np.ndarray) -> np.ndarray: ...
    def to_book(self, qe: np.ndarray) -> np.ndarray: ...
    def jacobian(self, q: np.ndarray) -> np.ndarray: ...
    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...


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


@dataclass(frozen=True)
class SphericalToCartesian:
    """x̄ = (ρ sin θ cos φ, ρ sin θ sin φ, ρ cos θ): the book's spherical coordinates (ρ, θ, φ)
    of Example 5 to an engine's three Cartesian slide joints. Non-linear, so accelerations
    pick up the term (∂²x̄/∂xᵐ∂xⁿ) vᵐ vⁿ of (2.2.5); singular on the z axis (θ = 0, π)."""

    description: str = "joints (x, y, z) = (ρ sin θ cos φ, ρ sin θ sin φ, ρ cos θ)"

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        rho, th, ph = q.T
        return np.column_stack(
            [rho * np.sin(th) * np.cos(ph), rho * np.sin(th) * np.sin(ph), rho * np.cos(th)]
        )

    def to_book(self, qe: np.ndarray) -> np.ndarray:
        """Principal values: θ ∈ [0, π], φ ∈ (−π, π]."""
        rho = np.linalg.norm(qe, axis=1)
        return np.column_stack([rho, np.arccos(qe[:, 2] / rho), np.arctan2(qe[:, 1], qe[:, 0])])

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        rho, th, ph = q.T
        st, ct, sp_, cp = np.sin(th), np.cos(th), np.sin(ph), np.cos(ph)
        z = np.zeros_like(rho)
        return np.stack(
            [
                np.stack([st * cp, rho * ct * cp, -rho * st * sp_], -1),
                np.stack([st * sp_, rho * ct * sp_, rho * st * cp], -1),
                np.stack([ct, -rho * st, z], -1),
            ],
            -2,
        )

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(∂²x̄/∂xᵐ∂xⁿ) vᵐ vⁿ, written out from the second derivatives of x̄."""
        rho, th, ph = q.T
        rd, thd, phd = v.T
        st, ct, sp_, cp = np.sin(th), np.cos(th), np.sin(ph), np.cos(ph)
        hx = (
            2 * rd * thd * ct * cp
            - 2 * rd * phd * st * sp_
            - rho * thd**2 * st * cp
            - 2 * rho * thd * phd * ct * sp_
            - rho * phd**2 * st * cp
        )
        hy = (
            2 * rd * thd * ct * sp_
            + 2 * rd * phd * st * cp
            - rho * thd**2 * st * sp_
            + 2 * rho * thd * phd * ct * cp
            - rho * phd**2 * st * sp_
        )
        hz = -2 * rd * thd * st - rho * thd**2 * ct
        return np.column_stack([hx, hy, hz])
