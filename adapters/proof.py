"""How a cause an engine's adapter can name is proved before a check page writes it as the
cause (#77: a cause is a counterfactual, measured). Each module that holds the text of a hint
declares, beside it, ``PROOFS``: each text's name → its :class:`Proof`. A test walks every
adapter module and holds each hint text to it."""

from __future__ import annotations

from enum import StrEnum


class Proof(StrEnum):
    """How one cause is proved."""

    FIX = "fix"
    """Its fix applied to a copy of the model, the copy read by the engine, the difference
    measured again (:class:`~dyncheck.adapters.model_tree.FixedReading`): "fix verified", or
    "cause unknown" with what the fix leaves."""
    MEASURED = "measured"
    """The engine's own measurement (:attr:`~dyncheck.adapters.model_tree.ModelTree.measured`):
    its own report of what it did, its converted plant, its reading in the written order, or
    a field its API does not hold."""
    PREDICTED = "predicted"
    """Its size predicted and compared with the difference on the row."""
    SUSPECTED = "suspected"
    """Its premise checked on the file only, its fix not yet measured: a page writes it as
    "cause unknown; suspected" (the work left)."""
