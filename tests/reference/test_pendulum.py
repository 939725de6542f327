"""The reference against closed forms and independent derivations (Examples 7 and 8)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.special import ellipj, ellipk

from dyncheck.reference import pendulum as P
from dyncheck.reference.trajectory import solve

EPS = np.finfo(float).eps
SIMPLE = {"m": 1.3, "l": 0.9, "g": 9.81}
COMPOUND = {"m1": 1.2, "m2": 0.8, "L1": 1.1, "L2": 0.7, "g": 9.81}


@pytest.fixture
def states():
    rng = np.random.default_rng(7)
    return rng.uniform(-3, 3, (50, 2)), rng.uniform(-4, 4, (50, 2)), rng.uniform(-5, 5, (50, 2))


def test_simple_pendulum_closed_form_acceleration(states):
    """Example 7: θ̈ = −(g/ℓ) sin θ (printed), from the general method."""
    q, v, _ = states
    dyn = P.simple_pendulum(**SIMPLE)
    acc = dyn.forward(q[:, :1], v[:, :1], np.zeros((50, 1)))
    assert_allclose(
        acc[:, 0],
        -SIMPLE["g"] / SIMPLE["l"] * np.sin(q[:, 0]),
        rtol=0,
        atol=64 * EPS * SIMPLE["g"] / SIMPLE["l"],
    )


def test_simple_pendulum_matches_elliptic_closed_form():
    """Released from rest at θ₀: θ(t) = 2 arcsin(k sn(K(m) − ω t | m)), k = sin(θ₀/2), m = k²
    (the classic exact solution, independent of the book's text)."""
    theta0 = 2.0
    dyn = P.simple_pendulum(**SIMPLE)
    t = np.linspace(0, 3, 61)
    q, _ = solve(dyn, np.array([theta0]), np.array([0.0]), t)
    k = np.sin(theta0 / 2)
    w = np.sqrt(SIMPLE["g"] / SIMPLE["l"])
    sn, *_ = ellipj(ellipk(k**2) - w * t, k**2)
    assert_allclose(q[:, 0], 2 * np.arcsin(k * sn), rtol=0, atol=1e-10)


def test_compound_mass_matrix_from_printed_kinetic_energy(states):
    """M = ∂²T/∂θ̇∂θ̇ of (2.2.29), written out by hand here."""
    q, _, _ = states
    m1, m2, L1, L2 = (COMPOUND[k] for k in ("m1", "m2", "L1", "L2"))
    c = np.cos(q[:, 0] - q[:, 1])
    expected = np.stack(
        [
            np.stack([np.full(50, (m1 + m2) * L1**2), m2 * L1 * L2 * c], -1),
            np.stack([m2 * L1 * L2 * c, np.full(50, m2 * L2**2)], -1),
        ],
        -2,
    )
    assert_allclose(
        P.compound_pendulum(**COMPOUND).mass_matrix(q),
        expected,
        rtol=0,
        atol=64 * EPS * (m1 + m2) * L1**2,
    )


@pytest.mark.parametrize(
    "quantity", ["mass_matrix", "bias", "inverse", "forward", "kinetic_energy", "potential_energy"]
)
@pytest.mark.parametrize("system", ["simple", "compound"])
def test_printed_equals_general_method(states, system, quantity):
    """The book's printed equations against the general method (no erratum expected in
    Examples 7, 8); potential energies agree up to the datum constant."""
    q, v, a = states
    if system == "simple":
        q, v, a = q[:, :1], v[:, :1], a[:, :1]
        printed, general = P.simple_pendulum_printed(**SIMPLE), P.simple_pendulum(**SIMPLE)
    else:
        printed, general = P.compound_pendulum_printed(**COMPOUND), P.compound_pendulum(**COMPOUND)
    args = {
        "mass_matrix": (q,),
        "bias": (q, v),
        "inverse": (q, v, a),
        "forward": (q, v, a),
        "kinetic_energy": (q, v),
        "potential_energy": (q,),
    }[quantity]
    got, want = getattr(printed, quantity)(*args), getattr(general, quantity)(*args)
    if quantity == "potential_energy":
        got, want = got - got[0], want - want[0]
    assert_allclose(
        got,
        want,
        rtol=0,
        atol=64 * EPS * np.abs(want).max() * 4,
        err_msg=f"{system} {quantity}: printed vs general method",
    )


def test_energy_is_conserved_along_reference_trajectory():
    """Exercise 19: T + V is a constant of the motion of a conservative system."""
    dyn = P.compound_pendulum(**COMPOUND)
    t = np.linspace(0, 5, 101)
    q, v = solve(dyn, np.array([1.0, -0.5]), np.array([0.2, 1.0]), t)
    e = dyn.kinetic_energy(q, v) + dyn.potential_energy(q)
    assert np.ptp(e) < 1e-10 * np.abs(e).max()


def test_rotational_inertia_variant_adds_diagonal_exactly(states):
    """½ I θ̇² per body (absolute angles) adds I to the diagonal of M only."""
    q, _, _ = states
    base = P.compound_pendulum(**COMPOUND).mass_matrix(q)
    with_inertia = P.compound_pendulum(**COMPOUND, inertia=(0.25, 0.5)).mass_matrix(q)
    assert_allclose(
        with_inertia - base, np.broadcast_to(np.diag([0.25, 0.5]), base.shape), rtol=0, atol=1e-14
    )


SPH = {"m": 1.3, "l": 1.1, "g": 9.81}


def test_spherical_pendulum_printed_equals_general(states):
    """Exercise 28 as printed (both equations ÷ mℓ²) against Lagrange's equations from the
    bob's position; φ kept off the pole."""
    q, v, a = states
    q = np.column_stack([0.3 + np.abs(q[:, 0]) % 2.5, q[:, 1]])
    printed, general = P.spherical_pendulum_printed(**SPH), P.spherical_pendulum(**SPH)
    for name, args in (
        ("mass_matrix", (q,)),
        ("bias", (q, v)),
        ("inverse", (q, v, a)),
        ("kinetic_energy", (q, v)),
    ):
        got, want = getattr(printed, name)(*args), getattr(general, name)(*args)
        assert_allclose(got, want, rtol=0, atol=256 * EPS * np.abs(want).max(), err_msg=name)


def test_spherical_pendulum_conserved_quantities():
    """sin²φ θ̇ (the first printed equation) and T + V are constants of the motion."""
    dyn = P.spherical_pendulum(**SPH)
    t = np.linspace(0, 4, 201)
    q, v = solve(dyn, np.array([0.8, 0.3]), np.array([0.2, 1.5]), t)
    h = np.sin(q[:, 0]) ** 2 * v[:, 1]
    assert np.ptp(h) < 1e-11 * abs(h[0])
    e = dyn.kinetic_energy(q, v) + dyn.potential_energy(q)
    assert np.ptp(e) < 1e-11 * np.abs(e).max()


def test_steady_conical_motion():
    """φ̈ = 0 in the second printed equation: θ̇² = g/(ℓ cos φ₀) keeps φ = φ₀, θ = θ̇ t."""
    phi0 = 0.6
    w = np.sqrt(SPH["g"] / (SPH["l"] * np.cos(phi0)))
    t = np.linspace(0, 3, 61)
    q, _ = solve(P.spherical_pendulum(**SPH), np.array([phi0, 0.0]), np.array([0.0, w]), t)
    assert_allclose(q[:, 0], phi0, atol=1e-10)
    assert_allclose(q[:, 1], w * t, atol=1e-9)
