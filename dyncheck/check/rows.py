"""The rows of a model check, one record type for every section."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from dyncheck.results import Verdict


class Section(StrEnum):
    """Where a row comes from, in the order a report shows them."""

    LOAD = "load"
    DESCRIPTION = "description"
    VALIDITY = "validity"
    DYNAMICS = "dynamics"
    ACTUATION = "actuation"
    DERIVATIVES = "derivatives"


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
    worst_state: int = -1


COMPUTED = "max rel error"
"""The field of a row that compares computed values, the largest relative error over the
states (an actuation row's other fields compare readings)."""

COLUMNS = [
    "model", "section", "subject", "field", "impl_a", "impl_b", "value_a", "value_b", "error",
    "tolerance", "basis", "verdict", "note", "worst_state",
]
