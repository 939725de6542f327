"""A particle in generalized coordinates: kinematics, Lagrange's form, Example 5, Hamilton,
geodesics and the action's line element, each against an independent answer."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.reference import particle as P
from dyncheck.reference.coordinates import cartesian, cylindrical, spherical
from dyncheck.reference.trajectory import solve

M, G = 1.5, 9.81


def _spherical_states(n=20, seed=0):
    rng = np.random.default_rng(seed)
    q = np.column_stack([rng.uniform(0.5, 2, n), rng.uniform(0.3, 2.8, n), rng.uniform(-3, 3, n)])
    return q, rng.uniform(-1, 1, (n, 3)), rng.uniform(-1, 1, (n, 3))


def _to_cartesian_motion(q, v, a):
    """Position, velocity, acceleration of the spherical point, by hand (chain rule)."""
    rho, th, ph = q.T
    x = np.column_stack(
        [rho * np.sin(th) * np.cos(ph), rho * np.sin(th) * np.sin(ph), rho * np.cos(th)]
    )
    J = spherical().numeric.jacobian(q)
    xd = np.einsum("nkj,nj->nk", J, v)
    h = 1e-6  # ẍ = J a + (dJ/dt) v, dJ/dt by a central difference along v
    Jd = (spherical().numeric.jacobian(q + h * v) - spherical().numeric.jacobian(q - h * v)) / (
        2 * h
    )
    xdd = np.einsum("nkj,nj->nk", J, a) + np.einsum("nkj,nj->nk", Jd, v)
    return x, xd, xdd


def test_acceleration_is_intrinsic_derivative():
    """(2.2.5): the Cartesian acceleration equals J f with fⁱ = ẍⁱ + {i; mn} ẋᵐẋⁿ."""
    q, v, a = _spherical_states()
    _, _, xdd = _to_cartesian_motion(q, v, a)
    f = P.acceleration(spherical(), q, v, a)
    assert_allclose(np.einsum("nkj,nj->nk", spherical().numeric.jacobian(q), f), xdd, atol=1e-8)


def test_speed_is_invariant_and_velocity_transforms():
    """(2.2.4): velocities between spherical and cylindrical coordinates; v² the same."""
    q, v, _ = _spherical_states()
    rho, th, ph = q.T
    q_cyl = np.column_stack([rho * np.sin(th), ph, rho * np.cos(th)])
    v_cyl = P.transform_velocity(spherical(), cylindrical(), q, q_cyl, v)
    assert_allclose(
        P.speed_squared(cylindrical(), q_cyl, v_cyl), P.speed_squared(spherical(), q, v), rtol=1e-13
    )
    # by hand: r = ρ sin θ, ṙ = ρ̇ sin θ + ρ cos θ θ̇; θ_cyl = φ; ż = ρ̇ cos θ − ρ sin θ θ̇
    assert_allclose(v_cyl[:, 0], v[:, 0] * np.sin(th) + rho * np.cos(th) * v[:, 1], rtol=1e-12)
    assert_allclose(v_cyl[:, 1], v[:, 2], rtol=1e-12, atol=1e-15)
    assert_allclose(
        v_cyl[:, 2], v[:, 0] * np.cos(th) - rho * np.sin(th) * v[:, 1], rtol=1e-12, atol=1e-14
    )


def test_physical_components_exercise_7():
    """Physical velocity components in spherical coordinates: (ρ̇, ρθ̇, ρ sin θ φ̇)."""
    q, v, _ = _spherical_states()
    phys = P.physical_components(spherical(), q, v)
    assert_allclose(
        phys,
        np.column_stack([v[:, 0], q[:, 0] * v[:, 1], q[:, 0] * np.sin(q[:, 1]) * v[:, 2]]),
        rtol=1e-14,
    )


def test_example5_physical_components():
    q, v, a = _spherical_states()
    Q = P.example5_printed(M, 0.0).inverse(q, v, a)
    phys = P.example5_physical(q, Q)
    f_phys = P.physical_components(spherical(), q, P.acceleration(spherical(), q, v, a))
    assert_allclose(phys, M * f_phys, rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("cs", [spherical(), cylindrical()], ids=lambda c: c.name)
def test_lagrange_form_equals_general_method(cs):
    """(2.2.23) via metric and Christoffel symbols vs Lagrange's equations from T and V."""
    q, v, a = _spherical_states()
    if cs.name == "cylindrical":
        q = q[:, [0, 2, 1]]
    lf, gm = P.lagrange_form(cs, M, G), P.particle(cs, M, G)
    assert_allclose(lf.inverse(q, v, a), gm.inverse(q, v, a), rtol=1e-13, atol=1e-12)
    assert_allclose(lf.mass_matrix(q), gm.mass_matrix(q), rtol=1e-14, atol=1e-14)


def test_free_fall_in_spherical_coordinates_is_a_parabola():
    """The closed form x(t) = x₀ + v₀t − ½gt² e_z, reached through the spherical equations."""
    dyn = P.particle(spherical(), M, G)
    q0, v0 = np.array([1.2, 1.2, 0.4]), np.array([0.3, -0.2, 0.5])
    t = np.linspace(0, 1, 21)
    q, _ = solve(dyn, q0, v0, t)
    x0, xd0, _ = _to_cartesian_motion(q0[None], v0[None], np.zeros((1, 3)))
    expected = x0 + np.outer(t, xd0[0]) - 0.5 * G * np.outer(t**2, [0, 0, 1])
    assert_allclose(spherical().numeric.position(q), expected, atol=1e-10)


