"""Derivative rows of the book's cases in ``dyncheck run`` (#46). Expected values: the
referee (the general method differentiated, with its own error estimate) and the other
engines; a test double breaks one engine's derivative on purpose."""

from __future__ import annotations

import pytest

from dyncheck.cases import get_case
from dyncheck.studies.derivatives import derivative_rows

from ...conftest import CASE_NAMES

CORE = ["reference", "mujoco", "pinocchio"]


@pytest.mark.parametrize("case", CASE_NAMES)
def test_every_case_has_derivative_rows_that_pass_or_say_why_not(case):
    """Every pair of the core engines and the referee on all five derivatives, passed or (on
    Pinocchio's composite joint, an MJCF body with several joints) explained by its declared
    defect; a skipped row only for a step the referee's chain rule does not follow (RK4's
    naive stages on a rotation before MuJoCo 4.0), saying so."""
    rows = derivative_rows(get_case(case), CORE, 8)
    verdicts = {r.verdict for r in rows}
    assert "failed" not in verdicts, [r.note for r in rows if r.verdict == "failed"]
    skipped = [r for r in rows if r.verdict == "skipped"]
    steps = ("RK4's stages",)
    assert all(any(s in r.note for s in steps) for r in skipped)
    explained = [r for r in rows if r.verdict == "explained"]
    assert all("pinocchio" in (r.impl_a, r.impl_b) and "composite joint" in r.note
               and r.convention for r in explained)
    derivative = [r for r in rows if r.quantity.startswith("d(")]
    pairs = {(r.impl_a, r.impl_b) for r in derivative}
    expected = 5 * (len(CORE) - 1) * len(CORE) // 2 if not skipped or all(
        any(s in r.note for s in steps) for r in skipped) else 5
    assert len(derivative) == expected, pairs


def test_a_derivative_off_by_one_part_in_a_million_fails_naming_engine_case_and_entry(
        monkeypatch):
    """A test double of Pinocchio whose ∂τ/∂q has one entry scaled by 1 + 1e-6: its rows
    against the referee and MuJoCo fail, naming Pinocchio and the entry; nothing else."""
    from dataclasses import replace

    from dyncheck.adapters.pinocchio import model as pinocchio_model

    original = pinocchio_model.PinocchioModel.derivatives

    def broken(self, q, v, a):
        found = original(self, q, v, a)
        inverse_q = found.inverse_q.copy()
        inverse_q[:, 0, 0] *= 1 + 1e-6
        return replace(found, inverse_q=inverse_q)

    monkeypatch.setattr(pinocchio_model.PinocchioModel, "derivatives", broken)
    rows = derivative_rows(get_case("compound_pendulum"), CORE, 8)
    failed = [r for r in rows if r.verdict == "failed"]
    assert {(r.quantity, r.impl_a, r.impl_b) for r in failed} == {
        ("d(inverse)/dq", "reference", "pinocchio"), ("d(inverse)/dq", "mujoco", "pinocchio")}
    assert all(r.case == "compound_pendulum" and "pinocchio differs" in r.note
               and "entry (0, 0)" in r.note for r in failed)


@pytest.mark.parametrize("case", ["compound_pendulum", "atwood"])
def test_rows_on_the_runs_engines_are_the_rows_of_a_fresh_load(case):
    """The derivative rows computed on the engines the run loaded (``reuse``: MuJoCo's with
    the case's cords enabled on Atwood's machine, Pinocchio's ``pinocchio-mjcf``) are those of
    engines loaded afresh from the case's MJCF — the expected values, an independent load:
    a run's couplings, step size and integrator leave an engine's smooth derivatives as
    they were."""
    from dyncheck.implementations import engines_as_read
    from dyncheck.slices import built

    spec = get_case(case)
    names = [*CORE, "pinocchio-mjcf", "drake"]
    impls = built(spec, names)
    reuse = engines_as_read(impls)
    assert {"mujoco", "pinocchio"} <= set(reuse)
    for impl in impls.values():  # a study's step set on every engine before the rows
        if not isinstance(impl, Exception) and impl.adapter is not None:
            impl.simulate(0.01, impl.integrators[0])

    def rows(**given):
        return sorted((r.quantity, r.impl_a, r.impl_b, r.verdict, repr(r.max_rel_err))
                      for r in derivative_rows(spec, CORE, 6, **given))

    fresh, again = rows(), rows(reuse=reuse)
    assert len(fresh) > 10
    assert again == fresh
