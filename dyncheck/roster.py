"""The implementations dyncheck compares, by name — importable without any engine or sympy
(``dyncheck list`` reads it in a fraction of a second)."""

from __future__ import annotations

from collections.abc import Collection

from dyncheck.adapters import ACCELERATORS, ENGINE_EXTRAS, RUN
from dyncheck.vocabulary import REFEREE

BOOK_SIDE: tuple[str, ...] = (REFEREE, "book")
"""The book's side: the general method (2.2.23)–(2.2.26) and the printed equations."""

IMPLEMENTATIONS: tuple[str, ...] = (*BOOK_SIDE, *RUN)
"""All implementation names, most trusted first: in a pair the earlier one is ``desired``.
The engines come in the order of their registration (:data:`dyncheck.adapters.RUN`)."""

ON_A_CPU: tuple[str, ...] = tuple(n for n in IMPLEMENTATIONS if n not in ACCELERATORS)
"""What ``dyncheck run`` runs by default: every implementation but the engines built for
accelerators (``--accelerators`` adds them)."""


def not_run(ran: Collection[str], command: str = "dyncheck run") -> str | None:
    """One line naming the implementations a run left out and how to add them, or None when
    it ran every one: the engines built for accelerators with their extras and the second
    command (``COMMAND --accelerators``), the others as left out by ``--impl``."""
    ports = [n for n in ACCELERATORS if n not in ran]
    others = [n for n in IMPLEMENTATIONS if n not in ran and n not in ports]
    said = []
    if ports:
        extras = ",".join(dict.fromkeys(ENGINE_EXTRAS[n] for n in ports))
        gpu = "; on a GPU add `--device cuda`" if command == "dyncheck run" else ""
        said.append(f"{', '.join(ports)} (built for accelerators: installed by the README's "
                    f"second command (extras {extras}), run by `{command} --accelerators`{gpu})")
    if others:
        said.append(f"{', '.join(others)} (left out by --impl)")
    return "not run: " + "; ".join(said) if said else None
