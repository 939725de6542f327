"""Masses held by inextensible cords: the constrained (KKT) form of Lagrange's equations, and
the soft-constraint model an engine may use instead.

Free coordinates s (one per mass: its displacement along its line of motion, positive down,
from a rest configuration) carry M_s = diag(m) and the free force F = m g + F_applied. The
cords are linear constraints C s = 0 (C s = the cords' length changes). With the multipliers
f (M_s s̈ = F + Cᵀ f) the exact solve is the KKT system

    [M_s  Cᵀ] [s̈]   [F]
    [C    0 ] [−f] = [0],    f = −(C M_s⁻¹ Cᵀ)⁻¹ C a₀,  a₀ = M_s⁻¹ F,

the tension of a cord being −f. It is Lagrange's method with multipliers, equivalent to
(2.2.23)–(2.2.26) in the independent coordinates (Example 6: y₁ + y₂ = ℓ).

The soft model is MuJoCo's documented constraint model (Computation chapter, "Soft
constraints"; parameters solref = (timeconst, dampratio), solimp = (dmin, dmax, width, mid,
power)): with violation r = C s, its rate ṙ, impedance d(r) and A = C M_s⁻¹ Cᵀ,

    f = −(A + R)⁻¹ (C a₀ − a_ref),   R = (1 − d)/d · diag(A),
    a_ref = −b ṙ − k d(r) r,         b = 2/(dmax τ),  k = 1/(dmax² τ² ζ²),

d clamped to [1e-4, 0.9999]. At r = ṙ = 0 this gives s̈ = a_exact + (1 − d)(a₀ − a_exact) and
f = d f_exact. (MuJoCo also raises τ to at least twice the time step; the steps used here,
≤ τ/2, never trigger it.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_IMPEDANCE, MAX_IMPEDANCE = 1e-4, 0.9999


@dataclass(frozen=True)
class Softness:
    """A soft constraint's parameters, MuJoCo's solref and solimp."""

    timeconst: float
    dampratio: float
    dmin: float
    dmax: float
    width: float
    mid: float
    power: float

    def impedance(self, r: np.ndarray) -> np.ndarray:
        """d(r): dmin at r = 0 rising to dmax at |r| = width along two power-law halves
        joined at ``mid``, clamped to [1e-4, 0.9999]."""
        x = np.clip(np.abs(r) / self.width, 0.0, 1.0)
        p, mid = self.power, self.mid
        y = np.where(
            x <= mid,
            x**p / mid ** (p - 1),
            1 - (1 - x) ** p / (1 - mid) ** (p - 1),
        )
        return np.clip(self.dmin + y * (self.dmax - self.dmin), MIN_IMPEDANCE, MAX_IMPEDANCE)

    @property
    def damping(self) -> float:
        """b = 2/(dmax τ), 1/s."""
        return 2.0 / (self.dmax * self.timeconst)

    @property
    def stiffness(self) -> float:
        """k = 1/(dmax² τ² ζ²), 1/s² (multiplied by d(r) in a_ref)."""
        return 1.0 / (self.dmax**2 * self.timeconst**2 * self.dampratio**2)


@dataclass(frozen=True)
class CordSystem:
    """Point masses on vertical lines held by cords.

    ``masses`` (k,), ``g`` (m/s², down), ``C`` (nc, k) the cords' length changes per unit
    displacement, and the book's coordinates x mapped to the free ones by s = A x + b
    (``A`` (k, N), ``b`` (k,)), with C A = 0 and C b = 0 (the book's coordinates satisfy the
    cords identically)."""

    masses: np.ndarray
    g: float
    C: np.ndarray
    A: np.ndarray
    b: np.ndarray

    def __post_init__(self) -> None:
        scale = float(np.abs(self.C).max() * max(1.0, np.abs(self.A).max()))
        if np.abs(self.C @ self.A).max() > 1e-12 * scale:
            raise ValueError("the book's coordinates do not satisfy the cords (C A != 0)")

    # --- coordinates --------------------------------------------------------------------

    def to_free(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(s, ṡ) = (A x + b, A ẋ), batched (n, k)."""
        return np.atleast_2d(q) @ self.A.T + self.b, np.atleast_2d(v) @ self.A.T

    def force_to_free(self, tau: np.ndarray) -> np.ndarray:
        """The book's generalized force spread over the masses by least norm,
        F = A (AᵀA)⁻¹ τ (Aᵀ F = τ; the convention the comparison layer uses for engines)."""
        return np.linalg.solve(self.A.T @ self.A, np.atleast_2d(tau).T).T @ self.A.T

    def to_book(self, a_free: np.ndarray) -> np.ndarray:
        """Least-squares book components (AᵀA)⁻¹ Aᵀ of free-coordinate vectors (n, k)."""
        return np.linalg.solve(self.A.T @ self.A, self.A.T @ np.atleast_2d(a_free).T).T

    # --- dynamics -----------------------------------------------------------------------

    def free_acceleration(self, F: np.ndarray) -> np.ndarray:
        """a₀ = g + F/m: every mass falling freely under gravity and its applied force."""
        return self.g + np.atleast_2d(F) / self.masses

    def solve(
        self,
        s: np.ndarray,
        sd: np.ndarray,
        F: np.ndarray,
        softness: Softness | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(s̈, f), batched: the exact KKT solve (``softness`` None) or the soft model."""
        a0 = self.free_acceleration(F)
        Minv_Ct = self.C.T / self.masses[:, None]  # (k, nc)
        A = self.C @ Minv_Ct
        rhs = a0 @ self.C.T  # C a₀, (n, nc)
        if softness is None:
            f = -np.linalg.solve(A, rhs.T).T
        else:
            r, rd = np.atleast_2d(s) @ self.C.T, np.atleast_2d(sd) @ self.C.T
            d = softness.impedance(r)
            a_ref = -softness.damping * rd - softness.stiffness * d * r
            R = (1 - d) / d * np.diag(A)
            f = np.stack(
                [
                    -np.linalg.solve(A + np.diag(Rk), ck)
                    for Rk, ck in zip(R, rhs - a_ref, strict=True)
                ]
            )
        return a0 + f @ Minv_Ct.T, f

    def tension(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, softness=None) -> np.ndarray:
        """The cords' tensions −f (N) at book states, shape (n, nc)."""
        s, sd = self.to_free(q, v)
        return -self.solve(s, sd, self.force_to_free(tau), softness)[1]

    def acceleration(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, softness=None
    ) -> np.ndarray:
        """ẍ (book coordinates, least squares) of the exact or the soft solve."""
        s, sd = self.to_free(q, v)
        return self.to_book(self.solve(s, sd, self.force_to_free(tau), softness)[0])
