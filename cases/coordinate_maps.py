"""Maps between the book's generalized coordinates and an engine's joint coordinates.

A map is x̄ = x̄(x) in the notation of (2.2.2): x are the book's coordinates, x̄ the engine's.
Quantities cross it by the book's transformation laws (applied in ``dyncheck.coordinates``):
velocities as contravariant vectors (2.2.4), generalized forces as covariant vectors, the mass
matrix as a covariant 2-tensor, accelerations with the second-derivative term of (2.2.5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Protocol

import numpy as np

from dyncheck.errors import InvalidInput


class CoordinateMap(Protocol):
    """x̄(x) with its Jacobian and second-derivative term, all batched."""

    @property
    def description(self) -> str: ...

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

    @cached_property
    def A(self) -> np.ndarray:
        """The matrix as an array (read-only: built once, asked at every stage of a step)."""
        A = np.asarray(self.matrix, dtype=float)
        A.flags.writeable = False
        return A

    @cached_property
    def _offset(self) -> np.ndarray:
        c = np.asarray(self.offset, dtype=float)
        c.flags.writeable = False
        return c

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return q @ self.A.T + self._offset

    def to_book(self, qe: np.ndarray) -> np.ndarray:
        """x = A⁻¹ (x̄ − c); least squares (AᵀA)⁻¹Aᵀ(x̄ − c) for an embedding (more engine
        coordinates than book ones: a constraint's), exact on A's range."""
        A = self.A
        if A.shape[0] == A.shape[1]:
            return np.linalg.solve(A, (qe - self._offset).T).T
        return np.linalg.solve(A.T @ A, A.T @ (qe - self._offset).T).T

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
        J = np.empty((q.shape[0], 3, 3))  # filled in place: a stage calls it on one state
        J[:, 0, 0], J[:, 0, 1], J[:, 0, 2] = st * cp, rho * ct * cp, -rho * st * sp_
        J[:, 1, 0], J[:, 1, 1], J[:, 1, 2] = st * sp_, rho * ct * sp_, rho * st * cp
        J[:, 2, 0], J[:, 2, 1], J[:, 2, 2] = ct, -rho * st, 0.0
        return J

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


def quat_from_matrix(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z), w ≥ 0, of rotation matrices (n, 3, 3) (Shepperd's
    method, the branch on the largest of w², x², y², z²; every branch computed over the
    batch, each row taking its own)."""
    tr = np.trace(R, axis1=1, axis2=2)
    cand = np.stack(
        [1 + tr, 1 + 2 * R[:, 0, 0] - tr, 1 + 2 * R[:, 1, 1] - tr, 1 + 2 * R[:, 2, 2] - tr], -1
    )
    k = np.argmax(cand, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):  # branches a row does not take
        s = 0.5 / np.sqrt(np.take_along_axis(cand, k[:, None], 1)[:, 0])
        quarter = 0.25 / s
    d21, d02, d10 = R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]
    s01, s02, s12 = R[:, 0, 1] + R[:, 1, 0], R[:, 0, 2] + R[:, 2, 0], R[:, 1, 2] + R[:, 2, 1]
    branches = np.stack(
        [
            np.stack([quarter, d21 * s, d02 * s, d10 * s], -1),
            np.stack([d21 * s, quarter, s01 * s, s02 * s], -1),
            np.stack([d02 * s, s01 * s, quarter, s12 * s], -1),
            np.stack([d10 * s, s02 * s, s12 * s, quarter], -1),
        ]
    )
    q = np.take_along_axis(branches, k[None, :, None], 0)[0]
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    return q


UNIT_TOLERANCE = 1e-6
"""How far a quaternion's norm may stray from 1 (engines renormalize every step; a state
written by hand with 6 digits passes)."""


def _one_quat_to_matrix(q: np.ndarray, norm: np.ndarray) -> np.ndarray:
    """:func:`quat_to_matrix` of one quaternion with Python floats: each entry is the same
    sequence of IEEE double operations as the array path (bit-identical, tested), at a
    fifth of the cost of nine tiny array expressions."""
    n = float(norm[0, 0])
    if not (math.isfinite(n) and abs(n - 1.0) <= UNIT_TOLERANCE):
        raise InvalidInput(
            "quaternion", tuple(float(x) for x in q[0]), "a unit quaternion (w, x, y, z)"
        )
    w, x, y, z = (float(c) for c in (q / norm)[0])
    return np.array([_entries(w, x, y, z)])


