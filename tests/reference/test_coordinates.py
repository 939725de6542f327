"""Coordinate systems: closed-form Christoffel symbols against the exact derivation, the
metric's definiteness away from the singular set, and a user-given map."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from numpy.testing import assert_allclose

from dyncheck.reference.coordinates import NAMED, custom, spherical


@pytest.mark.parametrize("name", sorted(NAMED))
def test_closed_form_christoffel_equals_derived(name):
    cs = NAMED[name]()
    closed = cs.closed_form_christoffel()
    for i in range(3):
        for m in range(3):
            for k in range(3):
                assert sp.simplify(cs.christoffel[i][m][k] - closed[i][m][k]) == 0, (i, m, k)
    assert list(cs.metric.diagonal()) == [sp.sympify(e) for e in cs.closed_metric]


@pytest.mark.parametrize("name", sorted(NAMED))
def test_metric_positive_definite_away_from_singular_set(name):
    cs = NAMED[name]()
    rng = np.random.default_rng(5)
    q = np.column_stack(
        [rng.uniform(0.1, 3, 200), rng.uniform(0.05, np.pi - 0.05, 200), rng.uniform(-3, 3, 200)]
    )
    assert (np.linalg.eigvalsh(cs.numeric.metric(q)) > 0).all()


def test_spherical_metric_degenerates_on_the_axis():
    g = spherical().numeric.metric(np.array([[1.0, 0.0, 0.3]]))
    assert np.linalg.eigvalsh(g)[0][0] == 0.0


def test_user_map_derivatives_are_exact():
    """Parabolic coordinates (u, v, φ): x = uv cos φ, y = uv sin φ, z = (u² − v²)/2 have
    g = diag(u² + v², u² + v², u²v²) (a standard result, independent of the code)."""
    u, v, ph = sp.symbols("u v phi", positive=True)
    cs = custom(
        "parabolic", (u, v, ph), (u * v * sp.cos(ph), u * v * sp.sin(ph), (u**2 - v**2) / 2)
    )
    assert sp.simplify(cs.metric - sp.diag(u**2 + v**2, u**2 + v**2, u**2 * v**2)) == sp.zeros(3)
    # {u; v v} = −u/(u² + v²) from [vv, u] = −u with g_uu = u² + v²
    assert sp.simplify(cs.christoffel[0][1][1] + u / (u**2 + v**2)) == 0
    q = np.array([[1.2, 0.7, 0.3]])
    assert_allclose(cs.numeric.metric(q)[0], np.diag([1.93, 1.93, 1.44 * 0.49]), rtol=1e-15)
