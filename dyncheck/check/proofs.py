"""A reading's cause proved by its fix (#77): an engine's hint names why it reads a field
otherwise and how to change that; where the engine read a copy of the model with that fix
applied (:class:`~dyncheck.adapters.model_tree.FixedReading`), the difference is measured
again on the copy. The note then says "fix verified" with what the copy reads, or, where the
fix leaves part of the difference, how much it accounts for and that the rest has no known
cause. A hint whose fix was not measured is left as the engine's hint."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

from dyncheck.adapters.model_tree import ModelTree

VERIFIED = "fix verified: with {fix}, {engine} {outcome}"
UNVERIFIED = "cause unknown; suspected, its fix not measured: {why}"
REFUSED = "cause unknown: {engine} refused the copy with the named fix ({fix}): {refused}"
PART = ("cause unknown: the named fix ({fix}) accounts for {share} of the difference; "
        "{engine} still {outcome}")
FIX_VERIFIED = "fix verified"
"""The words every proved cause carries (the check pages and their tests find them)."""


class Standing(StrEnum):
    """Where a row's cause stands, read from its note (:func:`standing`)."""

    VERIFIED = "fix verified"
    SHORT = "fix measured, gap left: cause unknown"
    SUSPECTED = "suspected, fix not measured"
    UNNAMED = "no cause named, or the engine's own measurement or prediction"


def standing(note: str) -> Standing:
    """How the cause in a row's ``note`` was proved, by the words :func:`proved` writes."""
    if UNVERIFIED.split("{")[0] in note:
        return Standing.SUSPECTED
    if PART.split("(")[0] in note or "refused the copy with the named fix" in note:
        return Standing.SHORT
    if f"; {FIX_VERIFIED}: with " in note:
        return Standing.VERIFIED
    return Standing.UNNAMED


@dataclass(frozen=True, kw_only=True)
class Remeasured:
    """A difference measured again on the fixed copy: whether it is within its bound there,
    what the copy reads in words, and the error left relative to the error before (0 where
    closed; 1 where the fix changed nothing)."""

    closed: bool
    outcome: str
    left: float = 0.0


def proved(tree: ModelTree, subject: str, field: str, *,
           measure: Callable[[ModelTree], Remeasured]) -> str | None:
    """The note of a difference that ``tree``'s hint for (``subject``, ``field``) explains
    (None where it gives none): the hint where the engine proved it by its own measurement
    (:attr:`ModelTree.measured`); the hint and its fix verified where ``measure`` finds the
    difference closed on the fixed copy; "cause unknown" with what the fix leaves where it
    does not; "cause unknown", the hint only suspected, where no fix was measured."""
    why = tree.hint(subject, field)
    if why is None or why in tree.measured:
        return why
    reading = tree.fixed_reading(subject, field)
    if reading is None:
        return UNVERIFIED.format(why=why)
    if reading.tree is None:
        return REFUSED.format(engine=tree.engine, fix=reading.fix, refused=reading.refused)
    again = measure(reading.tree)
    if again.closed:
        return f"{why}; " + VERIFIED.format(fix=reading.fix, engine=tree.engine,
                                            outcome=again.outcome)
    share = 100 * max(0.0, 1.0 - again.left)  # (all but a sliver: how much is left, not "100 %")
    shown = f"{share:.0f} %" if share < 99.5 else f"all but {again.left:.2g}"
    return PART.format(fix=reading.fix, share=shown, engine=tree.engine, outcome=again.outcome)


def unmeasured(tree: ModelTree, subject: str, field: str) -> str | None:
    """``tree``'s hint for (``subject``, ``field``) where no fixed reading can measure it
    (a field the fixed copy does not compare): the hint where the engine measured it, else
    "cause unknown", the hint only suspected; None where it gives none."""
    why = tree.hint(subject, field)
    if why is None or why in tree.measured:
        return why
    return UNVERIFIED.format(why=why)
