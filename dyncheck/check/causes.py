"""The causes behind a check page's explained rows: each row's label (``convention``), what
it is and whose property (:data:`~dyncheck.explain.explanations.EXPLANATIONS`), and the
conventions catalogue's entry and the tutorial that teach it — linked where the page sits
beside them (a page in ``reports/check/``), else named with the command that shows them."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from dyncheck.escaping import markdown, markdown_code
from dyncheck.explain.entry import TUTORIALS, tutorial_where
from dyncheck.explain.explanations import EXPLANATIONS
from dyncheck.vocabulary import Verdict

CATALOGUE = "conventions.md"
"""The conventions catalogue's page in a report folder (``dyncheck run`` writes it)."""
TUTORIALS_FOLDER = "tutorials"
"""The executed tutorials' folder in a report folder (``reports/tutorials``)."""
TUTORIALS_FOLDER_LINK = f"../{TUTORIALS_FOLDER}"


@dataclass(frozen=True, kw_only=True)
class Beside:
    """What a page's folder has beside it to link to: the catalogue's page and the rendered
    tutorials (their names), each relative to the page; nothing for a folder of its own."""

    catalogue: str = ""
    tutorials: frozenset[str] = frozenset()


def beside(out: Path) -> Beside:
    """The catalogue and tutorials one level above ``out`` (a check written into a report
    folder's ``check/``, as the committed ``reports/check``)."""
    up = out.parent
    catalogue = f"../{CATALOGUE}" if (up / CATALOGUE).is_file() else ""
    folder = up / TUTORIALS_FOLDER
    names = frozenset(p.stem for p in folder.glob("*.md")) if folder.is_dir() else frozenset()
    return Beside(catalogue=catalogue, tutorials=names)


def tutorial_of(label: str) -> str:
    """The tutorial that teaches the property ``label`` (its own, or its catalogue entry's),
    or empty."""
    known = EXPLANATIONS.get(label)
    if known is None:
        return ""
    return known.tutorial or TUTORIALS.get(known.entry, "")


def lines(rows: pd.DataFrame, there: Beside) -> list[str]:
    """The page's section on the causes of its explained rows (none where no row has one):
    one line per label, in the order the rows name them, with how many rows it explains."""
    if "convention" not in rows:
        return []
    explained = rows[(rows["verdict"] == Verdict.EXPLAINED)
                     & rows["convention"].fillna("").astype(str).ne("")]
    if explained.empty:
        return []
    counts = explained["convention"].value_counts(sort=False)
    out = ["## Causes of the explained rows", "",
           "Each is a property of an engine, of the book or of the mathematics (its line says "
           "whose), measured on the rows it explains; the catalogue entry that demonstrates "
           "it and the tutorial that teaches it are named where there are any.", ""]
    for label, n in counts.items():
        out.append(_line(str(label), int(n), there))
    return [*out, ""]


def _line(label: str, n: int, there: Beside) -> str:
    known = EXPLANATIONS.get(label)
    rows = f"{n} row" + ("s" if n != 1 else "")
    if known is None:
        return f"- **{markdown(label)}** ({rows}): not a registered property"
    said = [f"- **{markdown(label)}** ({rows}; whose property: {known.origin.value})"]
    if known.entry:
        command = markdown_code(f"dyncheck explain {known.entry}")
        said.append(f"catalogue entry [{known.entry}]({there.catalogue}#{known.entry}) "
                    f"({command})" if there.catalogue else f"catalogue entry {command}")
    tutorial = tutorial_of(label)
    if tutorial:
        said.append(f"tutorial [{tutorial}]({TUTORIALS_FOLDER_LINK}/{tutorial}.md)"
                    if tutorial in there.tutorials else
                    f"tutorial {markdown(tutorial_where(tutorial))}")
    return said[0] + (": " + "; ".join(said[1:]) if len(said) > 1 else "")
