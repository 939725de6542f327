"""Rigid bodies: the reference against hand expansions, classic closed forms and scipy's
integrator (second half of §2.2, Example 9, exercises 12–16, 23, 26, 30)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp

from dyncheck.reference import rigid as R

EPS = np.finfo(float).eps
angles = st.tuples(
    st.floats(-np.pi, np.pi), st.floats(0.05, np.pi - 0.05), st.floats(-np.pi, np.pi)
)


@pytest.fixture
def particles():
    rng = np.random.default_rng(12)
    return rng.uniform(0.2, 2.0, 7), rng.uniform(-1.0, 1.0, (7, 3))


def test_inertia_tensor_components_exercise_12(particles):
    """(2.2.39) written out by hand: I₁₁ = Σ m(y² + z²), I₁₂ = −Σ m x y, …"""
    m, r = particles
    x, y, z = r.T
    expected = np.array(
        [
            [m @ (y**2 + z**2), -m @ (x * y), -m @ (x * z)],
            [-m @ (x * y), m @ (x**2 + z**2), -m @ (y * z)],
            [-m @ (x * z), -m @ (y * z), m @ (x**2 + y**2)],
        ]
    )
    assert_allclose(R.inertia_tensor(m, r), expected, rtol=1e-14)


def test_energy_and_momentum_from_particles_equal_tensor_forms(particles):
    """(2.2.38) = (2.2.40) and (2.2.41) = (2.2.42), the e–δ identity at work."""
    m, r = particles
    w = np.array([0.3, -1.2, 0.8])
    I = R.inertia_tensor(m, r)
    assert np.isclose(R.kinetic_energy_of_particles(m, r, w), R.kinetic_energy(I, w), rtol=1e-14)
    v = np.cross(w, r)  # (2.2.37)
    assert_allclose(R.angular_momentum_of_particles(m, r, v), R.angular_momentum(I, w), rtol=1e-14)


@given(
    st.lists(st.floats(0.01, 10), min_size=1, max_size=6),
    st.lists(st.floats(-3, 3), min_size=18, max_size=18),
)
def test_inertia_of_particles_is_psd_with_triangle_inequality(masses, coords):
    """Any particle system: I symmetric positive semi-definite, I₁ + I₂ ≥ I₃."""
    m = np.array(masses)
    r = np.array(coords).reshape(6, 3)[: len(m)]
    I = R.inertia_tensor(m, r)
    assert_allclose(I, I.T, atol=0)
    moments, _ = R.principal_axes(I)
    scale = max(1.0, moments[-1])
    assert moments[0] >= -1e-12 * scale
    assert moments[0] + moments[1] >= moments[2] - 1e-12 * scale


def test_continuous_box_and_the_particle_limit():
    """Exercise 13 and the continuum limit: a uniform box a × b × c centred at c₀ has mass
    ρabc, centre c₀ and I = m/12 diag(b² + c², a² + c², a² + b²) + m(|c₀|² δ − c₀c₀ᵀ)
    (classic closed form, parallel axes); a lattice of particles converges to it as O(1/n²)."""
    a, b, c, rho = 0.4, 0.6, 1.0, 2.5
    c0 = np.array([0.3, -0.2, 0.1])
    bounds = tuple((c0[i] - s / 2, c0[i] + s / 2) for i, s in enumerate((a, b, c)))
    mass, com, I = R.continuous_body(lambda x, y, z: rho, bounds)
    m = rho * a * b * c
    expected = m / 12 * np.diag([b**2 + c**2, a**2 + c**2, a**2 + b**2]) + m * (
        c0 @ c0 * np.eye(3) - np.outer(c0, c0)
    )
    assert np.isclose(mass, m, rtol=1e-12)
    assert_allclose(com, c0, rtol=1e-12)
    assert_allclose(I, expected, rtol=1e-10, atol=1e-12)
    errors = []
    for n in (4, 8, 16):
        axes = [lo + (np.arange(n) + 0.5) * (hi - lo) / n for lo, hi in bounds]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
        pts = np.full(len(grid), m / len(grid))
        assert_allclose(R.centre_of_mass(pts, grid), c0, atol=1e-14)
        errors.append(np.abs(R.inertia_tensor(pts, grid) - expected).max())
    assert np.allclose(np.array(errors[:-1]) / np.array(errors[1:]), 4.0, rtol=0.05)


@given(angles)
def test_example_9_printed_equals_product_of_rotations(a):
    """Example 9's printed matrix against R₃(ψ)R₁(θ)R₃(φ), and orthogonal with det 1
    (exercise 16, (2.2.51))."""
    A = R.euler_matrix_printed(*a)
    assert_allclose(A, R.euler_matrix_product(*a), atol=4 * EPS)
    ell = A.T
    assert_allclose(ell.T @ ell, np.eye(3), atol=8 * EPS)  # ℓ_ij ℓ_ik = δ_jk
    assert_allclose(ell @ ell.T, np.eye(3), atol=8 * EPS)  # ℓ_ij ℓ_kj = δ_ik
    assert np.isclose(np.linalg.det(A), 1.0, atol=8 * EPS)


@given(angles)
def test_euler_angles_round_trip_away_from_gimbal_lock(a):
    back = R.euler_angles_from_matrix(R.euler_matrix_printed(*a))
    assert_allclose(R.euler_matrix_printed(*back), R.euler_matrix_printed(*a), atol=1e-14)
    assert np.isclose(back[1], a[1], atol=1e-7)


@pytest.mark.parametrize("theta", [0.0, np.pi, 1e-12])
def test_gimbal_lock_is_refused(theta):
    with pytest.raises(ValueError, match="gimbal lock"):
        R.euler_angles_from_matrix(R.euler_matrix_printed(0.4, theta, -0.2))


@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3))
def test_pitch_roll_yaw_is_a_rotation(pitch, roll, yaw):
    """Exercise 26: orthogonal, det 1; a pure yaw is Example 9's rotation about x₃, a pure
    pitch takes the fixed X axis toward −Z (a rotation of axes about Y)."""
    A = R.pitch_roll_yaw_matrix(pitch, roll, yaw)
    assert_allclose(A @ A.T, np.eye(3), atol=8 * EPS)
    assert np.isclose(np.linalg.det(A), 1.0)
    assert_allclose(R.pitch_roll_yaw_matrix(0, 0, yaw), R.euler_matrix_product(yaw, 0, 0))
    p = R.pitch_roll_yaw_matrix(pitch, 0, 0)
    assert_allclose(p @ [1.0, 0, 0], [np.cos(pitch), 0, np.sin(pitch)], atol=8 * EPS)


@given(angles, st.tuples(*[st.floats(-3, 3)] * 3))
def test_angular_velocity_tensor_equals_exercise_23(a, rates):
    """ω̄_mn = ℓ_jn ℓ̇_jm (2.2.62), its dual (2.2.61), equals the Euler-angle rates of
    exercise 23 for any Euler-angle motion; both tensors are skew; ω = ℓ ω̄."""
    a, rates = np.array(a), np.array(rates)
    ell = R.direction_cosines(*a)
    ell_dot = R.direction_cosine_rates(a, rates)
    wb_t = R.angular_velocity_tensor_body(ell, ell_dot)
    ws_t = R.angular_velocity_tensor_space(ell, ell_dot)
    assert_allclose(wb_t, -wb_t.T, atol=1e-14)
    assert_allclose(ws_t, -ws_t.T, atol=1e-14)
    wb = R.dual_vector(wb_t)
    assert_allclose(wb, R.euler_angle_rates_to_body(a, rates), atol=1e-14)
    assert_allclose(R.dual_vector(ws_t), ell @ wb, atol=1e-14)


def test_body_point_velocity_and_exercise_30():
    """A point fixed in the body (x̄ constant, x = ℓ x̄): v(S) = ℓ̇ x̄ = ω × x (exercise 30,
    case 2 (e)), = −ω_mk x_k, and (2.2.63) with v(S̄) = 0; each body axis êᵢ obeys
    dêᵢ/dt = ω × êᵢ (case 2 (d)). Case 1: a fixed axis (φ̇ only) gives ω along it."""
    a, rates = np.array([0.4, 1.0, -0.6]), np.array([0.7, -0.3, 1.1])
    ell = R.direction_cosines(*a)
    ell_dot = R.direction_cosine_rates(a, rates)
    w_t = R.angular_velocity_tensor_space(ell, ell_dot)
    w = R.dual_vector(w_t)
    xb = np.array([0.2, -0.5, 0.9])
    x, v = ell @ xb, ell_dot @ xb
    assert_allclose(v, np.cross(w, x), atol=1e-15)
    assert_allclose(v, -w_t @ x, atol=1e-15)
    assert_allclose(R.relative_velocity_space(np.zeros(3), w_t, x), -w_t @ x, atol=0)
    for i in range(3):
        assert_allclose(ell_dot[:, i], np.cross(w, ell[:, i]), atol=1e-15)
    ell_dot1 = R.direction_cosine_rates(a, np.array([0.7, 0.0, 0.0]))
    w1 = R.dual_vector(R.angular_velocity_tensor_space(ell, ell_dot1))
    assert_allclose(w1, [0, 0, 0.7], atol=1e-15)


@pytest.fixture
def rigid_state():
    rng = np.random.default_rng(4)
    B = rng.normal(size=(3, 3))
    I = B @ B.T + 2 * np.eye(3)  # products of inertia: not principal axes
    return I, rng.normal(size=(5, 3)), rng.normal(size=(5, 3))


def test_euler_general_equals_printed_components(rigid_state):
    """(2.2.70) in index form against (2.2.71) as printed (exercise 15)."""
    I, w, dw = rigid_state
    assert_allclose(R.euler_residual(I, w, dw), R.euler_residual_printed(I, w, dw), atol=1e-13)


def test_euler_principal_is_the_diagonal_case(rigid_state):
    _, w, dw = rigid_state
    moments = np.array([1.0, 2.5, 3.2])
    assert_allclose(
        R.euler_residual(np.diag(moments), w, dw),
        R.euler_residual_principal(moments, w, dw),
        atol=1e-14,
    )


def test_fourth_order_forms(rigid_state):
    """(2.2.64) and its inverse; H_ij = I_ijst ω_st (before (2.2.68)); (2.2.69) contracted
    with ½ e_mpq is (2.2.70) (exercise 14), and is skew."""
    I, w, dw = rigid_state
    I4 = R.inertia_fourth_order(I)
    assert_allclose(R.inertia_from_fourth_order(I4), I, atol=1e-14)
    H = R.angular_momentum(I, w)
    assert_allclose(R.dual_tensor(H), np.einsum("ijst,nst->nij", I4, R.dual_tensor(w)), atol=1e-13)
    r4 = R.euler_fourth_order_residual(I, w, dw)
    assert_allclose(r4, -np.swapaxes(r4, -1, -2), atol=1e-13)
    assert_allclose(0.5 * np.einsum("mpq,npq->nm", R.E, r4), R.euler_residual(I, w, dw), atol=1e-13)


def test_angular_acceleration_solves_euler(rigid_state):
    I, w, _ = rigid_state
    M = np.array([0.3, -0.2, 0.5])
    assert_allclose(
        R.euler_residual(I, w, R.angular_acceleration(I, w, M)),
        np.broadcast_to(M, w.shape),
        atol=1e-13,
    )


def test_space_angular_momentum_conserved_torque_free(rigid_state):
    """(2.2.49) with M = 0: ω̄ by Euler's equations and the attitude by ℓ̇ = ℓ ω̄̃ keep
    H = ℓ Ī ω̄ constant in space (scipy's DOP853, tight tolerances)."""
    I, w, _ = rigid_state
    w0 = w[0]

    def rhs(_t, y):
        ell, wb = y[:9].reshape(3, 3), y[9:]
        # ℓ̇_ij = ℓ_ik ω̄̃_kj with ω̄̃ the body tensor, ω̄̃ x̄ = ω̄ × x̄
        return np.concatenate(
            [(ell @ -R.dual_tensor(wb)).ravel(), R.angular_acceleration(I, wb, 0)]
        )

    sol = solve_ivp(rhs, (0, 5), np.concatenate([np.eye(3).ravel(), w0]), method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=np.linspace(0, 5, 11))  # fmt: skip
    H = [y[:9].reshape(3, 3) @ R.angular_momentum(I, y[9:]) for y in sol.y.T]
    assert_allclose(H, np.broadcast_to(H[0], (11, 3)), atol=1e-9)
    T = [R.kinetic_energy(I, y[9:]) for y in sol.y.T]
    assert_allclose(T, T[0], rtol=1e-10)


@pytest.mark.parametrize(
    "w0",
    [(0.1, 1.5, 0.3), (1.2, 0.5, -0.3), (-0.4, -0.2, 1.1), (0.05, 1.0, -0.05)],
    ids=["near-intermediate", "H2<2TI2", "near-major", "tumbling"],
)
def test_torque_free_closed_form_matches_integration(w0):
    """The Jacobi-elliptic closed form against DOP853 on (2.2.72) with M = 0 (rtol 1e-13),
    over several periods; both regimes H² ≷ 2T I₂; T and H² constant along it."""
    moments = np.array([1.0, 2.0, 3.0])
    tf = R.TorqueFree(tuple(moments), w0)
    t = np.linspace(0, 20, 81)
    sol = solve_ivp(lambda _t, w: R.angular_acceleration(np.diag(moments), w, 0), (0, 20), w0,
                    method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)  # fmt: skip
    w = tf.omega(t)
    assert_allclose(w, sol.y.T, atol=1e-9)
    assert_allclose(w[0], w0, atol=1e-14)
    assert_allclose(moments @ (w**2).T, moments @ np.square(w0), rtol=1e-13)
    assert_allclose(moments**2 @ (w**2).T, moments**2 @ np.square(w0), rtol=1e-13)
    assert 0 < tf.parameter < 1


def test_torque_free_needs_an_asymmetric_body():
    with pytest.raises(ValueError, match="I1 < I2 < I3"):
        R.TorqueFree((1.0, 1.0, 2.0), (0.1, 0.2, 0.3))