def test_hamilton_equals_lagrange():
    """Exercises 20, 22: Hamilton's equations from H = g^ij p_i p_j/2M + V, with the
    Legendre map p = M g ẋ, trace the same trajectory as Lagrange's equations."""
    cs = spherical()
    q0, v0 = np.array([1.2, 1.2, 0.4]), np.array([0.3, -0.2, 0.5])
    t = np.linspace(0, 0.8, 17)
    q_l, v_l = solve(P.particle(cs, M, G), q0, v0, t)
    q_h, p_h = P.solve_hamilton(cs, M, G, q0, P.momentum(cs, M, q0[None], v0[None])[0], t)
    assert_allclose(q_h, q_l, atol=1e-10)
    assert_allclose(p_h, P.momentum(cs, M, q_l, v_l), atol=1e-9)


def test_geodesic_on_cylinder_exercise_18e():
    """Surface coordinates (θ, z) of a cylinder of radius a: the geodesic from (0, 0) to
    (π, H) has length √(a²π² + H²). The surface's metric diag(a², 1) has zero Christoffel
    symbols, so the geodesic is θ = πs/L, z = Hs/L; check it solves exercise 18(c) and its
    length by (2.2.35)."""
    a, H = 0.7, 2.0
    L = np.sqrt(a**2 * np.pi**2 + H**2)

    def metric(x):
        return np.broadcast_to(np.diag([a**2, 1.0]), (len(x), 2, 2))

    def christoffel(x):
        return np.zeros((len(x), 2, 2, 2))

    from scipy.integrate import solve_ivp

    u0 = np.array([np.pi / L, H / L])
    s = np.linspace(0, L, 201)
    sol = solve_ivp(
        P.geodesic_rhs(christoffel), (0, L), np.r_[0, 0, u0], t_eval=s, rtol=1e-12, atol=1e-12
    )
    assert_allclose(sol.y[:2, -1], [np.pi, H], rtol=1e-10)
    assert P.curve_length(metric, sol.y[:2].T, sol.y[2:].T, s) == pytest.approx(L, rel=1e-12)


def test_trajectory_is_geodesic_of_action_line_element():
    """ds² = 2m(h − V) g_jk dxʲ dxᵏ: a trajectory of energy h satisfies that metric's
    geodesic equation up to reparametrisation (component along ẋ)."""
    cs = spherical()
    dyn = P.particle(cs, M, G)
    q0, v0 = np.array([1.2, 1.2, 0.4]), np.array([0.3, -0.2, 0.5])
    t = np.linspace(0, 0.3, 7)
    q, v = solve(dyn, q0, v0, t)
    a = dyn.forward(q, v, np.zeros_like(q))
    h = float(dyn.kinetic_energy(q0[None], v0[None])[0] + dyn.potential_energy(q0[None])[0])
    r = P.jacobi_residual(cs, M, G, q, v, a, h)
    assert np.abs(r).max() < 1e-9 * np.abs(a).max()
    # a trajectory of another energy is not a geodesic of this metric
    assert np.abs(P.jacobi_residual(cs, M, G, q, v, a, 2 * h)).max() > 1e-3


def test_cartesian_has_no_christoffel_symbols():
    assert not np.any(cartesian().numeric.christoffel(np.ones((3, 3))))


def test_kepler_orbit_exercise_25():
    """Exercise 25(b): r × v is constant; the energy T + V_f is constant; after one period
    2π√(a³/μ) (Kepler's third law, independent of the book) the orbit closes. Reference
    solved in spherical coordinates; a = 1.2, e = 0.3, μ = 1 (the kepler case's orbit)."""
    from dyncheck.cases import get_case

    case = get_case("kepler")
    dyn = P.particle(spherical(), case.M, mu=case.mu)
    period = 2 * np.pi * np.sqrt(1.2**3 / case.mu)
    t = np.linspace(0, period, 401)
    q, v = solve(dyn, np.array(case.trajectory.q0), np.array(case.trajectory.v0), t)
    x = spherical().numeric.position(q)
    xd = np.einsum("nkj,nj->nk", spherical().numeric.jacobian(q), v)
    h = np.cross(x, xd)
    assert np.abs(h - h[0]).max() < 1e-10 * np.linalg.norm(h[0])
    energy = dyn.kinetic_energy(q, v) + dyn.field_potential(q)
    assert np.ptp(energy) < 1e-10 * abs(energy[0])
    assert energy[0] == pytest.approx(-case.mu * case.M / (2 * 1.2), rel=1e-12)  # vis-viva
    assert_allclose(x[-1], x[0], atol=1e-8)
    assert np.linalg.norm(x[200] - x[0]) > 1.0  # it did go round


def test_physical_components_exercise_6():
    """Cylindrical: physical velocity (ṙ, rθ̇, ż) and acceleration (r̈ − rθ̇², rθ̈ + 2ṙθ̇, z̈)."""
    rng = np.random.default_rng(9)
    q = np.column_stack([rng.uniform(0.5, 2, 10), rng.uniform(-3, 3, 10), rng.uniform(-1, 1, 10)])
    v, a = rng.uniform(-1, 1, (10, 3)), rng.uniform(-1, 1, (10, 3))
    cs = cylindrical()
    r, rd, thd = q[:, 0], v[:, 0], v[:, 1]
    assert_allclose(
        P.physical_components(cs, q, v), np.column_stack([rd, r * thd, v[:, 2]]), rtol=1e-14
    )
    f = P.physical_components(cs, q, P.acceleration(cs, q, v, a))
    assert_allclose(
        f,
        np.column_stack([a[:, 0] - r * thd**2, r * a[:, 1] + 2 * rd * thd, a[:, 2]]),
        rtol=1e-13,
        atol=1e-15,
    )
