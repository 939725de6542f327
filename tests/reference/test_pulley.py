"""The reference's pulley systems against closed forms and independent derivations
(Example 6, exercise 17) and MuJoCo's documented soft-constraint model at its limits."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.reference import pulley as P
from dyncheck.reference.constraints import CordSystem, Softness

EPS = np.finfo(float).eps
ATWOOD = {"m1": 1.1, "m2": 0.9, "a": 0.1, "l": 3.0, "g": 9.81}
COMPOUND = {"m1": 2.0, "m2": 0.7, "m3": 1.1, "a": 0.1, "l1": 3.0, "l2": 2.5, "g": 9.81}
SOFT = Softness(0.02, 1.0, 0.9, 0.95, 0.001, 0.5, 2.0)


@pytest.fixture
def states():
    rng = np.random.default_rng(3)
    return rng.uniform(0.3, 1.0, (40, 2)), rng.uniform(-2, 2, (40, 2)), rng.uniform(-9, 9, (40, 2))


def _atwood(**kw):
    return P.atwood(**ATWOOD, rest=1.5, **kw)


def _compound(**kw):
    return P.compound_pulley(**COMPOUND, rest=(1.2, 1.0), **kw)


def test_atwood_acceleration_and_tension_closed_form(states):
    """Example 6: ÿ₁ = (m₁ − m₂) g/(m₁ + m₂); Newton on m₁ alone (m₁ÿ₁ = m₁g − T) gives the
    tension T = 2 m₁ m₂ g/(m₁ + m₂) — a derivation the book does not print."""
    q, v, _ = states
    m1, m2, g = ATWOOD["m1"], ATWOOD["m2"], ATWOOD["g"]
    dyn = _atwood()
    zero = np.zeros((40, 1))
    assert_allclose(dyn.forward(q[:, :1], v[:, :1], zero), (m1 - m2) * g / (m1 + m2), rtol=1e-14)
    assert_allclose(
        dyn.constraint_force(q[:, :1], v[:, :1], zero), 2 * m1 * m2 * g / (m1 + m2), rtol=1e-14
    )


def test_atwood_printed_equals_general_method(states):
    q, v, tau = states
    book, ref = P.atwood_printed(ATWOOD["m1"], ATWOOD["m2"], ATWOOD["g"]), _atwood()
    args = q[:, :1], v[:, :1], tau[:, :1]
    assert_allclose(book.forward(*args), ref.forward(*args), rtol=1e-14)
    assert_allclose(book.mass_matrix(q[:, :1]), ref.mass_matrix(q[:, :1]), rtol=1e-14)


def test_compound_pulley_newton_derivation(states):
    """Exercise 17 by Newton's second law on each mass and the massless movable pulley
    (T₁ = 2T₂) with the cords' kinematics 2Z̈₁ + Z̈₂ + Z̈₃ = 0 — a linear solve in the test,
    independent of both Lagrange's method and the reference's KKT."""
    m1, m2, m3, g = (COMPOUND[k] for k in ("m1", "m2", "m3", "g"))
    # unknowns Z̈₁, Z̈₂, Z̈₃, T₂ (depths down): mᵢZ̈ᵢ = mᵢg − Tᵢ, T₁ = 2T₂
    K = np.array([[m1, 0, 0, 2], [0, m2, 0, 1], [0, 0, m3, 1], [2, 1, 1, 0]], float)
    z1, z2, z3, T2 = np.linalg.solve(K, [m1 * g, m2 * g, m3 * g, 0])
    # book coordinates: y₁ = Z₁, y₂ = Z₂ − y_P with y_P = const − Z₁
    expected = np.array([z1, z2 + z1])
    q, v, _ = states
    dyn = _compound()
    zero = np.zeros_like(q)
    assert_allclose(dyn.forward(q, v, zero), np.broadcast_to(expected, q.shape), rtol=1e-13)
    assert_allclose(dyn.constraint_force(q, v, zero)[:, 0], T2, rtol=1e-13)
    assert np.isclose(z3, -2 * z1 - z2)


def test_compound_pulley_printed_equals_general_method(states):
    q, v, tau = states
    book = P.compound_pulley_printed(*(COMPOUND[k] for k in ("m1", "m2", "m3", "g")))
    ref = _compound()
    assert_allclose(book.mass_matrix(q), ref.mass_matrix(q), rtol=1e-14)
    assert_allclose(book.forward(q, v, tau), ref.forward(q, v, tau), rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("build", [_atwood, _compound])
def test_kkt_equals_lagrange_in_independent_coordinates(build, states):
    """The cords' KKT solve on the free masses (with the least-norm spread of τ) and
    Lagrange's equations in the book's coordinates give the same ẍ: two derivations."""
    q, v, tau = states
    dyn = build()
    n = dyn.lagrange.ndof
    q, v, tau = q[:, :n], v[:, :n], tau[:, :n]
    assert_allclose(dyn.cords.acceleration(q, v, tau), dyn.lagrange.forward(q, v, tau), atol=1e-13)


@pytest.mark.parametrize("build", [_atwood, _compound])
def test_soft_model_at_zero_violation(build, states):
    """On the cords (r = ṙ = 0) the soft model gives ẍ = ẍ_exact + (1 − d)(a₀ − ẍ_exact) and
    tension d·T_exact, d = dmin (MuJoCo's documented impedance model)."""
    q, v, tau = states
    exact, soft = build(), build(softness=SOFT)
    n = exact.lagrange.ndof
    q, v, tau = q[:, :n], v[:, :n], tau[:, :n]
    c = exact.cords
    a0 = c.to_book(c.free_acceleration(c.force_to_free(tau)))
    a_exact = exact.forward(q, v, tau)
    d = SOFT.dmin
    assert_allclose(soft.forward(q, v, tau), a_exact + (1 - d) * (a0 - a_exact), atol=1e-13)
    assert_allclose(
        soft.constraint_force(q, v, tau), d * exact.constraint_force(q, v, tau), rtol=1e-13
    )


def test_impedance_shape():
    """d(0) = dmin, d(mid·width) = dmin + mid (dmax − dmin), d(≥ width) = dmax; clamped."""
    s = SOFT
    d = s.impedance(np.array([0.0, s.mid * s.width, -s.width, 5 * s.width]))
    assert_allclose(d, [s.dmin, s.dmin + s.mid * (s.dmax - s.dmin), s.dmax, s.dmax])
    assert Softness(0.02, 1, 1.0, 1.0, 0.001, 0.5, 2).impedance(np.zeros(1))[0] == 0.9999


def test_soft_cord_stretch_settles_where_spring_balances_excess():
    """Released on the cord at rest, the Atwood cord stretches until the spring balances the
    excess: C s̈ = (1 − d) C a₀ + d a_ref with a_ref = −b ṙ − k d r, so at rest
    (r̈ = ṙ = 0) with a constant impedance (dmin = dmax) r = (1 − d) C a₀ /(d² k)."""
    soft = Softness(0.02, 1.0, 0.95, 0.95, 0.001, 0.5, 2.0)
    dyn = _atwood(softness=soft)
    _, r = dyn.free_trajectory(np.array([[1.5]]), np.zeros((1, 1)), np.linspace(0, 1, 11), 1e-12)
    d, ca0 = 0.95, 2 * ATWOOD["g"]
    assert_allclose(r[-1, 0], (1 - d) * ca0 / (d**2 * soft.stiffness), rtol=1e-6)


def test_cords_must_hold_the_book_coordinates():
    with pytest.raises(ValueError, match="C A"):
        CordSystem(np.ones(2), 9.81, np.array([[1.0, 1.0]]), np.array([[1.0], [1.0]]), np.zeros(2))
