"""The general method on a system with a textbook answer: a particle in polar coordinates."""

from __future__ import annotations

import numpy as np
import sympy as sp
from numpy.testing import assert_allclose

from dyncheck.reference.lagrange import SymbolicSystem


def test_polar_particle_in_central_field():
    """T = ½ m (ṙ² + r² φ̇²), V = −k/r: M = diag(m, m r²), h = (−m r φ̇² + k/r², 2 m r ṙ φ̇)."""
    r, phi, rd, phid = sp.symbols("r phi rdot phidot")
    m, k = sp.symbols("m k", positive=True)
    T = m * (rd**2 + r**2 * phid**2) / 2
    dyn = SymbolicSystem((r, phi), (rd, phid), (m, k), T, -k / r).numeric({"m": 2.0, "k": 3.0})
    rng = np.random.default_rng(3)
    q = np.column_stack([rng.uniform(0.5, 2, 20), rng.uniform(-3, 3, 20)])
    v = rng.uniform(-2, 2, (20, 2))
    M = dyn.mass_matrix(q)
    assert_allclose(M[:, 0, 0], 2.0)
    assert_allclose(M[:, 1, 1], 2.0 * q[:, 0] ** 2)
    assert_allclose(M[:, 0, 1], 0.0)
    h = dyn.bias(q, v)
    assert_allclose(h[:, 0], -2.0 * q[:, 0] * v[:, 1] ** 2 + 3.0 / q[:, 0] ** 2, rtol=1e-14)
    assert_allclose(h[:, 1], 2 * 2.0 * q[:, 0] * v[:, 0] * v[:, 1], rtol=1e-14)


def test_forward_inverts_inverse():
    th, thd = sp.symbols("theta thetadot")
    dyn = SymbolicSystem((th,), (thd,), (), (2 + sp.cos(th)) * thd**2 / 2, sp.sin(th)).numeric({})
    q, v, a = np.array([[0.3], [1.2]]), np.array([[0.5], [-2.0]]), np.array([[1.0], [3.0]])
    assert_allclose(dyn.forward(q, v, dyn.inverse(q, v, a)), a, rtol=1e-14)
