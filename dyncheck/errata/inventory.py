"""The inventory of §2.2's formulas: every displayed formula (numbered or not), every relation
stated inline in the running text, every result an exercise states — each with a stable id,
its text as printed and its line in the book file.

Ids: a numbered display is its equation number (``2.2.22``); any other formula is the slug of
its part of the chapter (a heading, an example, an exercise) with ``d`` (display) or ``i``
(inline) and its order there (``action-integral.d3``, ``ex18.i4``). Inline ``$…$`` spans count
as relations when they hold ``=`` and are not an index range (``i = 1, 2, 3``).
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import asdict, dataclass
from enum import StrEnum
from pathlib import Path

BOOK = Path(__file__).resolve().parents[2].parent / "shared" / "book" / "dynamics-2.2.md"
"""The book file beside the repository (``../shared/book``), when present."""
STORED = Path(__file__).with_name("inventory.json")
"""The inventory as committed (read when the book file is not beside the repository)."""

HEADINGS = {
    "Particle Movement": "particle-movement",
    "Frenet-Serret Formulas": "frenet-serret",
    "Velocity and Acceleration": "velocity-acceleration",
    "Work and Potential Energy": "work",
    "Conservative Systems": "conservative",
    "Lagrange's Equations of Motion": "lagrange",
    "Euler-Lagrange Equations of Motion": "euler-lagrange",
    "Alternative Derivation of Lagrange's Equations of Motion": "variational",
    "Action Integral": "action-integral",
    "Dynamics of Rigid Body Motion": "rigid-body",
    "Relative Motion and Angular Velocity": "relative-motion",
    "Euler's Equations of Motion": "euler-equations",
    "EXERCISE 2.2": "exercises",
}
"""The chapter's headings as printed (each on a line of its own) and their slugs."""

DISPLAY = re.compile(r"\$\$(.+?)\$\$")
INLINE = re.compile(r"(?<!\$)\$([^$]+?)\$(?!\$)")
NUMBER = re.compile(r"\\(?:quad|tag)\s*\{?\(?(2\.2\.\d+)\)?\}?\s*$")
EXAMPLE = re.compile(r"^EXAMPLE (\d+)")
EXERCISE = re.compile(r"^\W*(?:►|▶)?\s*\**\s*(\d+)\.\**\s")


class Kind(StrEnum):
    DISPLAYED = "displayed"
    INLINE = "inline"


@dataclass(frozen=True, kw_only=True)
class Formula:
    """One formula of the book as printed."""

    id: str
    kind: Kind
    number: str | None
    part: str
    line: int
    text: str

    @property
    def in_exercise(self) -> bool:
        return is_exercise(self.part)


RANGES = re.compile(r"(?:^|,)\s*[a-z]\s*=\s*1\s*,\s*(?:2\s*,\s*3|\\dots\s*,\s*N)")


def is_exercise(part: str) -> bool:
    """A part that is one exercise (``ex18``), not an example (``example-8``)."""
    return re.fullmatch(r"ex\d+", part) is not None


def _is_relation(text: str) -> bool:
    """Holds ``=`` once index ranges (``i = 1, 2, 3``, ``r = 1, \\dots, N``) are taken out."""
    return "=" in RANGES.sub("", text)


def parse(text: str) -> list[Formula]:
    """Every displayed formula and every inline relation of ``text``, in book order."""
    part = heading = "section-2.2"
    counts: dict[tuple[str, Kind], int] = {}
    out: list[Formula] = []
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if stripped in HEADINGS:
            part = heading = HEADINGS[stripped]
        elif stripped.startswith("■") or stripped.endswith("■"):
            part = heading  # the example ended: back to the text around it
        elif m := EXAMPLE.match(stripped):
            part = f"example-{m.group(1)}"
        elif (part == "exercises" or is_exercise(part)) and (m := EXERCISE.match(stripped)):
            part = f"ex{m.group(1)}"
        for kind, found in ((Kind.DISPLAYED, DISPLAY.findall(line)),
                            (Kind.INLINE, INLINE.findall(DISPLAY.sub("", line)))):
            for body in found:
                if kind is Kind.INLINE and not _is_relation(body):
                    continue
                eq = NUMBER.search(body)
                key = (part, kind)
                counts[key] = counts.get(key, 0) + 1
                ident = eq.group(1) if eq else f"{part}.{kind.value[0]}{counts[key]}"
                out.append(Formula(id=ident, kind=kind, number=eq.group(1) if eq else None,
                                   part=part, line=number, text=body.strip()))
    return out


def digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def stored() -> tuple[str, list[Formula]]:
    """The committed inventory (``inventory.json``)."""
    data = json.loads(STORED.read_text(encoding="utf-8"))
    return data["sha256"], [Formula(**{**f, "kind": Kind(f["kind"])}) for f in data["formulas"]]


def load() -> tuple[str, list[Formula]]:
    """(the book's SHA-256, the inventory): parsed from the book file where it is beside the
    repository, else the committed copy."""
    if BOOK.is_file():
        text = BOOK.read_text(encoding="utf-8")
        return digest(text), parse(text)
    return stored()


def dump(sha: str, formulas: list[Formula]) -> str:
    return json.dumps({"book": "dynamics-2.2.md", "sha256": sha,
                       "formulas": [asdict(f) for f in formulas]}, ensure_ascii=False,
                      indent=1) + "\n"
