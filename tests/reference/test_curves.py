"""Frenet–Serret, the acceleration split, Darboux, work — and exercises 1–5 with answers
derived by hand in the tests."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from numpy.testing import assert_allclose

from dyncheck.reference.coordinates import cylindrical, spherical
from dyncheck.reference.curves import (
    Curve,
    DegenerateCurve,
    intersect_plane,
    line_through,
    plane_through,
)
from dyncheck.reference.work import conservative_force, kinetic_energy, work

t = sp.Symbol("t")


def test_exercise_1_line_tangent_and_degenerate_frame():
    """Through (1,1,1) and (2,3,4): x = 1 + t, y = 1 + 2t, z = 1 + 3t; T = (1,2,3)/√14.
    A straight line has κ = 0: asking for N is a clear error, not NaN."""
    line = line_through(np.array([1, 1, 1]), np.array([2, 3, 4]), t)
    assert_allclose(line.position(1.0), [2, 3, 4])
    assert_allclose(line.tangent(0.3), np.array([1, 2, 3]) / np.sqrt(14), rtol=1e-15)
    with pytest.raises(DegenerateCurve, match=r"curvature is zero at t=0\.3"):
        line.frame(0.3)


def test_exercise_2_frame_at_pi():
    """r' = (½ sin 2t, sin²t, cos t), r'' = (cos 2t, sin 2t, −sin t); at t = π, r' = (0,0,−1)
    and r'' = (1,0,0) ⊥ r' with |r'| stationary, so T = (0,0,−1), N = (1,0,0),
    B = T × N = (0,−1,0), κ = |r' × r''|/|r'|³ = 1."""
    c = Curve(t, (sp.sin(t) ** 2 / 2, t / 2 - sp.sin(2 * t) / 4, sp.sin(t)))
    f = c.frame(np.pi)
    assert_allclose(f.T, [0, 0, -1], atol=1e-15)
    assert_allclose(f.N, [1, 0, 0], atol=1e-15)
    assert_allclose(f.B, [0, -1, 0], atol=1e-15)
    assert f.kappa == pytest.approx(1.0, rel=1e-15)


def test_exercise_3_twisted_cubic_meets_plane_three_times():
    """t³ − 6t² + 11t − 6 = (t − 1)(t − 2)(t − 3): the claim is true, points (1,1,1),
    (2,4,8), (3,9,27)."""
    cubic = Curve(t, (t, t**2, t**3))
    roots = intersect_plane(cubic, (11, -6, 1), 6)
    assert roots == [1, 2, 3]
    assert [tuple(cubic.position(float(r))) for r in roots] == [(1, 1, 1), (2, 4, 8), (3, 9, 27)]


def test_exercise_4_plane_and_normal():
    """x/3 + y/4 + z/5 = 1 has normal ∝ (1/3, 1/4, 1/5) ∝ (20, 15, 12), |.| = √769."""
    x, n = plane_through(np.array([3, 0, 0]), np.array([0, 4, 0]), np.array([0, 0, 5]))
    s1, s2 = sp.symbols("s1 s2")
    for a, b in ((0, 0), (1, 0), (0, 1), (0.3, 0.2)):
        p = x.subs({s1: a, s2: b})
        assert sp.simplify(p[0] / 3 + p[1] / 4 + p[2] / 5 - 1) == 0
    assert sp.simplify(n - sp.Matrix([20, 15, 12]) / sp.sqrt(769)) == sp.zeros(3, 1)


def test_exercise_5_helix_tangent_line_and_normal_plane():
    """x = sin t, y = cos t, z = 2t/π at t = π/4: r₀ = (√2/2, √2/2, ½), r' = (√2/2, −√2/2,
    2/π); tangent line r₀ + λ r', normal plane r'·(x − r₀) = 0."""
    helix = Curve(t, (sp.sin(t), sp.cos(t), 2 * t / sp.pi))
    r0 = np.array([np.sqrt(2) / 2, np.sqrt(2) / 2, 0.5])
    rp = np.array([np.sqrt(2) / 2, -np.sqrt(2) / 2, 2 / np.pi])
    assert_allclose(helix.position(np.pi / 4), r0, rtol=1e-15)
    assert_allclose(helix.tangent(np.pi / 4), rp / np.linalg.norm(rp), rtol=1e-15)


@pytest.mark.parametrize(
    ("curve", "kappa", "tau"),
    [
        # circular helix radius a, pitch c per radian: κ = a/(a² + c²), τ = c/(a² + c²)
        (Curve(t, (sp.Integer(1), t, t / 2), cylindrical()), 0.8, 0.4),
        (Curve(t, (2 * sp.cos(t), 2 * sp.sin(t), 3 * t)), 2 / 13, 3 / 13),
        # circle of radius 1.5 on the sphere's equator, in spherical coordinates
        (Curve(t, (sp.Rational(3, 2), sp.pi / 2, t), spherical()), 1 / 1.5, 0.0),
    ],
    ids=["helix-cylindrical", "helix-cartesian", "circle-spherical"],
)
def test_frenet_serret_in_any_coordinates(curve, kappa, tau):
    f = curve.frame(0.37)
    assert f.kappa == pytest.approx(kappa, rel=1e-14)
    assert f.tau == pytest.approx(tau, abs=1e-14)
    res = curve.frenet_residuals(0.37)  # (2.2.15)
    assert max(res.values()) < 1e-14


def test_acceleration_lies_in_osculating_plane():
    """(2.2.17): f = (dv/dt) T + κ v² N, for a curve with varying speed in spherical coords."""
    c = Curve(t, (1 + t**2 / 3, sp.pi / 3 + t / 5, 2 * t), spherical())
    dv, kv2, f = c.acceleration_split(0.8)
    fr = c.frame(0.8)
    assert_allclose(f, dv * fr.T + kv2 * fr.N, rtol=1e-12, atol=1e-13)


def test_darboux_vector_exercise_29():
    """δT/δs = D × T, δN/δs = D × N, δB/δs = D × B with D = τT + κB (Cartesian helix)."""
    c = Curve(t, (2 * sp.cos(t), 2 * sp.sin(t), 3 * t))
    f, D = c.frame(0.5), c.darboux(0.5)
    assert_allclose(np.cross(D, f.T), f.kappa * f.N, atol=1e-15)
    assert_allclose(np.cross(D, f.N), f.tau * f.B - f.kappa * f.T, atol=1e-15)
    assert_allclose(np.cross(D, f.B), -f.tau * f.N, atol=1e-15)


def test_work_is_path_independent_for_conservative_force():
    """(2.2.19)–(2.2.20): gravity V = m g z from (1,0,0) to (0,1,2) along two paths: W = −ΔV
    = −m g·2; a non-conservative field (−y, x, 0) gives different work on the two paths."""
    x, y, z = sp.symbols("x y z", real=True)
    m, g = 1.3, 9.81
    straight = Curve(t, (1 - t, t, 2 * t))
    arc = Curve(t, (sp.cos(sp.pi * t / 2), sp.sin(sp.pi * t / 2), 2 * t**2))
    grav = conservative_force(m * g * z, (x, y, z))
    assert work(grav, straight, 0, 1) == pytest.approx(-m * g * 2, rel=1e-13)
    assert work(grav, arc, 0, 1) == pytest.approx(-m * g * 2, rel=1e-13)

    def swirl(x, y, z):
        return [-y, x, 0 * z]

    # by hand: straight: ∫(−t·(−1) + (1−t)·1) dt = 1; quarter circle: ∫ (π/2) dt = π/2
    assert work(swirl, straight, 0, 1) == pytest.approx(1.0, rel=1e-13)
    assert work(swirl, arc, 0, 1) == pytest.approx(np.pi / 2, rel=1e-13)


def test_kinetic_energy_in_spherical_coordinates():
    """(2.2.21) with the spherical metric: ½M(ρ̇² + ρ²θ̇² + ρ² sin²θ φ̇²)."""
    c = Curve(t, (1 + t, sp.pi / 4 + t, 3 * t), spherical())
    rho, th = 1.5, np.pi / 4 + 0.5
    assert kinetic_energy(c, 2.0, 0.5) == pytest.approx(
        0.5 * 2.0 * (1 + rho**2 + rho**2 * np.sin(th) ** 2 * 9), rel=1e-14
    )
