"""Skipped rows stated once (dyncheck/skipped.py): an engine's limit on a case is one row
naming the engine and the quantities it leaves out; measured rows untouched.
Expected values: the rows the test writes."""

from __future__ import annotations

import math

from dyncheck.results import Discrepancy
from dyncheck.skipped import once_per_case

WHY = "pybullet does not compute it here: its inverse dynamics takes no spherical joint"


def _skip(quantity: str, a: str, b: str, note: str = WHY, case: str = "ball") -> Discrepancy:
    return Discrepancy.unmeasured(case=case, quantity=quantity, impl_a=a, impl_b=b,
                                  tolerance=1e-14, basis="", verdict="skipped", note=note)


def test_one_reason_on_one_case_is_one_row_naming_the_engine():
    rows = [_skip(q, a, "pybullet") for q in ("bias_forces", "inverse_dynamics")
            for a in ("book", "mujoco", "reference")]
    rows.append(_skip("bias_forces", "pybullet", "sympy-mechanics"))  # the engine as impl_a
    measured = Discrepancy.measured(case="ball", quantity="mass_matrix", impl_a="book",
                                    impl_b="pybullet", error=0.0, scale=1.0, tolerance=1e-14,
                                    basis="", verdict="passed")
    out = once_per_case([measured, *rows])
    assert out[0] == measured
    assert len(out) == 2
    merged = out[1]
    assert merged.impl_b == "pybullet"
    assert merged.impl_a == ""  # the engine's row, whatever partners a run had
    assert merged.quantity == "bias_forces, inverse_dynamics"
    assert merged.note == WHY and merged.verdict == "skipped"


def test_other_reasons_and_other_cases_stay_apart():
    rows = [_skip("trajectory", "reference", "newton", "newton: a step budget", case=c)
            for c in ("ball", "free")]
    rows += [_skip("bias_forces", "book", "newton", "newton: another limit")]
    out = once_per_case(rows)
    assert sorted((r.case, r.note) for r in out) == [
        ("ball", "newton: a step budget"), ("ball", "newton: another limit"),
        ("free", "newton: a step budget")]
    assert all(r.impl_b == "newton" for r in out)
    assert all(math.isnan(r.dt) for r in out)


def test_an_engine_named_in_quotes_is_the_row_s_engine():
    """A missing engine's rows say "implementation 'pinocchio' needs 'pin'": the merged row
    is pinocchio's, whichever side its rows had it on (a derivative row has no partner)."""
    why = "implementation 'pinocchio' needs 'pin', which is not installed; pip install pin"
    rows = [_skip("derivatives", "pinocchio", "", why), _skip("trajectory", "reference",
                                                              "pinocchio", why)]
    (merged,) = once_per_case(rows)
    assert merged.impl_b == "pinocchio" and merged.quantity == "derivatives, trajectory"
