"""The implementations dyncheck compares, by name — importable without any engine or sympy
(``dyncheck list`` reads it in a fraction of a second)."""

from __future__ import annotations

from dyncheck.adapters import RUN

BOOK_SIDE: tuple[str, ...] = ("reference", "book")
"""The book's side: the general method (2.2.23)–(2.2.26) and the printed equations."""

IMPLEMENTATIONS: tuple[str, ...] = (*BOOK_SIDE, *RUN)
"""All implementation names, most trusted first: in a pair the earlier one is ``desired``.
The engines come in the order of their registration (:data:`dyncheck.adapters.RUN`)."""
