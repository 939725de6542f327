"""The pulley cases: geometry, couplings, bad input, and the identity the soft-constraint
predictions rely on (engine coordinates = the reference's free coordinates)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.cases import get_case
from dyncheck.cases.multibody import Body, Coupling, Joint, Multibody
from dyncheck.errors import InvalidInput
from dyncheck.implementations import general_method

from ..conftest import COUPLED_CASES


@pytest.mark.parametrize("case_name", COUPLED_CASES)
def test_engine_coordinates_are_the_references_free_coordinates(case_name):
    """s = A x + b in both: the soft model is stepped on the engine's own coordinates."""
    case = get_case(case_name)
    cords = general_method(case).cords
    cmap = case.engine_map()
    assert np.array_equal(cmap.A, cords.A)
    assert np.array_equal(np.asarray(cmap.offset), cords.b)
    assert_allclose(case.multibody().coupling_matrix(), cords.C)


@pytest.mark.parametrize("case_name", COUPLED_CASES)
def test_book_states_satisfy_the_cords(case_name):
    case = get_case(case_name)
    s = case.sample_states(50)
    qe = case.engine_map().to_engine(s.q)
    C = case.multibody().coupling_matrix(positions=True)
    assert_allclose(qe @ C.T, 0, atol=1e-15)
    assert_allclose(case.engine_map().to_book(qe), s.q, atol=1e-15)


def test_compound_pulley_geometry():
    """Depths from the cords: y_P = ℓ₁ − πa − y₁; m₂, m₃ hang y₂ and ℓ₂ − πa − y₂ below P."""
    c = get_case("compound_pulley")
    z = c.depths(np.array([1.0, 0.4]))[0]
    yp = c.l1 - np.pi * c.a - 1.0
    assert_allclose(z, [1.0, yp + 0.4, yp + c.l2 - np.pi * c.a - 0.4])


@pytest.mark.parametrize(
    ("case_name", "field", "value", "message"),
    [
        ("atwood", "a", -0.1, "a must be a positive finite number, got -0.1"),
        ("atwood", "a", float("inf"), "a must be a positive finite number, got inf"),
        ("atwood", "m2", 0.0, "m2 must be a positive finite number, got 0.0"),
        ("compound_pulley", "a", 0.0, "a must be a positive finite number, got 0.0"),
        ("compound_pulley", "l2", 0.2, "l2 must be longer than the wrap"),
    ],
)
def test_bad_pulley_parameters(case_name, field, value, message):
    with pytest.raises(InvalidInput, match=f"^{message}"):
        dataclasses.replace(get_case(case_name), **{field: value})


def test_state_above_the_pulley_is_refused():
    case = get_case("atwood")
    spec = dataclasses.replace(case.trajectory, q0=(3.5,))
    with pytest.raises(InvalidInput, match=r"^q0 must be off the singular set.*above the pulley"):
        dataclasses.replace(case, trajectory=spec)


def _slide(name: str) -> Body:
    return Body(name, None, (0, 0, 0), (Joint(name, "slide", (0, 0, -1)),), 1.0, (0, 0, 0))


@pytest.mark.parametrize(
    ("coefs", "message"),
    [
        ((("a", 1.0), ("nope", 1.0)), "must be the name of a slide or hinge joint, got 'nope'"),
        ((("a", 1.0), ("b", 0.0)), r"cord.coefs\[b\] must be a finite non-zero number"),
        ((("a", float("nan")),), r"cord.coefs\[a\] must be a finite non-zero number"),
        ((), "cord.coefs must be at least one joint"),
    ],
)
def test_bad_coupling(coefs, message):
    with pytest.raises(InvalidInput, match=message):
        Multibody(
            "m", (_slide("a"), _slide("b")), (0, 0, -9.81), couplings=(Coupling("cord", coefs),)
        )
