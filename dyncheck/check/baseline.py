"""A stored baseline of a check (``check --baseline FILE``): every row of the models checked,
with its two values, error, tolerance and verdict, under a header naming the versions that
made it (:func:`dyncheck.baseline.write_table`). A later check of the same models is held to
it row by row:

- ``regressed`` / ``improved``: the verdict got worse / better, or the error moved by more
  than the row's own tolerance (errors are relative and the tolerance is the round-off bound
  scaled by the model's conditioning, so a move beyond it is no round-off);
- ``value changed``: a reading (a gear, a count of joints, a mass) changed — as a number by
  more than the tolerance relative to its size, else as text;
- ``appeared`` / ``vanished``: a row, or a whole model, on one side only.

Unlike ``dyncheck diff`` (two runs, a factor above the tolerance), a baseline of one's own
model is held to the tolerance itself: the question is "did anything move?", not "how far".
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from dyncheck import baseline, diff
from dyncheck.errors import InvalidInput
from dyncheck.results import SEVERITY

FLAG = "--baseline"
KEY = diff.KEYS[diff.RunKind.CHECK]
COLUMNS = [*KEY, "value_a", "value_b", "error", "tolerance", "verdict"]


def table(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """The baseline table of a check's models (their rows, :data:`COLUMNS`, sorted)."""
    rows = pd.concat([t[COLUMNS] for t in tables.values()], ignore_index=True) if tables \
        else pd.DataFrame(columns=COLUMNS)
    return rows.sort_values(KEY, kind="stable").reset_index(drop=True)


def write(tables: dict[str, pd.DataFrame], path: Path, versions: dict[str, str]) -> None:
    baseline.write_table(table(tables), path, versions)


def load(path: Path) -> pd.DataFrame:
    """The baseline at ``path``, validated before any work: a one-line InvalidInput for a
    missing, unreadable, malformed or truncated file."""
    if path.is_dir() or not path.exists():
        raise InvalidInput(FLAG, str(path), "an existing check baseline CSV (write one with "
                           "--update-baseline)")
    frame = diff.read_csv(path, FLAG)
    missing = [c for c in COLUMNS if c not in frame.columns]
    if missing:
        raise InvalidInput(FLAG, str(path), f"a check baseline (missing {missing})")
    diff.tables(frame, diff.RunKind.CHECK, path=path, flag=FLAG)  # types, verdicts, keys
    expected = baseline.header(path).get("rows")
    if expected is not None and expected != str(len(frame)):
        raise InvalidInput(FLAG, str(path),
                           f"{expected} rows as its header says ({len(frame)} found: truncated?)")
    return texts(frame)


def texts(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with its pair's second engine and its two values as text, an empty cell
    as "" (a row of one implementation, a row without readings)."""
    frame = frame.copy()
    for col in ("value_a", "value_b", "impl_b"):
        frame[col] = frame[col].map(lambda x: "" if pd.isna(x) else str(x))
    return frame


def _number(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _value_moved(old: str, new: str, tol: float) -> bool:
    if old == new:
        return False
    a, b = _number(old), _number(new)
    if a is None or b is None:
        return True
    return abs(a - b) > tol * max(abs(a), abs(b), np.finfo(float).tiny)


def _move(old: pd.Series, new: pd.Series) -> tuple[diff.Move, str]:
    va, vb = str(old["verdict"]), str(new["verdict"])
    ea, eb = float(old["error"]), float(new["error"])
    tol = max(float(old["tolerance"]), float(new["tolerance"]))
    if SEVERITY[va] != SEVERITY[vb]:
        move = diff.Move.REGRESSED if SEVERITY[vb] > SEVERITY[va] else diff.Move.IMPROVED
        return move, f"verdict {va} -> {vb}"
    if math.isfinite(ea) != math.isfinite(eb):
        return ((diff.Move.REGRESSED, "error no longer finite") if math.isfinite(ea)
                else (diff.Move.IMPROVED, "error finite again"))
    if math.isfinite(ea) and abs(eb - ea) > tol:
        move = diff.Move.REGRESSED if eb > ea else diff.Move.IMPROVED
        return move, f"error {ea:.3e} -> {eb:.3e} (moved {abs(eb - ea):.1e} > tolerance {tol:.1e})"
    for side in ("value_a", "value_b"):
        if _value_moved(str(old[side]), str(new[side]), tol):
            return diff.Move.VALUE_CHANGED, f"{side} {old[side]} -> {new[side]}"
    return diff.Move.UNCHANGED, ""


def compare(current: pd.DataFrame, stored: pd.DataFrame) -> pd.DataFrame:
    """Every row that moved against the baseline: its model, ``row`` (its label and pair),
    ``move``, ``note``, and each side's verdict and error (``baseline``, ``current``)."""
    now = texts(current[COLUMNS])
    old, new = stored[COLUMNS].set_axis(diff.keys(stored, KEY)), now.set_axis(diff.keys(now, KEY))
    p = diff.paired(old, new)
    moves = [(k, diff.Move.VANISHED, f"row gone (was {old.loc[k, 'verdict']})")
             for k in p.vanished]
    moves += [(k, diff.Move.APPEARED, f"new row ({new.loc[k, 'verdict']})") for k in p.appeared]
    moves += [(k, *_move(p.a.loc[k], p.b.loc[k])) for k in p.a.index]
    out = [_line(old, new, k, move=move, note=note) for k, move, note in moves
           if move is not diff.Move.UNCHANGED]
    frame = pd.DataFrame(out, columns=["model", "row", "move", "note", "baseline", "current"])
    return frame.sort_values(["model", "row"], kind="stable").reset_index(drop=True)


def _line(old: pd.DataFrame, new: pd.DataFrame, key: str, *, move: diff.Move,
          note: str) -> dict[str, str]:
    def side(frame: pd.DataFrame) -> str:
        if key not in frame.index:
            return ""
        r = frame.loc[key]
        return f"{r['verdict']} {float(r['error']):.3e}"

    r = new.loc[key] if key in new.index else old.loc[key]
    pair = f"{r['impl_a']}/{r['impl_b']}" if r["impl_b"] else str(r["impl_a"])
    return {"model": str(r["model"]), "row": f"{r['section']} {r['subject']} {r['field']} {pair}",
            "move": move.value, "note": note, "baseline": side(old), "current": side(new)}


def versions_moved(path: Path, current: dict[str, str]) -> list[str]:
    """The libraries whose versions differ from the baseline's header."""
    return baseline.version_changes(path, current)


PAGE = "baseline"
"""The page (``baseline.md``) a check against a baseline writes beside the models' pages."""


def page(moved: pd.DataFrame, path: Path, versions: list[str], rows: int) -> str:
    """What moved against the baseline at ``path``, as Markdown: the versions that changed,
    then one line per moved row (escaped: names come from the user's files)."""
    from dyncheck.escaping import markdown, markdown_code, markdown_table

    changed = "; ".join(versions) if versions else (
        "none (a move is a change of the models or of dyncheck)")
    counts = moved["move"].value_counts()
    lines = [f"# Check against the baseline {markdown_code(path.name)}", "",
             f"{rows} rows checked against it; a row moved when its verdict changed, its "
             "error moved by more than its tolerance, a reading changed, or it appeared or "
             "vanished.", "",
             f"**Versions changed since the baseline:** {markdown(changed)}", "",
             "**Outcome: " + (f"{len(moved)} rows moved** ("
                              + ", ".join(f"{n} {m}" for m, n in counts.items()) + ")."
                              if len(moved) else "nothing moved**."), ""]
    if len(moved):
        lines.append(markdown_table(moved))
    return "\n".join(lines) + "\n"
