"""The book's tensor calculus against the engines' recursive algorithms: for a particle carried
by coordinate joints, the engine's mass matrix (pulled back to the book's coordinates) is
M g_ij and its velocity-dependent bias is M g_ij {j; m n} q̇ᵐ q̇ⁿ — metric and Christoffel
symbols from dyncheck.reference.coordinates (closed forms), engines through the case's map."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.cases import get_case
from dyncheck.implementations import make_implementation
from dyncheck.reference.coordinates import cylindrical, spherical

from ..conftest import ENGINES, FLOORED, supported

SYSTEMS = {"spherical_coordinates": spherical, "cylindrical_coordinates": cylindrical}


@pytest.mark.parametrize(("case_name", "engine"), [
    (c, e) for c in sorted(SYSTEMS) for e in ENGINES if supported(c, e)
    # Newton applies a body's slides before its hinges (its D6): another model, whose M is
    # the referee's on that order (tests/adapters/newton/test_model.py)
    and e != "newton"])
def test_engine_mass_matrix_is_metric_and_bias_is_christoffel(case_name, engine):
    case = get_case(case_name)
    cs = SYSTEMS[case_name]()
    s = case.sample_states(64)
    impl = make_implementation(engine, case)
    out = impl.evaluate(s)
    g = cs.numeric.metric(s.q)
    reads_mjcf = engine in FLOORED
    floor = case.multibody().mjcf_point_inertia if reads_mjcf else 0.0
    # the MJCF floor adds I |ω|² / 2: diag over the rotating coordinates (predicted, see report)
    rot = {"spherical_coordinates": [0, 1, 1], "cylindrical_coordinates": [0, 1, 0]}[case_name]
    assert_allclose(
        out["mass_matrix"],
        case.M * g + floor * np.diag(rot),
        rtol=0,
        atol=64 * impl.eps * case.M * np.abs(g).max(),
    )
    gravity = case.M * case.g * cs.numeric.jacobian(s.q)[:, 2, :]  # ∂V/∂q, V = M g z
    velocity_terms = case.M * np.einsum(
        "nij,njmk,nm,nk->ni", g, cs.numeric.christoffel(s.q), s.v, s.v
    )
    scale = np.abs(velocity_terms).max() + np.abs(gravity).max()
    assert_allclose(
        out["bias_forces"] - gravity, velocity_terms, rtol=0, atol=64 * impl.eps * scale
    )
