"""The transformation laws, on a linear map (the pendulums') and a non-linear one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.testing import assert_allclose

from dyncheck import coordinates as co
from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import LinearMap, SphericalToCartesian

from ..conftest import CASE_NAMES


def test_maps_round_trip():
    rng = np.random.default_rng(1)
    for name in CASE_NAMES:
        case = get_case(name)
        cmap = case.engine_map()
        low, high = case.q_bounds()
        q = rng.uniform(low, high, (10, case.ndof))
        assert_allclose(cmap.to_book(cmap.to_engine(q)), q, rtol=0, atol=1e-14)


def test_spherical_map_derivatives():
    """SphericalToCartesian against the reference's exact Jacobian, and its (2.2.5) term
    against the flat-space identity ∂ₘ∂ₙx = {i; m n} ∂ᵢx."""
    from dyncheck.reference.coordinates import spherical

    rng = np.random.default_rng(3)
    q = np.column_stack([rng.uniform(0.5, 2, 9), rng.uniform(0.3, 2.8, 9), rng.uniform(-3, 3, 9)])
    v = rng.uniform(-1, 1, (9, 3))
    cmap = SphericalToCartesian()
    J = spherical().numeric.jacobian(q)
    assert_allclose(cmap.jacobian(q), J, rtol=1e-14, atol=1e-15)
    expected = np.einsum("nki,nimj,nm,nj->nk", J, spherical().numeric.christoffel(q), v, v)
    assert_allclose(cmap.hessian_term(q, v), expected, rtol=1e-12, atol=1e-13)


@dataclass(frozen=True)
class PolarToCartesian:
    """x̄ = (r cos φ, r sin φ): a non-linear map whose (2.2.5) term is the centripetal one."""

    def to_engine(self, q):
        return np.column_stack([q[:, 0] * np.cos(q[:, 1]), q[:, 0] * np.sin(q[:, 1])])

    def to_book(self, qe):
        return np.column_stack([np.hypot(qe[:, 0], qe[:, 1]), np.arctan2(qe[:, 1], qe[:, 0])])

    def jacobian(self, q):
        r, p = q[:, 0], q[:, 1]
        return np.stack(
            [np.stack([np.cos(p), -r * np.sin(p)], -1), np.stack([np.sin(p), r * np.cos(p)], -1)],
            -2,
        )

    def hessian_term(self, q, v):
        r, p, rd, pd = q[:, 0], q[:, 1], v[:, 0], v[:, 1]
        return np.column_stack(
            [
                -2 * rd * pd * np.sin(p) - r * pd**2 * np.cos(p),
                2 * rd * pd * np.cos(p) - r * pd**2 * np.sin(p),
            ]
        )


def test_nonlinear_map_pulls_back_a_free_particle():
    """A free particle of mass m in Cartesian coordinates (M̄ = m I, h̄ = 0) pulled back to
    polar coordinates must give Example 5's planar equations: M = diag(m, m r²),
    h = (−m r φ̇², 2 m r ṙ φ̇)."""
    m, cmap = 2.0, PolarToCartesian()
    rng = np.random.default_rng(2)
    q = np.column_stack([rng.uniform(0.5, 2, 8), rng.uniform(-3, 3, 8)])
    v = rng.uniform(-2, 2, (8, 2))
    Me = np.broadcast_to(m * np.eye(2), (8, 2, 2))
    M = co.mass_matrix_to_book(cmap, q, Me)
    h = co.bias_to_book(cmap, q, v, Me, np.zeros((8, 2)))
    assert_allclose(M[:, 0, 0], m)
    assert_allclose(M[:, 1, 1], m * q[:, 0] ** 2)
    assert_allclose(M[:, 0, 1], 0, atol=1e-15)
    assert_allclose(h[:, 0], -m * q[:, 0] * v[:, 1] ** 2, rtol=1e-13)
    assert_allclose(h[:, 1], 2 * m * q[:, 0] * v[:, 0] * v[:, 1], rtol=1e-13)
    a = rng.uniform(-1, 1, (8, 2))
    assert_allclose(
        co.acceleration_to_book(cmap, q, v, co.acceleration_to_engine(cmap, q, v, a)), a, rtol=1e-12
    )


def test_forces_are_covariant_velocities_contravariant():
    """Power τ·v is invariant under the map (2.2.4), (2.2.19)."""
    cmap = LinearMap(((-1.0, 0.0), (1.0, -1.0)), (0.0, 0.0), "test")
    rng = np.random.default_rng(4)
    q, v, tau = (rng.uniform(-2, 2, (5, 2)) for _ in range(3))
    ve = co.velocity_to_engine(cmap, q, v)
    tau_e = co.force_to_engine(cmap, q, tau)
    assert_allclose(np.sum(tau * v, 1), np.sum(tau_e * ve, 1), rtol=1e-14)