def _entries(w: Any, x: Any, y: Any, z: Any) -> list[list[Any]]:  # floats or arrays alike
    """The rotation matrix of (w, x, y, z), entry by entry."""
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) in (w, x, y, z) order; q and −q
    give the same rotation. A zero, non-finite or non-unit quaternion is refused."""
    if np.iscomplexobj(q):  # a complex step (derivatives of a map): first order exact, as is
        w, x, y, z = np.asarray(q).T
        return np.moveaxis(np.array(_entries(w, x, y, z)), (0, 1), (1, 2))
    q = np.asarray(q, float)
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    if q.shape[0] == 1:  # one state per integrator stage: the same IEEE operations on floats
        return _one_quat_to_matrix(q, norm)
    bad = ~np.isfinite(norm[:, 0]) | (np.abs(norm[:, 0] - 1.0) > UNIT_TOLERANCE)
    if bad.any():
        k = int(np.argmax(bad))
        raise InvalidInput(
            "quaternion", tuple(float(x) for x in q[k]), "a unit quaternion (w, x, y, z)"
        )
    q = q / norm
    w, x, y, z = q.T
    out = np.empty((q.shape[0], 3, 3))  # filled entry by entry: no stacking (a hot path)
    out[:, 0, 0] = 1 - 2 * (y * y + z * z)
    out[:, 0, 1] = 2 * (x * y - w * z)
    out[:, 0, 2] = 2 * (x * z + w * y)
    out[:, 1, 0] = 2 * (x * y + w * z)
    out[:, 1, 1] = 1 - 2 * (x * x + z * z)
    out[:, 1, 2] = 2 * (y * z - w * x)
    out[:, 2, 0] = 2 * (x * z - w * y)
    out[:, 2, 1] = 2 * (y * z + w * x)
    out[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return out


@dataclass(frozen=True)
class SphericalPendulumMap:
    """Exercise 28's angles (φ, θ) — z axis down, φ from the z axis, θ from the y axis, bob
    at ℓ(sin φ sin θ, sin φ cos θ, cos φ) in the book's axes — to a ball joint's state.

    The book's axes are the world's turned by π about x (x_b = x, y_b = −y, z_b = −z; the
    world's z is up). The orientation is R = R_z(θ + π) R_x(φ), which takes the body's
    (0, 0, −ℓ) to the bob; positions are unit quaternions (w, x, y, z) — each engine's storage
    order is applied by the comparison layer. Velocities are the body-frame angular velocity
    *without spin about the rod*, ω = Rᵀ (r̂ × ṙ̂): a point mass's spin is no degree of
    freedom of the book's, and a ball joint conserves ω·r̂, so states with ω·r̂ = 0 stay so.
    J (3×2) maps (φ̇, θ̇) to ω and the (2.2.5)-type term is Rᵀ r̂ × (∂²r̂/∂q∂q) q̇ q̇.
    """

    description: str = "ball joint: R = Rz(θ+π) Rx(φ), ω = Rᵀ(r̂ × ṙ̂) (no spin)"

    @staticmethod
    def rotation(q: np.ndarray) -> np.ndarray:
        phi, th = q.T
        a = th + np.pi
        ca, sa, cp, sp_ = np.cos(a), np.sin(a), np.cos(phi), np.sin(phi)
        z, o = np.zeros_like(phi), np.ones_like(phi)
        Rz = np.stack(
            [np.stack([ca, -sa, z], -1), np.stack([sa, ca, z], -1), np.stack([z, z, o], -1)], -2
        )
        Rx = np.stack(
            [np.stack([o, z, z], -1), np.stack([z, cp, -sp_], -1), np.stack([z, sp_, cp], -1)], -2
        )
        return Rz @ Rx

    @staticmethod
    def _rhat(q: np.ndarray) -> tuple[np.ndarray, ...]:
        """r̂ (world) and its first and second partial derivatives in (φ, θ)."""
        phi, th = q.T
        sp_, cp, st, ct = np.sin(phi), np.cos(phi), np.sin(th), np.cos(th)
        z = np.zeros_like(phi)
        r = np.stack([sp_ * st, -sp_ * ct, -cp], -1)
        r_p = np.stack([cp * st, -cp * ct, sp_], -1)
        r_t = np.stack([sp_ * ct, sp_ * st, z], -1)
        r_pt = np.stack([cp * ct, cp * st, z], -1)
        r_tt = np.stack([-sp_ * st, sp_ * ct, z], -1)
        return r, r_p, r_t, -r, r_pt, r_tt

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return quat_from_matrix(self.rotation(q))

    def to_book(self, qe: np.ndarray) -> np.ndarray:
        """(φ, θ) of the bob's direction r̂ = R (0, 0, −1), whatever the spin."""
        r = -quat_to_matrix(qe)[:, :, 2]
        return np.column_stack([np.arccos(np.clip(-r[:, 2], -1, 1)), np.arctan2(r[:, 0], -r[:, 1])])

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        r, r_p, r_t, *_ = self._rhat(q)
        Jw = np.stack([np.cross(r, r_p), np.cross(r, r_t)], -1)
        return np.swapaxes(self.rotation(q), 1, 2) @ Jw

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        r, _, _, r_pp, r_pt, r_tt = self._rhat(q)
        pd, td = v[:, :1], v[:, 1:]
        second = r_pp * pd**2 + 2 * r_pt * pd * td + r_tt * td**2
        Hw = np.cross(r, second)
        return np.einsum("nji,nj->ni", self.rotation(q), Hw)


@dataclass(frozen=True)
class EulerAngleMap:
    """Example 9's Euler angles (φ, θ, ψ) to a ball joint's state: the orientation is the
    direction-cosine matrix ℓ = Aᵀ of (2.2.50) (x = ℓ x̄ takes body components to space
    components, as an engine's body rotation does), A = R₃(ψ) R₁(θ) R₃(φ) the product of
    Example 9's rotations of axes; positions are unit quaternions (w, x, y, z). Velocities are
    the body-frame angular velocity of exercise 23, ω̄ = J(q) q̇ with

        J = [[sin θ sin ψ, cos ψ, 0], [sin θ cos ψ, −sin ψ, 0], [cos θ, 0, 1]],

    and the (2.2.5)-type term J̇ q̇. Singular at θ = 0, π (gimbal lock), where φ and ψ merge.
    """

    description: str = "ball joint: R = ℓ(φ, θ, ψ) of Example 9, ω̄ of exercise 23 (body frame)"

    @staticmethod
    def rotation(q: np.ndarray) -> np.ndarray:
        """ℓ(q) = (R₃(ψ) R₁(θ) R₃(φ))ᵀ, batched (n, 3, 3)."""

        def r3(a: np.ndarray) -> np.ndarray:
            c, s, z, o = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
            return np.stack(
                [np.stack([c, s, z], -1), np.stack([-s, c, z], -1), np.stack([z, z, o], -1)], -2
            )

        def r1(a: np.ndarray) -> np.ndarray:
            c, s, z, o = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
            return np.stack(
                [np.stack([o, z, z], -1), np.stack([z, c, s], -1), np.stack([z, -s, c], -1)], -2
            )

        phi, theta, psi = q.T
        return np.swapaxes(r3(psi) @ r1(theta) @ r3(phi), -1, -2)

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return quat_from_matrix(self.rotation(q))

    def to_book(self, qe: np.ndarray) -> np.ndarray:
        """θ = arccos A₃₃, φ = atan2(A₃₁, −A₃₂), ψ = atan2(A₁₃, A₂₃) with A = ℓᵀ."""
        A = np.swapaxes(quat_to_matrix(qe), -1, -2)
        return np.column_stack(
            [
                np.arctan2(A[:, 2, 0], -A[:, 2, 1]),
                np.arccos(np.clip(A[:, 2, 2], -1.0, 1.0)),
                np.arctan2(A[:, 0, 2], A[:, 1, 2]),
            ]
        )

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        _, th, ps = q.T
        st, ct, sp_, cp = np.sin(th), np.cos(th), np.sin(ps), np.cos(ps)
        z, o = np.zeros_like(th), np.ones_like(th)
        return np.stack(
            [
                np.stack([st * sp_, cp, z], -1),
                np.stack([st * cp, -sp_, z], -1),
                np.stack([ct, z, o], -1),
            ],
            -2,
        )

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """J̇ q̇: the time derivative of exercise 23's ω̄ at q̈ = 0."""
        _, th, ps = q.T
        dphi, dth, dps = v.T
        st, ct, sp_, cp = np.sin(th), np.cos(th), np.sin(ps), np.cos(ps)
        return np.column_stack(
            [
                dphi * (ct * dth * sp_ + st * cp * dps) - sp_ * dps * dth,
                dphi * (ct * dth * cp - st * sp_ * dps) - cp * dps * dth,
                -st * dth * dphi,
            ]
        )


@dataclass(frozen=True)
class FreeBodyMap:
    """A free body's book coordinates (x₁, x₂, x₃, φ, θ, ψ) — the centre of mass in space axes
    and Example 9's angles — to a free joint's canonical state: position, then the unit
    quaternion of ℓ (:class:`EulerAngleMap`); velocity (ẋ in space axes, ω̄ of exercise 23)."""

    description: str = "free joint: position, R = ℓ(φ, θ, ψ); velocity (ẋ world, ω̄ body)"

    def to_engine(self, q: np.ndarray) -> np.ndarray:
        return np.column_stack([q[:, :3], EulerAngleMap().to_engine(q[:, 3:])])

    def to_book(self, qe: np.ndarray) -> np.ndarray:
        return np.column_stack([qe[:, :3], EulerAngleMap().to_book(qe[:, 3:])])

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        J = np.zeros((q.shape[0], 6, 6))
        J[:, :3, :3] = np.eye(3)
        J[:, 3:, 3:] = EulerAngleMap().jacobian(q[:, 3:])
        return J

    def hessian_term(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.column_stack(
            [np.zeros((q.shape[0], 3)), EulerAngleMap().hessian_term(q[:, 3:], v[:, 3:])]
        )
