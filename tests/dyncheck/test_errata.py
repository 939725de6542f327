"""The errata inventory of §2.2: complete (counted in the book file independently of the
parser), current (the committed copy and page match), and every erratum proved both ways —
its printed form's residual is not zero, its corrected form's is."""

from __future__ import annotations

import re

import pytest
import sympy as sp

from dyncheck.__main__ import main
from dyncheck.errata import cayley, checks, frenet, inventory, page, rotation

ROOT = inventory.STORED.parents[2]
BOOK_PRESENT = inventory.BOOK.is_file()
needs_book = pytest.mark.skipif(not BOOK_PRESENT, reason="the book file (../shared/book) is "
                                "not beside this clone; the committed inventory is used")


@needs_book
def test_every_displayed_formula_of_the_book_is_in_the_inventory():
    """Counted by splitting the file at ``$$`` (not by the parser's regular expression)."""
    text = inventory.BOOK.read_text(encoding="utf-8")
    displayed = text.count("$$") // 2
    _, formulas = inventory.load()
    assert sum(f.kind is inventory.Kind.DISPLAYED for f in formulas) == displayed == 136


@needs_book
def test_every_inline_relation_is_in_the_inventory():
    """Every ``$…$`` span with an ``=`` outside index ranges, found line by line."""
    text = inventory.BOOK.read_text(encoding="utf-8")
    spans = [s for line in text.splitlines()
             for s in re.sub(r"\$\$.*?\$\$", "", line).split("$")[1::2]]
    relations = [s for s in spans if "=" in re.sub(r"[a-z] = 1, (2, 3|\\dots, N)", "", s)]
    _, formulas = inventory.load()
    assert [f.text for f in formulas if f.kind is inventory.Kind.INLINE] == \
        [s.strip() for s in relations]


@needs_book
def test_committed_inventory_is_the_books():
    sha, formulas = inventory.load()
    assert inventory.stored() == (sha, formulas), "run inventory.dump to refresh inventory.json"


def test_ids_are_unique_and_in_book_order():
    _, formulas = inventory.stored()
    assert len({f.id for f in formulas}) == len(formulas)
    assert [f.line for f in formulas] == sorted(f.line for f in formulas)
    numbered = [f.number for f in formulas if f.number]
    assert numbered == [f"2.2.{n}" for n in range(1, 73)]  # every numbered equation, once


def test_every_check_names_a_formula_of_the_inventory():
    _, formulas = inventory.stored()
    assert set(checks.CHECKS) <= {f.id for f in formulas}


@pytest.mark.slow
@pytest.mark.parametrize("ident", sorted(checks.CHECKS))
def test_finding_carries_its_evidence(ident):
    finding = checks.CHECKS[ident]()
    assert finding.verdict is not checks.Verdict.PENDING and finding.evidence
    if finding.verdict is checks.Verdict.NOT_CHECKABLE:
        assert finding.method is checks.Method.NONE
    else:
        assert finding.method is not checks.Method.NONE


SLIPS = (checks.Verdict.ERRATUM, checks.Verdict.NOTATION)


@pytest.mark.slow
def test_the_action_integral_errata_are_found():
    """Derived by hand before the code (the issue's review): the Euler–Lagrange line of the
    action doubles ∂V's coefficient, and dt/dτ = √(mφ)/√(2(h−V)) is not a time rate."""
    found = {k for k, fn in checks.CHECKS.items() if fn().verdict in SLIPS}
    assert {"action-integral.d5", "action-integral.i3"} <= found


@pytest.mark.slow
@pytest.mark.parametrize("ident", sorted(checks.CHECKS))
def test_erratum_printed_form_fails_and_corrected_form_holds(ident):
    """Every check is parametrized (no derivation runs at collection): an erratum or a
    notation slip carries both residuals, printed ≠ 0 and corrected = 0; any other finding
    carries no correction."""
    finding = checks.CHECKS[ident]()
    if finding.verdict not in SLIPS:
        assert finding.corrected is None and finding.printed_residual is None
        return
    assert finding.corrected
    assert sp.simplify(finding.printed_residual()) != 0
    assert sp.simplify(finding.corrected_residual()) == 0


def test_explain_reruns_an_erratum(capsys):
    assert main(["explain", "erratum-action-integral.i3"]) == 0
    out = capsys.readouterr().out
    assert "residual of the corrected form: 0" in out and "def _action_time_change" in out


def test_explain_an_unknown_formula_is_one_line(capsys):
    assert main(["explain", "erratum-2.2.99"]) == 2
    assert "unknown formula '2.2.99'" in capsys.readouterr().err


@pytest.mark.slow
def test_committed_errata_page_is_current():
    assert (ROOT / "reports" / "errata.md").read_text() == page.page()


def test_frenet_check_rejects_a_wrong_sign():
    """Negative control: the numeric Frenet check fails on δB/δs = +τN (the sign flipped)
    and on δT/δs = 2κN, so its 'holds' verdicts could have failed."""
    f = frenet.frenet_frame()
    assert not frenet.vanishes(f["dB"] - f["tau"] * f["N"])
    assert not frenet.vanishes(f["dT"] - 2 * f["kappa"] * f["N"])


def test_every_formula_has_a_verdict():
    """No formula of the inventory is left without a check (the page's 'not yet checked' is
    empty)."""
    _, formulas = inventory.stored()
    assert [f.id for f in formulas if f.id not in checks.CHECKS] == []


def test_rotation_checks_reject_a_wrong_sign():
    """Negative controls for the exact machinery of the rotation checks: ω_z = ψ̇ − ϕ̇ cosθ
    (exercise 23 with a sign flipped) is not an identity; the velocity of a body point is not
    +ω_mk x_k (relative-motion.i5 with its sign flipped); and ω = αê₃ − βê₁ does not give a
    body point's velocity (the ex30 erratum's printed residual is not small)."""
    (t, ph, th, ps), _, product = rotation._euler()
    ell = product.T
    body = cayley.vee(ell.diff(t).T * ell)
    assert not rotation._trig_nil(sp.Matrix([body[2] - (ps.diff(t) - ph.diff(t) * sp.cos(th))]))
    ell = cayley.generic()
    x = ell * sp.Matrix(sp.symbols("c1:4"))
    assert not cayley.nil(x.diff(t) - ell * ell.diff(t).T * x)
    assert cayley.nil(x.diff(t) + ell * ell.diff(t).T * x)
    assert checks.CHECKS["ex30.i16"]().printed_residual() > 0.1


def test_the_exercise_18_erratum_is_dimensional():
    """Derived by hand: the Euler–Lagrange equations of φ = ds/dt give ẋⁱ s̈/ṡ on the right;
    a straight line run at speed 2√5 t, x = (t², 2t²), satisfies that and not ẋⁱ s̈."""
    finding = checks.CHECKS["ex18.i3"]()
    assert finding.verdict is checks.Verdict.ERRATUM
    assert r"\frac{d^2s/dt^2}{ds/dt}" in finding.corrected
    assert sp.simplify(finding.printed_residual() - (420 - 80 * sp.sqrt(5))) == 0
