"""The vocabulary (dyncheck/vocabulary.py): each closed set once, with what belongs to it.

Expected values: the methods' orders from their definitions (Euler and its semi-implicit
variants first order; Drake's RK2 and RK3 and the classical RK4 by their Butcher tableaux; a
force held over RK4's stages errs by O(h²) a step: first order), and the severity order the
issue fixed (passed < explained < skipped < failed)."""

from __future__ import annotations

import pytest

from dyncheck.cases import NOMINAL_ORDER
from dyncheck.vocabulary import (
    ALONG_RUNS,
    INSTANTANEOUS,
    SEVERITY,
    Integrator,
    Quantity,
    Verdict,
    is_rk4,
)

ORDERS = {"euler": 1, "implicitfast": 1, "rk2": 2, "rk3": 3, "rk4": 4, "rk4-held-force": 1}


@pytest.mark.parametrize("name", sorted(ORDERS))
def test_each_integrator_has_its_methods_order(name):
    assert Integrator(name).nominal_order == ORDERS[name]
    assert NOMINAL_ORDER[name] == ORDERS[name]  # the cases' table is the vocabulary's


def test_rk4_and_its_held_force_variant_are_the_rk4_family_and_nothing_else_is():
    assert {i for i in Integrator if i.is_rk4} == {Integrator.RK4, Integrator.RK4_HELD_FORCE}
    assert is_rk4("rk4") and is_rk4("rk4-held-force")
    assert not any(is_rk4(n) for n in ("rk3-controlled eps=1e-07", "dop853", "rk3", "euler"))


def test_the_quantities_split_into_instantaneous_and_along_runs():
    assert set(INSTANTANEOUS) | set(ALONG_RUNS) == set(Quantity)
    assert not set(INSTANTANEOUS) & set(ALONG_RUNS)


def test_the_verdicts_one_order_puts_a_lost_check_between_explained_and_failed():
    assert sorted(Verdict, key=SEVERITY.__getitem__) == [
        Verdict.PASSED, Verdict.EXPLAINED, Verdict.SKIPPED, Verdict.FAILED]
    assert str(Verdict.PASSED) == "passed" and f"{Quantity.TRAJECTORY}" == "trajectory"
