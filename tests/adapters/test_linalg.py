"""The stage solve and the rigid constrained solve (adapters/linalg.py).

Expected values: numpy.linalg.solve of the same systems (numpy's own LAPACK build, reached
through numpy's checks and conversions): the same LU with partial pivoting, so within the
forward error bound of a backward-stable solve, 4·n·κ(a)·ε relative (the two builds' kernels
may round differently); numpy's LinAlgError for a singular matrix; a constrained point mass
solved by hand."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.adapters.linalg import closed, solve


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8])
def test_solve_is_numpys_solve_within_round_off(n):
    rng = np.random.default_rng(n)
    eps = np.finfo(float).eps
    for _ in range(50):
        a = rng.standard_normal((n, n)) + n * np.eye(n)
        b = rng.standard_normal(n)
        x, want = solve(a, b), np.linalg.solve(a, b)
        assert x.shape == (n,)
        bound = 4 * n * np.linalg.cond(a) * eps * np.linalg.norm(want)
        assert np.linalg.norm(x - want) <= bound


def test_a_kkt_matrix_needs_pivoting_and_is_solved():
    """A mass matrix bordered by a constraint row has a zero on its diagonal: only a pivoting
    LU solves it (Drake's cords, adapters/drake/simulation.py)."""
    m = np.diag([2.0, 3.0])
    c = np.array([[1.0, -1.0]])
    k = np.block([[m, -c.T], [c, np.zeros((1, 1))]])
    b = np.array([1.0, 2.0, 0.0])
    want = np.linalg.solve(k, b)
    bound = 4 * 3 * np.linalg.cond(k) * np.finfo(float).eps * np.linalg.norm(want)
    assert np.linalg.norm(solve(k, b) - want) <= bound


def test_a_singular_matrix_raises_numpys_error():
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        solve(np.array([[1.0, 2.0], [2.0, 4.0]]), np.array([1.0, 0.0]))


@pytest.mark.parametrize("repeated", [False, True])
def test_closed_holds_redundant_rows_and_answers_by_hand(repeated):
    """A point mass m on a plane held on the line x = 0 (J = [1, 0]; the row written twice
    where ``repeated``: J of rank 1), pushed by f = (f₁, f₂), drifting at J̇ v = d. By hand:
    ẍ = −d, ÿ = f₂/m, and the constraint's generalized force Jᵀλ = M v̇ − f = (−m d − f₁, 0)
    whatever the rows' redundancy."""
    m, f, d = 2.0, np.array([3.0, -5.0]), 0.7
    J = np.array([[1.0, 0.0], [1.0, 0.0]]) if repeated else np.array([[1.0, 0.0]])
    vdot, force = closed(np.diag([m, m]), f, J, np.full(len(J), d))
    np.testing.assert_allclose(vdot, [-d, f[1] / m], rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(J.T @ force, [-m * d - f[0], 0.0], rtol=1e-15, atol=1e-14)
