"""The rows of a model check, one record type for every section, and the check's result
(:class:`CheckResult`: its rows as a table, read by its page and the index)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

import pandas as pd

from dyncheck.vocabulary import Verdict


class Section(StrEnum):
    """Where a row comes from, in the order a report shows them."""

    LOAD = "load"
    DESCRIPTION = "description"
    VALIDITY = "validity"
    DYNAMICS = "dynamics"
    CLOSURES = "closures"
    ACTUATION = "actuation"
    DERIVATIVES = "derivatives"
    WITH_FIX = "with the fix"
    """An engine reading the file in part or otherwise, run on a copy with its fixes (#77)."""


@dataclass(frozen=True, kw_only=True)
class CheckRow:
    """One finding. ``subject`` is a joint (or body) name, a quantity, or ``model``; ``field``
    what was compared; ``impl_a`` the trusted side; errors relative to the quantity's scale
    where ``tolerance`` is relative (the basis says)."""

    model: str
    section: Section
    subject: str
    field: str
    impl_a: str
    impl_b: str
    value_a: str
    value_b: str
    error: float
    tolerance: float
    basis: str
    verdict: Verdict
    note: str
    convention: str = ""
    """An explained row's cause: the label (:mod:`dyncheck.labels`) of the property that
    explains it, which :data:`~dyncheck.explain.explanations.EXPLANATIONS` describes and
    links to its catalogue entry and tutorial; empty otherwise."""
    worst_state: int = -1
    accepted: str = ""
    """A failed row's acceptance (``--accept``): the known finding's reason; empty otherwise."""


WITH_FIX = "with the fix ({fix})"
"""How a "with the fix" row's note begins (``fix``: the fixes in words)."""
WITH_FIX_READING = "reading"
"""The field of a "with the fix" row that says how the engine reads the copy
(:mod:`.with_fix`)."""
COMPUTED = "max rel error"
"""The field of a row that compares computed values, the largest relative error over the
states (an actuation row's other fields compare readings)."""

COLUMNS = [
    "model", "section", "subject", "field", "impl_a", "impl_b", "value_a", "value_b", "error",
    "tolerance", "basis", "verdict", "note", "convention", "worst_state", "accepted",
]


def accepted(rows: pd.DataFrame) -> pd.Series:
    """Which rows an ``--accept`` entry accepts (a table without the column: none)."""
    if "accepted" not in rows:
        return pd.Series(False, index=rows.index)
    return rows["accepted"].fillna("").astype(str).ne("")


@dataclass(frozen=True, kw_only=True)
class CheckResult:
    """The rows of one model's check (a DataFrame, :data:`~dyncheck.check.rows.COLUMNS`)."""

    model: str
    path: Path
    rows: pd.DataFrame
    notes: tuple[str, ...]
    seconds: dict[str, float] = field(default_factory=dict)
    states: int = 0
    impls: tuple[str, ...] = ()
    """The implementations asked for (their versions are the page's provenance)."""

    @property
    def open_failures(self) -> pd.DataFrame:
        """The failed rows no ``--accept`` entry accepts (an accepted one stays failed: its
        verdict is the engines', the acceptance the user's)."""
        rows = self.rows
        return rows[(rows["verdict"] == Verdict.FAILED) & ~accepted(rows)]

    @property
    def ok(self) -> bool:
        return self.open_failures.empty

    def failures(self) -> str:
        failed = self.open_failures
        return "\n".join(
            f"{r.section} {r.subject} {r.field} {r.impl_a}/{r.impl_b}: {r.value_a} vs "
            f"{r.value_b} (error {r.error:.3g}) {r.note}"
            for r in failed.itertuples()
        )
