"""Which constraints each engine holds (#78): every closure of the canonical engine's reading
against another engine's reading of it — the same kind between the same joints, at the same
anchors, with the same held rotation, polynomial and lengths — as rows of the model-reading
section (a closure one engine drops or adds is a reading that differs)."""

from __future__ import annotations

import numpy as np

from dyncheck.adapters.closures import Closure
from dyncheck.adapters.model_tree import ModelTree
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.vocabulary import Verdict

BASIS = ("64 eps x reach (anchors), 64 eps (rotations, coefficients); eps the coarser "
         "arithmetic's")


def _ends(c: Closure) -> frozenset[str | None]:
    """What a closure ties: its two joints (a connect's or weld's), or its lengths' joints."""
    if c.first or c.second:
        return frozenset(n for n, _ in (*c.first, *c.second))
    return frozenset((c.joint1, c.joint2))


def _where(c: Closure) -> str:
    ends = sorted(str(e) if e is not None else "the world" for e in _ends(c))
    return f"{c.kind} between {' and '.join(ends)}" if len(ends) > 1 else \
        f"{c.kind} on {ends[0]}"


def _gap(mine: Closure, theirs: Closure, *, reach: float) -> tuple[float, str]:
    """The largest difference, relative, and the field it is in."""
    if theirs.joint1 != mine.joint1 and theirs.joint1 == mine.joint2:  # written the other way
        theirs = Closure(kind=theirs.kind, name=theirs.name, joint1=theirs.joint2,
                         joint2=theirs.joint1, point1=theirs.point2, point2=theirs.point1,
                         held=theirs.held.T, rotation_scale=theirs.rotation_scale)
    size = max(len(mine.polycoef), len(theirs.polycoef))
    gaps = {
        "polycoef": float(np.abs(np.pad(mine.polycoef, (0, size - len(mine.polycoef)))
                                 - np.pad(theirs.polycoef, (0, size - len(theirs.polycoef))))
                          .max(initial=0.0)),
        "lengths": 0.0 if (dict(mine.first), dict(mine.second)) == (dict(theirs.first),
                                                                    dict(theirs.second))
        else float("inf"),
    } if mine.first else {
        "anchor": max(float(np.abs(mine.point1 - theirs.point1).max()),
                      float(np.abs(mine.point2 - theirs.point2).max())) / reach,
        "rotation": float(np.abs(mine.held - theirs.held).max()),
    }
    field = max(gaps, key=lambda k: gaps[k])
    return gaps[field], field


def rows(model: str, canonical: ModelTree, tree: ModelTree, *, reach: float) -> list[CheckRow]:
    """The engine's reading of the closures against the canonical engine's (none for the
    canonical engine itself)."""
    if tree.engine == canonical.engine:
        return []
    theirs = list(tree.closures)
    tolerance = ROUNDOFF_FACTOR * max(EPS, tree.eps)  # (Newton holds its frames in float32)
    out = []

    def row(c: Closure, verdict: Verdict, note: str, *, error: float = 0.0,
            field: str = "closure") -> CheckRow:
        return CheckRow(model=model, section=Section.DESCRIPTION, subject=c.name, field=field,
                        impl_a=canonical.engine, impl_b=tree.engine, value_a="", value_b="",
                        error=error, tolerance=tolerance, basis=BASIS, verdict=verdict,
                        note=note)

    said = dict(tree.closures_unheld)
    for c in canonical.closures:
        match = next((t for t in theirs if t.kind == c.kind and _ends(t) == _ends(c)), None)
        if match is None:
            why = f" ({said[c.kind]})" if c.kind in said else ""
            out.append(row(c, Verdict.FAILED, f"{tree.engine} holds no {_where(c)} (the "
                           f"file's {c.name!r}){why}: its dynamics leave that constraint out",
                           error=float("inf")))
            continue
        theirs.remove(match)
        gap, field = _gap(c, match, reach=reach)
        out.append(row(c, Verdict.PASSED if gap <= tolerance else Verdict.FAILED,
                       f"{_where(c)} read alike" if gap <= tolerance else
                       f"{_where(c)}: its {field} differs", error=gap, field=f"closure {field}"))
    for extra in theirs:
        out.append(row(extra, Verdict.FAILED, f"{tree.engine} holds a {_where(extra)} that "
                       f"{canonical.engine} does not", error=float("inf")))
    return out
