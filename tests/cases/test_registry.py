"""The case registry: sorted, every case valid and loadable in every adapter; bad input."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from dyncheck.cases import CASES, get_case
from dyncheck.errors import InvalidInput, UnknownName, Unsupported
from dyncheck.implementations import make_implementation

from ..conftest import ALL_ENGINES, CASE_NAMES, loaded, supported, unsupported_reason


def test_registry_is_sorted():
    assert list(CASES) == sorted(CASES)


@pytest.mark.parametrize("engine", ALL_ENGINES)
@pytest.mark.parametrize("case", CASE_NAMES)
def test_case_loads_in_every_adapter(case, engine):
    """Every case loads in every engine, or is refused with the named reason (ball joints and
    couplings in Drake and sympy-mechanics; mujoco-stiff without couplings), never silently."""
    c = get_case(case)
    if not supported(case, engine):
        with pytest.raises(Unsupported, match=unsupported_reason(case, engine)):
            loaded(engine, c.multibody())
        return
    impl = make_implementation(engine, c)  # the case's map and the engine's storage
    nv = c.multibody().nv
    assert impl.adapter.mass_matrix(impl.map.to_engine(c.rest()[None])).shape == (1, nv, nv)


@pytest.mark.parametrize("case", CASE_NAMES)
def test_samples_are_deterministic(case):
    a, b = get_case(case).sample_states(), get_case(case).sample_states()
    assert np.array_equal(a.q, b.q) and np.array_equal(a.tau, b.tau)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("m", -1.0, "m must be a positive finite number, got -1.0"),
        ("l", 0.0, "l must be a positive finite number, got 0.0"),
        ("g", float("nan"), "g must be a positive finite number, got nan"),
    ],
)
def test_bad_parameters_name_field_and_value(field, value, message):
    with pytest.raises(InvalidInput, match=f"^{message}$"):
        dataclasses.replace(get_case("simple_pendulum"), **{field: value})


def test_bad_step_size():
    case = get_case("simple_pendulum")
    with pytest.raises(InvalidInput, match=r"^steps\[euler\] dt must be a divisor of duration"):
        dataclasses.replace(case.trajectory, steps={"euler": (0.003, 0.0015)})
    with pytest.raises(InvalidInput, match="must be a halving sequence"):
        dataclasses.replace(case.trajectory, steps={"euler": (0.004, 0.001)})
    with pytest.raises(InvalidInput, match="duration must be a positive finite number"):
        dataclasses.replace(case.trajectory, duration=-1.0)


def test_unknown_case_lists_valid_names():
    from dyncheck.cases import CASES  # (the registry: valid whatever cases it holds)

    valid = re.escape(", ".join(sorted(CASES)))
    with pytest.raises(UnknownName, match=f"unknown case 'pendulum'; valid: {valid}$"):
        get_case("pendulum")


@pytest.mark.parametrize("case", CASE_NAMES)
def test_states_do_not_depend_on_chunk_size(case):
    c = get_case(case)
    whole = c.sample_states(1000)
    chunks = list(c.iter_states(1000, chunk=300))
    assert [len(s) for s in chunks] == [300, 300, 300, 100]
    for name in ("q", "v", "tau", "a"):
        assert np.array_equal(
            np.concatenate([getattr(s, name) for s in chunks]), getattr(whole, name)
        )


@pytest.mark.parametrize("case", CASE_NAMES)
def test_a_slice_of_the_states_is_the_same_states(case):
    """Slices [start, stop) jump the random streams ahead: concatenated, they are the whole
    sample bit for bit (a sweep cut across workers samples the states of one process)."""
    c = get_case(case)
    whole = c.sample_states(1000)
    parts = [s for a, b in ((0, 1), (1, 377), (377, 1000)) for s in c.iter_states(
        1000, chunk=128, start=a, stop=b)]
    for name in ("q", "v", "tau", "a"):
        assert np.array_equal(
            np.concatenate([getattr(s, name) for s in parts]), getattr(whole, name)
        )


@pytest.mark.parametrize(("start", "stop"), [(-1, 5), (5, 5), (0, 11)])
def test_bad_state_slice(start, stop):
    with pytest.raises(InvalidInput, match=r"^states slice"):
        next(get_case("simple_pendulum").iter_states(10, start=start, stop=stop))


@pytest.mark.parametrize("n", [0, -3, 2.5, True])
def test_bad_state_count(n):
    with pytest.raises(InvalidInput, match=r"^states must be a positive integer"):
        get_case("simple_pendulum").sample_states(n)


def test_every_case_has_one_reference_system_and_no_system_lacks_a_case():
    """Adding a case = its module in cases/ + its system in reference/systems.py: a case
    without a system (or a system left behind by a removed case) is caught here."""
    from dyncheck.cases import CASES
    from dyncheck.reference.systems import systems

    assert set(systems()) == set(CASES)
