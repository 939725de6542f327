"""Forward dynamics of a tree closed by constraints (#78), two ways that must agree.

The tree's equations of motion M(q) v̇ + h(q, v) = τ (2.2.23)–(2.2.24), closed by constraints
C(q) = 0 on its configurations, hold on its velocities as J v = 0 and on its accelerations as
J v̇ + J̇ v = 0 (J = ∂C/∂q on the tree's velocity coordinates). Given M, h, τ, J and J̇ v at one
state:

- **the book's way** (Lagrange in independent coordinates, (2.2.23)–(2.2.26), Example 6's
  cord y₁ + y₂ = ℓ): the velocities that keep the constraints are v = T ż with T a basis of
  J's null space; the accelerations are v̇ = v̇ₚ + T z̈, with v̇ₚ = −J⁺ J̇ v the least-norm
  particular one, and z̈ solves the reduced equations (Tᵀ M T) z̈ = Tᵀ (τ − h − M v̇ₚ): the
  constraint forces, normal to every admissible motion, drop out;
- **the multiplier way** (KKT): M v̇ + h = τ + Jᵀ λ with J v̇ = −J̇ v, λ the constraint forces
  (:mod:`.constraints` solves the same for the book's cords).

A constraint row that is a combination of the others (redundant: a four-bar's planar loop in
3-D gives 6 rows of rank 3) is kept out by J's rank, found from its singular values; rows whose
acceleration equations contradict each other (J v̇ = −J̇ v has no solution) are named.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RANK_RTOL = 1e-10
"""A singular value of J below this fraction of the largest counts as zero (J's entries are
lever arms and direction cosines of order one: its round-off is ~1e-15 relative)."""


@dataclass(frozen=True, kw_only=True)
class Closed:
    """One state's constrained forward dynamics."""

    vdot: np.ndarray
    """v̇ (nv,)."""
    force: np.ndarray
    """The constraint forces Jᵀ λ in generalized coordinates (nv,): one answer whatever the
    rows' redundancy (λ itself is not unique where J has dependent rows)."""
    rank: int
    """J's rank: the number of independent constraints (nv − rank degrees of freedom)."""
    residual: float
    """|J v̇ + J̇ v| of the answer: 0 but for round-off where the rows are consistent."""


def _svd(J: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """J = U Σ Vᵀ (full), and J's rank (:data:`RANK_RTOL`)."""
    u, s, vt = np.linalg.svd(J)
    rank = int(np.sum(s > RANK_RTOL * s[0])) if s.size and s[0] > 0 else 0
    return u, s, vt, rank


def reduced(M: np.ndarray, h: np.ndarray, tau: np.ndarray, *, J: np.ndarray,
            jdot_v: np.ndarray) -> Closed:
    """The book's way: independent coordinates on J's null space (see the module)."""
    u, s, vt, rank = _svd(J)
    T = vt[rank:].T  # (J's null space: the admissible velocities, v = T ż)
    vdot_p = -vt[:rank].T @ ((u[:, :rank].T @ jdot_v) / s[:rank])  # (−J⁺ J̇ v)
    z = np.linalg.solve(T.T @ M @ T, T.T @ (tau - h - M @ vdot_p)) if T.shape[1] else \
        np.zeros(0)
    vdot = vdot_p + T @ z
    return Closed(vdot=vdot, force=M @ vdot + h - tau, rank=rank,
                  residual=float(np.abs(J @ vdot + jdot_v).max(initial=0.0)))


def multipliers(M: np.ndarray, h: np.ndarray, tau: np.ndarray, *, J: np.ndarray,
                jdot_v: np.ndarray) -> Closed:
    """The multiplier way: the KKT system on J's independent rows (its row space's basis
    Vᵣᵀ, the equations Σᵣ⁻¹ Uᵣᵀ of J v̇ = −J̇ v), regular where rows are redundant."""
    u, s, vt, rank = _svd(J)
    rows = vt[:rank]
    n = M.shape[0]
    kkt = np.block([[M, rows.T], [rows, np.zeros((rank, rank))]])
    rhs = (u[:, :rank].T @ -jdot_v) / s[:rank]
    solution = np.linalg.solve(kkt, np.concatenate([tau - h, rhs]))
    vdot, lam = solution[:n], -solution[n:]
    return Closed(vdot=vdot, force=rows.T @ lam, rank=rank,
                  residual=float(np.abs(J @ vdot + jdot_v).max(initial=0.0)))


def inconsistent(J: np.ndarray, jdot_v: np.ndarray, *, atol: float) -> list[int]:
    """The constraint rows whose acceleration equations J v̇ = −J̇ v cannot all hold: where
    −J̇ v has a part outside J's column space larger than ``atol``, the rows carrying it
    (empty: consistent)."""
    u, _, _, rank = _svd(J)
    outside = jdot_v - u[:, :rank] @ (u[:, :rank].T @ jdot_v)
    return [int(i) for i in np.flatnonzero(np.abs(outside) > atol)]


def soft(M: np.ndarray, h: np.ndarray, tau: np.ndarray, *, J: np.ndarray, a_ref: np.ndarray,
         regularizer: np.ndarray) -> Closed:
    """MuJoCo's documented soft constraints (Computation chapter, "Soft constraints"; the
    parameters of :class:`~.constraints.Softness`): with a₀ = M⁻¹ (τ − h) and A = J M⁻¹ Jᵀ,

        f = −(A + R)⁻¹ (J a₀ − a_ref),   v̇ = a₀ + M⁻¹ Jᵀ f,

    i.e. J v̇ = a_ref − R f: the rows' acceleration is J v̇ — no J̇ v — pulled toward a_ref
    and yielding by R f. ``regularizer`` R's diagonal (m,)."""
    a0 = np.linalg.solve(M, tau - h)
    minv_jt = np.linalg.solve(M, J.T)
    f = -np.linalg.solve(J @ minv_jt + np.diag(regularizer), J @ a0 - a_ref) if J.size else \
        np.zeros(0)
    vdot = a0 + minv_jt @ f
    return Closed(vdot=vdot, force=J.T @ f, rank=_svd(J)[3] if J.size else 0,
                  residual=float(np.abs(J @ vdot - a_ref + regularizer * f).max(initial=0.0)))
