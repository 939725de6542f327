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
    to_engine,
    velocity_frame_rates,
    velocity_frames,
)
from dyncheck.adapters.model_tree import Layout, StateLayout
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


def _weight(cmap: CoordinateMap, q: np.ndarray) -> np.ndarray | None:
    """The metric W of an embedding's least squares: the identity in the case's canonical
    engine coordinates; an engine whose velocities are T times them (a chart's rates) weighs
    by W = T⁻ᵀ T⁻¹, so that what the book cannot see (a spin) is chosen as canonically."""
    weight = getattr(cmap, "weight", None)
    return None if weight is None else weight(q)


def _left_solve(J: np.ndarray, x: np.ndarray, W: np.ndarray | None = None) -> np.ndarray:
    """y with J y = x: J⁻¹ x for a square J; for an embedding (more engine coordinates than
    book ones: a constraint, or a ball joint's spin) the least-squares (JᵀWJ)⁻¹ JᵀW x, exact
    when x lies in J's range, as it does for states of the book's model."""
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(J, x[..., None])[..., 0]
    Jt = np.swapaxes(J, -1, -2)
    if W is not None:
        Jt = Jt @ W
    return np.linalg.solve(Jt @ J, _mv(Jt, x)[..., None])[..., 0]


def velocity_to_book(cmap: CoordinateMap, q: np.ndarray, ve: np.ndarray) -> np.ndarray:
    """v = J⁻¹ v̄ (least squares for an embedding)."""
    return _left_solve(cmap.jacobian(q), ve, _weight(cmap, q))


def acceleration_to_engine(
    cmap: CoordinateMap, q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> np.ndarray:
    """ā = J a + (∂²x̄/∂x∂x) v v (2.2.5)."""
    return _mv(cmap.jacobian(q), a) + cmap.hessian_term(q, v)


def acceleration_to_book(
    cmap: CoordinateMap, q: np.ndarray, v: np.ndarray, ae: np.ndarray
) -> np.ndarray:
    """a = J⁻¹ (ā − (∂²x̄/∂x∂x) v v) (least squares for an embedding)."""
    return _left_solve(cmap.jacobian(q), ae - cmap.hessian_term(q, v), _weight(cmap, q))


def force_to_book(cmap: CoordinateMap, q: np.ndarray, tau_e: np.ndarray) -> np.ndarray:
    """τ = Jᵀ τ̄ (covariant)."""
    return _mtv(cmap.jacobian(q), tau_e)


def force_to_engine(cmap: CoordinateMap, q: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """τ̄ = J⁻ᵀ τ; for an embedding the least-norm τ̄ = W J (JᵀWJ)⁻¹ τ with Jᵀ τ̄ = τ (a force
    outside J's range — along a constraint or a spin — would change nothing the book sees;
    W as in :func:`_weight`)."""
    J = cmap.jacobian(q)
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(np.swapaxes(J, -1, -2), tau[..., None])[..., 0]
    W = _weight(cmap, q)
    WJ = J if W is None else W @ J
    return _mv(WJ, np.linalg.solve(np.swapaxes(J, -1, -2) @ WJ, tau[..., None])[..., 0])


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
    """The case's map followed by the engine's storage of each joint (its
    :class:`~dyncheck.adapters.model_tree.Layout`, mapped by :mod:`dyncheck.adapters.layout`):
    quaternion order or chart, a free joint's layout, and the frames (or angle rates) of a
    rotating joint's velocities, v_native = T v_canonical."""

    base: Any
    layouts: tuple[Layout, ...]
    kinds: tuple[JointType, ...]

    @classmethod
    def of(cls, case: Case, base: Any = None,
           state_layout: StateLayout | None = None) -> NativeMap:
        """``case``'s map (or ``base``) into ``state_layout`` (by default the canonical one,
        MuJoCo's, which every engine's run is seen in: :mod:`dyncheck.case_engine`)."""
        kinds = tuple(JointType(j.type) for j in case.multibody().joints)
        layouts = tuple((state_layout or StateLayout()).joints(kinds))
        return cls(case.engine_map() if base is None else base, layouts, kinds)

    @property
    def description(self) -> str:
        return self.base.description

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return to_engine(self.layouts, self.kinds, self.base.to_engine(q))

    def to_book(self, qn: np.ndarray) -> np.ndarray:
        return self.base.to_book(from_engine(self.layouts, self.kinds, qn))

    def _frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """The canonical engine state of ``q`` and T there (None where T = 1)."""
        qe = self.base.to_engine(q)
        return qe, velocity_frames(self.layouts, self.kinds, qe)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """T J: the case's Jacobian, then the engine's velocity frames."""
        J = self.base.jacobian(q)
        T = self._frames(q)[1]
        return J if T is None else T @ J

    def weight(self, q: np.ndarray) -> np.ndarray | None:
        """W = T⁻ᵀ T⁻¹: least squares in the canonical coordinates (None where T = 1)."""
        T = self._frames(q)[1]
        if T is None:
            return None
        Tinv = np.linalg.inv(T)
        return np.swapaxes(Tinv, -1, -2) @ Tinv

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """T H + Ṫ J v: the frames' rotation adds to the (2.2.5)-type term."""
        H = self.base.hessian_term(q, v)
        qe, T = self._frames(q)
        if T is None:
            return H
        ve = np.einsum("nij,nj->ni", self.base.jacobian(q), v)
        rates = velocity_frame_rates(self.layouts, self.kinds, qe, ve, T)
        return np.einsum("nij,nj->ni", T, H) + rates
