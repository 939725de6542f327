"""Constrained forward dynamics two ways (:mod:`dyncheck.reference.constrained`, #78): each
against a closed form derived in its test, and the two ways against each other."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.reference.constrained import inconsistent, multipliers, reduced, soft

WAYS = [reduced, multipliers]
G = 9.81


@pytest.mark.parametrize("way", WAYS)
def test_the_atwood_machine_is_the_books_cord(way):
    """Example 6's cord y₁ + y₂ = ℓ (y down, M = diag(m₁, m₂), h = −m g): by hand,
    ÿ₁ = (m₁ − m₂) g / (m₁ + m₂) = −ÿ₂ and the cord's tension T = 2 m₁ m₂ g / (m₁ + m₂),
    the constraint force −T on each mass."""
    m1, m2 = 3.0, 1.0
    M, h = np.diag([m1, m2]), -G * np.array([m1, m2])
    found = way(M, h, np.zeros(2), J=np.array([[1.0, 1.0]]), jdot_v=np.zeros(1))
    expected = (m1 - m2) * G / (m1 + m2)
    np.testing.assert_allclose(found.vdot, [expected, -expected], rtol=1e-14)
    tension = 2 * m1 * m2 * G / (m1 + m2)
    np.testing.assert_allclose(found.force, [-tension, -tension], rtol=1e-14)
    assert found.rank == 1


def _pendulum(theta: float, omega: float, *, l: float = 0.7, m: float = 1.3):
    """A point mass at (x, y) = l (sin θ, −cos θ) held by C = x² + y² − l² = 0: J = 2 (x, y),
    J̇ v = 2 (ẋ² + ẏ²); M = m I, h = (0, m g)."""
    x, y = l * np.sin(theta), -l * np.cos(theta)
    xd, yd = l * omega * np.cos(theta), l * omega * np.sin(theta)
    return (m * np.eye(2), np.array([0.0, m * G]), np.array([[2 * x, 2 * y]]),
            np.array([2 * (xd**2 + yd**2)]), (l, m, x, y))


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize(("theta", "omega"), [(0.4, 0.0), (-1.2, 2.5), (2.9, -1.1)])
def test_a_point_mass_held_at_a_distance_is_the_pendulum(way, theta, omega):
    """By hand: θ̈ = −(g/l) sin θ, and the rod's tension m (g cos θ + l θ̇²) pulling the mass
    toward the pivot."""
    M, h, J, jdot_v, (l, m, x, y) = _pendulum(theta, omega)
    found = way(M, h, np.zeros(2), J=J, jdot_v=jdot_v)
    alpha = -G / l * np.sin(theta)
    expected = np.array([l * (alpha * np.cos(theta) - omega**2 * np.sin(theta)),
                         l * (alpha * np.sin(theta) + omega**2 * np.cos(theta))])
    np.testing.assert_allclose(found.vdot, expected, atol=1e-13)
    tension = m * (G * np.cos(theta) + l * omega**2)
    np.testing.assert_allclose(found.force, -tension * np.array([x, y]) / l, atol=1e-12)


@pytest.mark.parametrize("way", WAYS)
def test_a_redundant_row_changes_nothing(way):
    """The pendulum's constraint written twice (the second row twice the first): rank 1, the
    same motion and the same constraint force."""
    M, h, J, jdot_v, _ = _pendulum(0.8, 1.5)
    once = way(M, h, np.zeros(2), J=J, jdot_v=jdot_v)
    twice = way(M, h, np.zeros(2), J=np.vstack([J, 2 * J]),
                jdot_v=np.concatenate([jdot_v, 2 * jdot_v]))
    assert twice.rank == 1
    np.testing.assert_allclose(twice.vdot, once.vdot, atol=1e-13)
    np.testing.assert_allclose(twice.force, once.force, atol=1e-12)


def test_contradicting_rows_are_named():
    """Two rows on the same coordinate asking for different accelerations (ẍ = 0, ẍ = −1):
    both named; the same rows asking the same are consistent."""
    J = np.array([[1.0, 0.0], [1.0, 0.0]])
    assert inconsistent(J, np.array([0.0, 1.0]), atol=1e-12) == [0, 1]
    assert inconsistent(J, np.array([1.0, 1.0]), atol=1e-12) == []


@pytest.mark.parametrize("seed", range(5))
def test_the_two_ways_agree_on_any_tree(seed):
    """Any symmetric positive definite M and any J of full row rank: the independent
    coordinates and the multipliers give the same v̇ and Jᵀ λ, to round-off scaled by M's
    condition number; the answer keeps the constraints (J v̇ = −J̇ v)."""
    rng = np.random.default_rng(seed)
    n, k = 7, 3
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    h, tau, jdot_v = rng.normal(size=n), rng.normal(size=n), rng.normal(size=k)
    J = rng.normal(size=(k, n))
    a = reduced(M, h, tau, J=J, jdot_v=jdot_v)
    b = multipliers(M, h, tau, J=J, jdot_v=jdot_v)
    bound = 64 * np.finfo(float).eps * np.linalg.cond(M) * max(1.0, np.abs(a.vdot).max())
    np.testing.assert_allclose(a.vdot, b.vdot, atol=bound)
    np.testing.assert_allclose(a.force, b.force, atol=bound * np.abs(M).max())
    assert a.residual < bound and b.residual < bound
    assert a.rank == b.rank == k


def test_the_soft_model_is_the_rigid_one_as_r_vanishes_and_mixes_with_the_free_one():
    """The Atwood machine at rest (J̇ v = 0, a_ref = 0): by hand, with A = 1/m₁ + 1/m₂ and
    R = (1 − d)/d · A (MuJoCo's regularizer at impedance d), f = −d (J a₀)/A, so
    v̇ = a_rigid + (1 − d)(a₀ − a_rigid), a₀ = (g, g) the free fall; d = 1 is the rigid."""
    m1, m2 = 3.0, 1.0
    M, h, J = np.diag([m1, m2]), -G * np.array([m1, m2]), np.array([[1.0, 1.0]])
    rigid = multipliers(M, h, np.zeros(2), J=J, jdot_v=np.zeros(1)).vdot
    a = 1 / m1 + 1 / m2
    for d in (0.9, 0.99, 1.0):
        found = soft(M, h, np.zeros(2), J=J, a_ref=np.zeros(1),
                     regularizer=np.array([(1 - d) / d * a]))
        np.testing.assert_allclose(found.vdot, rigid + (1 - d) * (np.full(2, G) - rigid),
                                   atol=1e-13)
