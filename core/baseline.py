"""Regression baselines: a stored long table, and what moved against it.

A baseline is ``discrepancies.csv``'s key columns with each row's error and verdict, written
for the pinned engine versions (``reports/baseline.csv``). A regression is any row whose
verdict changed, whose relative error moved by more than ``FACTOR`` (either way) where it
matters — the larger of the two exceeds the row's round-off tolerance, or the row is a
trajectory (judged by order, not by tolerance) — and any row that appeared or vanished.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from dyncheck.errors import InvalidInput
from dyncheck.results import DISCREPANCY_KEY, to_csv, write_atomic

COLUMNS = [*DISCREPANCY_KEY, "max_rel_err", "tolerance", "verdict"]
FACTOR = 10.0
"""An error that grows or shrinks by more than this factor is reported."""


def baseline_table(discrepancies: pd.DataFrame) -> pd.DataFrame:
    return discrepancies[COLUMNS].sort_values(DISCREPANCY_KEY, kind="stable").reset_index(drop=True)


def write(discrepancies: pd.DataFrame, path: Path) -> None:
    write_atomic(path, to_csv(baseline_table(discrepancies)))


def load(path: Path) -> pd.DataFrame:
    """The baseline at ``path``; a one-line InvalidInput for a missing or malformed file."""
    try:
        frame = pd.read_csv(path, keep_default_na=False, na_values=[""])
    except FileNotFoundError:
        raise InvalidInput("--baseline", str(path), "an existing baseline CSV file") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise InvalidInput("--baseline", str(path), f"a CSV file ({exc})") from None
    missing = [c for c in COLUMNS if c not in frame.columns]
    if missing:
        raise InvalidInput("--baseline", str(path), f"a dyncheck baseline (missing {missing})")
    try:
        frame["max_rel_err"] = frame["max_rel_err"].astype(float)
        frame["dt"] = frame["dt"].astype(float)
    except ValueError as exc:
        raise InvalidInput("--baseline", str(path), f"numeric errors and steps ({exc})") from None
    frame["integrator"] = frame["integrator"].fillna("").astype(str)
    return frame


def _key(frame: pd.DataFrame) -> pd.Series:
    dt = frame["dt"].map(lambda x: "" if pd.isna(x) else f"{x:.6e}")
    parts = [frame[c].astype(str) for c in DISCREPANCY_KEY if c != "dt"]
    out = parts[0]
    for p in parts[1:]:
        out = out + "|" + p
    return out + "|" + dt


def compare(
    current: pd.DataFrame, baseline: pd.DataFrame, *, cases: list[str] | None = None
) -> pd.DataFrame:
    """Rows that regressed: columns ``key, change, baseline, current``. ``cases`` restricts
    the baseline to the cases that were run."""
    if cases is not None:
        baseline = baseline[baseline["case"].isin(cases)]
    cur = current.assign(_k=_key(current)).set_index("_k")
    base = baseline.assign(_k=_key(baseline)).set_index("_k")
    out = []
    for k in sorted(set(base.index) - set(cur.index)):
        out.append((k, "vanished", base.loc[k, "verdict"], ""))
    for k in sorted(set(cur.index) - set(base.index)):
        out.append((k, "appeared", "", cur.loc[k, "verdict"]))
    for k in sorted(set(cur.index) & set(base.index)):
        b, c = base.loc[k], cur.loc[k]
        if b["verdict"] != c["verdict"]:
            out.append((k, "verdict changed", b["verdict"], c["verdict"]))
            continue
        eb, ec = float(b["max_rel_err"]), float(c["max_rel_err"])
        if not (np.isfinite(eb) and np.isfinite(ec)):
            continue
        tol = float(c["tolerance"]) if pd.notna(c["tolerance"]) else 0.0
        tiny = np.finfo(float).tiny
        ratio = max(eb, ec, tiny) / max(min(eb, ec), tiny)
        if ratio > FACTOR and max(eb, ec) > tol:
            out.append((k, f"error moved x{ratio:.3g}", f"{eb:.3e}", f"{ec:.3e}"))
    return pd.DataFrame(out, columns=["row", "change", "baseline", "current"])
