"""Skipped rows stated once: an engine's limit on a case is one row, whatever number of
quantities and partners it leaves uncompared."""

from __future__ import annotations

import math
from dataclasses import replace

from dyncheck.results import Discrepancy
from dyncheck.vocabulary import Verdict


def _engine(note: str, rows: list[Discrepancy]) -> str:
    """The engine whose limit ``note`` states: the one of the rows' sides the note begins
    with (its own words: "newton: …", "pybullet does not compute it here: …") or names in
    quotes, else the first checked side."""
    sides = {side for r in rows for side in (r.impl_a, r.impl_b) if side}
    named = [s for s in sides if note.startswith((f"{s}:", f"{s} "))] or \
        [s for s in sides if f"'{s}'" in note]  # ("implementation 'NAME' needs …")
    if named:
        return max(named, key=len)
    return next((side for r in rows for side in (r.impl_b, r.impl_a) if side), "")


def once_per_case(rows: list[Discrepancy]) -> list[Discrepancy]:
    """``rows`` with the skipped rows of one case that give one reason merged into one: the
    engine whose limit it is as ``impl_b`` (no ``impl_a``: the row is the engine's, whatever
    partners a run had, so that a run of fewer engines finds it alike), the quantities (and
    the integrator and step where they are one) it leaves uncompared as ``quantity``. The
    other rows as they are, in their order."""
    out: list[Discrepancy] = []
    groups: dict[tuple[str, str], list[Discrepancy]] = {}
    for row in rows:
        if row.verdict != Verdict.SKIPPED:
            out.append(row)
        else:
            groups.setdefault((row.case, row.note), []).append(row)
    for (_, note), group in groups.items():
        engine = _engine(note, group)
        one = {(r.integrator, r.dt if not math.isnan(r.dt) else None) for r in group}
        integrator, dt = next(iter(one)) if len(one) == 1 else ("", None)
        out.append(replace(
            group[0], quantity=", ".join(sorted({r.quantity for r in group})),
            impl_a="", impl_b=engine, integrator=integrator,
            dt=math.nan if dt is None else dt))
    return out
