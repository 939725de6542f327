"""Regression baselines: a stored long table, and what moved against it.

A baseline is ``discrepancies.csv``'s key columns with each row's error and verdict, written
for the pinned engine versions (``reports/baseline.csv``). A regression is any row whose
verdict changed, whose relative error moved by more than ``FACTOR`` (either way) where it
matters — the larger of the two exceeds the row's round-off tolerance, or the row is a
trajectory (judged by order, not by tolerance) — and any row that appeared or vanished.
"""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path

import numpy as np
import pandas as pd

from dyncheck import diff
from dyncheck.errors import InvalidInput
from dyncheck.results import DISCREPANCY_KEY, texts, to_csv, write_atomic
from dyncheck.vocabulary import Verdict

COLUMNS = [*DISCREPANCY_KEY, "max_rel_err", "tolerance", "verdict"]
FACTOR = diff.FACTOR
"""An error that grows or shrinks by more than this factor is reported."""


def baseline_table(discrepancies: pd.DataFrame) -> pd.DataFrame:
    return discrepancies[COLUMNS].sort_values(DISCREPANCY_KEY, kind="stable").reset_index(drop=True)


HEADER = "# dyncheck baseline"


def write(discrepancies: pd.DataFrame, path: Path, versions: dict[str, str] | None = None) -> None:
    """The baseline CSV under a header line naming its row count (a file cut short at a line
    end is still found truncated) and the versions that made it (so that a later mismatch
    says whether the code or an engine changed)."""
    write_table(baseline_table(discrepancies), path, versions)


def write_table(table: pd.DataFrame, path: Path, versions: dict[str, str] | None) -> None:
    """Any baseline table (a run's, a check's) under its header line, written whole."""
    items = {"rows": str(len(table)), **(versions or {})}
    head = HEADER + " " + " ".join(f"{_word(k)}={_word(v)}" for k, v in items.items())
    write_atomic(path, head + "\n" + to_csv(table))


def _word(text: str) -> str:
    return text.replace(" ", "_")


def header(path: Path) -> dict[str, str]:
    """The items of a baseline's header line (``rows`` and the versions; empty without
    one)."""
    with path.open(encoding="utf-8", errors="replace") as f:
        first = f.readline()
    if not first.startswith(HEADER):
        return {}
    return dict(item.split("=", 1) for item in first[len(HEADER) :].split() if "=" in item)


def versions_of(path: Path) -> dict[str, str]:
    """The versions a baseline was made with (empty when its header names none)."""
    return {k: v for k, v in header(path).items() if k != "rows"}


def load(path: Path, flag: str = "--baseline") -> pd.DataFrame:
    """The baseline at ``path``, validated before any work: a one-line InvalidInput for a
    missing, unreadable or malformed file (columns, types, verdicts, a number wherever a
    verdict needs one, no duplicate keys)."""
    if path.is_dir():
        raise InvalidInput(flag, str(path), "a baseline CSV file, not a folder")
    if not path.exists():
        raise InvalidInput(flag, str(path), "an existing baseline CSV file")
    frame = diff.read_csv(path, flag)
    missing = [c for c in COLUMNS if c not in frame.columns]
    if missing:
        raise InvalidInput(flag, str(path), f"a dyncheck baseline (missing {missing})")
    try:
        for col in ("max_rel_err", "dt", "tolerance"):
            frame[col] = frame[col].astype(float)
    except ValueError as exc:
        raise InvalidInput(flag, str(path), f"numeric errors and steps ({exc})") from None
    for col in ("integrator", "impl_b"):  # empty cells: a row of one implementation
        frame[col] = texts(frame[col])
    diff.checked_signs(frame, ["max_rel_err", "tolerance"], flag=flag, path=path)
    diff.checked_keys(frame, DISCREPANCY_KEY, flag=flag, path=path)
    judged = frame["verdict"].isin([Verdict.PASSED, Verdict.EXPLAINED])
    nan = judged & ~np.isfinite(frame["max_rel_err"].to_numpy())
    if nan.any():
        row = int(np.flatnonzero(nan.to_numpy())[0]) + 1
        raise InvalidInput(
            flag,
            str(path),
            f"a finite max_rel_err on every passed or explained row (data row {row})",
        )
    expected = header(path).get("rows")
    if expected is not None and expected != str(len(frame)):
        raise InvalidInput(
            flag, str(path), f"{expected} rows as its header says ({len(frame)} found: truncated?)"
        )
    return frame


def compare(
    current: pd.DataFrame,
    baseline: pd.DataFrame,
    *,
    cases: list[str] | None = None,
    impls: Collection[str] | None = None,
) -> pd.DataFrame:
    """Rows that moved (:func:`dyncheck.diff.diff` at :data:`FACTOR`): columns ``row`` (its
    key), ``change`` (the move and why), ``baseline`` and ``current`` (verdict and error).
    ``cases`` and ``impls`` restrict the baseline to the cases and implementations that were
    run."""
    if cases is not None:
        baseline = baseline[baseline["case"].isin(cases)]
    if impls is not None:
        ran = [baseline[c].isna() | baseline[c].isin(impls) for c in ("impl_a", "impl_b")]
        baseline = baseline[ran[0] & ran[1]]
    here = Path("current run")
    old = diff.tables(baseline[COLUMNS], diff.RunKind.RUN, path=here, flag="--baseline")
    new = diff.tables(current[COLUMNS], diff.RunKind.RUN, path=here)
    table = diff.moved(diff.diff(old, new, factor=FACTOR))

    def side(s: str) -> pd.Series:
        err = table[f"error_{s}"].map(lambda x: f" {x:.3e}" if pd.notna(x) else "")
        return table[f"verdict_{s}"] + err

    return pd.DataFrame(
        {
            "row": diff.keys(table, DISCREPANCY_KEY).to_numpy(),
            "change": (table["move"].astype(str) + ": " + table["note"]).to_numpy(),
            "baseline": side("a").to_numpy(),
            "current": side("b").to_numpy(),
        }
    )


def version_changes(path: Path, current: dict[str, str]) -> list[str]:
    """Engines and libraries whose version differs from the baseline's header (none when the
    header records no versions)."""
    old = versions_of(path)
    return diff.version_changes(old, current) if old else []
