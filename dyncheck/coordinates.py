"""Book ↔ engine coordinates: the book's transformation laws, written once.

With x̄ = x̄(x) the engine's coordinates as functions of the book's (2.2.2), J = ∂x̄/∂x:

- velocities are contravariant (2.2.4): v̄ = J v;
- accelerations pick up the second-derivative term of (2.2.5): ā = J a + (∂²x̄/∂x∂x) v v;
- generalized forces are covariant: τ = Jᵀ τ̄;
- the mass matrix is a covariant 2-tensor (the metric of (2.2.21) times mass): M = Jᵀ M̄ J;
- bias forces follow from the engine's equation M̄ ā + h̄ = τ̄ pulled back:
  h = Jᵀ (h̄ + M̄ (∂²x̄/∂x∂x) v v);
- energies are scalars (potential energy up to its datum, (2.2.20)).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from dyncheck.adapters.joint_layouts import (
    from_engine,
)
from dyncheck.adapters.model_tree import StateLayout
from dyncheck.cases.base import Case
from dyncheck.vocabulary import JointType


class CoordinateMap(Protocol):
    def to_engine(self, q: np.ndarray) -> np.ndarray: ...
    def to_book(self, qe: np.ndarray) -> np.ndarray: ...
    def jacobian(self, q: np.ndarray) -> np.ndarray: ...
    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...


def _mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("nij,nj->ni", A, x)


def _mtv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("nji,nj->ni", A, x)


def velocity_to_engine(cmap: CoordinateMap, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v̄ = J v (2.2.4)."""
    return _mv(cmap.jacobian(q), v)


def _left_solve(J: np.ndarray, x: np.ndarray) -> np.ndarray:
    """y with J y = x: J⁻¹ x for a square J; for an embedding (more engine coordinates than
    book ones: a constraint, or a ball joint's spin) the least-squares (JᵀJ)⁻¹ Jᵀ x in the
    canonical coordinates, exact when x lies in J's range, as it does for states of the
    book's model."""
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(J, x[..., None])[..., 0]
    Jt = np.swapaxes(J, -1, -2)
    return np.linalg.solve(Jt @ J, _mv(Jt, x)[..., None])[..., 0]


def velocity_to_book(cmap: CoordinateMap, q: np.ndarray, ve: np.ndarray) -> np.ndarray:
    """v = J⁻¹ v̄ (least squares for an embedding)."""
    return _left_solve(cmap.jacobian(q), ve)


def acceleration_to_engine(
    cmap: CoordinateMap, q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """ā = J a + (∂²x̄/∂x∂x) v v (2.2.5)."""
    return _mv(cmap.jacobian(q), a) + cmap.hessian_term(q, v)


def acceleration_to_book(
    cmap: CoordinateMap, q: np.ndarray, v: np.ndarray, ae: np.ndarray
) -> np.ndarray:
    """a = J⁻¹ (ā − (∂²x̄/∂x∂x) v v) (least squares for an embedding)."""
    return _left_solve(cmap.jacobian(q), ae - cmap.hessian_term(q, v))


def force_to_book(cmap: CoordinateMap, q: np.ndarray, tau_e: np.ndarray) -> np.ndarray:
    """τ = Jᵀ τ̄ (covariant)."""
    return _mtv(cmap.jacobian(q), tau_e)


def force_to_engine(cmap: CoordinateMap, q: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """τ̄ = J⁻ᵀ τ; for an embedding the least-norm τ̄ = J (JᵀJ)⁻¹ τ with Jᵀ τ̄ = τ, in the
    canonical coordinates (a force outside J's range — along a constraint or a spin — would
    change nothing the book sees)."""
    J = cmap.jacobian(q)
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(np.swapaxes(J, -1, -2), tau[..., None])[..., 0]
    return _mv(J, np.linalg.solve(np.swapaxes(J, -1, -2) @ J, tau[..., None])[..., 0])


def mass_matrix_to_book(cmap: CoordinateMap, q: np.ndarray, Me: np.ndarray) -> np.ndarray:
    """M = Jᵀ M̄ J (covariant 2-tensor)."""
    J = cmap.jacobian(q)
    return np.swapaxes(J, -1, -2) @ Me @ J


def bias_to_book(
    cmap: CoordinateMap, q: np.ndarray, v: np.ndarray, Me: np.ndarray, he: np.ndarray
) -> np.ndarray:
    """h = Jᵀ (h̄ + M̄ (∂²x̄/∂x∂x) v v)."""
    return force_to_book(cmap, q, he + _mv(Me, cmap.hessian_term(q, v)))


@dataclass(frozen=True)
class NativeMap:
    """The case's map into the canonical layout (MuJoCo's), which every engine's run is seen
    in (:mod:`dyncheck.case_engine` maps each engine's own layout): the engine's positions
    back to the book's with each quaternion renormalized first (a stepping that lets its norm
    drift, Drake's, is read as the rotation it stands for)."""

    base: Any
    kinds: tuple[JointType, ...]

    @classmethod
    def of(cls, case: Case, base: Any = None) -> NativeMap:
        """``case``'s map (or ``base``, a map of the same coordinates)."""
        kinds = tuple(JointType(j.type) for j in case.multibody().joints)
        return cls(case.engine_map() if base is None else base, kinds)

    @property
    def description(self) -> str:
        return self.base.description

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return self.base.to_engine(q)

    def to_book(self, qn: np.ndarray) -> np.ndarray:
        return self.base.to_book(from_engine(StateLayout().joints(self.kinds), self.kinds, qn))

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        return self.base.jacobian(q)

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.base.hessian_term(q, v)
