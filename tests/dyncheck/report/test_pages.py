"""The report's first page (report/pages.py): it links every other committed page and its
glossary covers every tolerance basis the committed rows give.

Expected values: the committed ``reports/`` folder (what a reader opens), read directly."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from dyncheck.report.pages import PAGES
from dyncheck.results import MEANINGS, Verdict
from dyncheck.tolerances import basis_term

REPORTS = Path(__file__).resolve().parents[3] / "reports"
CASE_PAGES = {f"{name}.md" for name in set(pd.read_csv(REPORTS / "discrepancies.csv")["case"])}
"""The committed report's case pages: one per case its rows hold (those it was run on, the
built-in ones; a case a package adds has no committed page)."""


def test_every_committed_page_is_linked_from_the_first_page():
    linked = {link for _, link, _ in PAGES}
    pages = {p.name for p in REPORTS.glob("*.md")} - CASE_PAGES - {"README.md"}
    assert pages <= linked, f"not in PAGES: {sorted(pages - linked)}"
    assert all((REPORTS / link).is_file() for link in linked), "a link to no page"
    first = (REPORTS / "README.md").read_text()
    head = first[: first.index("### Provenance")]  # the contents are at the top
    assert all(f"]({link})" in head for link in linked | CASE_PAGES)


def test_every_verdict_has_a_meaning():
    assert set(MEANINGS) == set(Verdict)


@pytest.mark.parametrize("basis", sorted(set(
    pd.read_csv(REPORTS / "discrepancies.csv")["tolerance_basis"].dropna())))
def test_every_committed_tolerance_basis_is_in_the_glossary(basis):
    assert basis_term(basis) is not None, basis
