"""What moved between two runs: ``dyncheck diff RUN_A RUN_B``.

Two output folders of ``dyncheck run`` (their ``discrepancies.csv``) or of ``dyncheck check``
(one CSV per model) are joined on their keys. Each row's error is compared *relative to the
row's own tolerance*: two errors below the tolerance are the same result whatever their
digits (round-off differs between builds and machines); above it, an error that grew or shrank
by more than the factor (``--tolerance``, default 10) moved. Each row gets one :class:`Move`:

- ``regressed`` / ``improved``: the verdict got worse / better, or the error moved beyond the
  factor above the tolerance;
- ``definition changed``: a trajectory row whose change *vanishes with the step* — over the
  steps of one (case, quantity, pair, integrator) group the difference of the two errors falls
  as dt^p with p ≥ :data:`SCHEME_SLOPE`; a model or parser change would not vanish as dt → 0,
  a change of integration scheme (its truncation error is O(dt^p)) does;
- ``appeared`` / ``vanished``: a row present on one side only;
- ``unchanged``: everything else.

The exit status of the command is 1 when any row moved (``unchanged`` is the only quiet
answer: an improvement is a change a maintainer must see and accept as a new baseline).
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import BinaryIO

import numpy as np
import pandas as pd

from dyncheck.errors import InvalidInput
from dyncheck.escaping import markdown_code, markdown_table
from dyncheck.provenance import NOT_USED
from dyncheck.regular_files import NotRegular, Refusal, open_regular
from dyncheck.results import DISCREPANCY_KEY, PROVENANCE, SEVERITY, VERDICTS, texts

FACTOR = 10.0
"""Default factor an error must grow or shrink by, above its tolerance, to count as moved."""
SCHEME_SLOPE = 0.5
"""Least log-log slope of |Δerror| against dt that makes a change one of the scheme (a change
of definition of an order-p integrator gives slope ≈ p ≥ 1; a model change gives ≈ 0)."""


class RunKind(StrEnum):
    """Which command wrote a folder."""

    RUN = "run"
    CHECK = "check"


class Move(StrEnum):
    """How one row changed from run A to run B."""

    UNCHANGED = "unchanged"
    IMPROVED = "improved"
    REGRESSED = "regressed"
    DEFINITION_CHANGED = "definition changed"
    VALUE_CHANGED = "value changed"
    """A reading's value changed, its verdict and error did not (a check baseline)."""
    APPEARED = "appeared"
    VANISHED = "vanished"


KEYS = {
    RunKind.RUN: DISCREPANCY_KEY,
    RunKind.CHECK: ["model", "section", "subject", "field", "impl_a", "impl_b"],
}
ERROR = {RunKind.RUN: "max_rel_err", RunKind.CHECK: "error"}
_RANK = SEVERITY
"""Verdicts from best to worst: a verdict that moves right regressed."""


@dataclass(frozen=True, kw_only=True)
class RunTables:
    """One folder's rows (key columns, ``error``, ``tolerance``, ``verdict``) and versions."""

    path: Path
    kind: RunKind
    rows: pd.DataFrame
    versions: dict[str, str] = field(default_factory=dict)


def load(path: Path, flag: str) -> RunTables:
    """The rows of a ``run`` or ``check`` output folder (or one of their CSV files), validated:
    a one-line InvalidInput naming ``flag`` and the path for anything that is not one."""
    if not path.exists():
        raise InvalidInput(flag, str(path), "an existing output folder of `run` or `check`")
    if path.is_dir():
        disc = path / "discrepancies.csv"
        files = [disc] if disc.is_file() else sorted(  # a check's index is a summary
            f for f in path.glob("*.csv") if f.name != "index.csv")
        folder = path
    else:
        files, folder = [path], path.parent
    if not files:
        raise InvalidInput(flag, str(path), "a folder holding discrepancies.csv or check CSVs")
    frames = [read_csv(f, flag) for f in files]
    kinds = {_kind(f, frame, flag) for f, frame in zip(files, frames, strict=True)}
    if len(kinds) != 1:
        raise InvalidInput(flag, str(path), "the output of one command (run and check mixed)")
    kind = kinds.pop()
    rows = pd.concat(frames, ignore_index=True)
    return tables(rows, kind, path=path, flag=flag, versions=read_versions(folder))


def tables(
    rows: pd.DataFrame,
    kind: RunKind,
    *,
    path: Path,
    flag: str = "RUN",
    versions: dict[str, str] | None = None,
) -> RunTables:
    """A table of ``kind``'s columns (a run's discrepancies, a baseline, a check's rows) as
    :class:`RunTables`; InvalidInput naming ``flag`` for bad types, verdicts or keys."""
    normal = _normalise(rows, kind, flag, path)
    return RunTables(path=path, kind=kind, rows=normal, versions=versions or {})


TEXTS = {"value_a": str, "value_b": str}
"""Columns read as text whatever they hold (a reading "2" stays "2", never 2.0)."""


CSV_MOST = 1 << 30
"""The largest table read (``diff``, ``--baseline``): a check's rows are a few hundred bytes
each, a run's thousands of rows."""


@contextmanager
def regular_file(path: Path, flag: str, *, most: int) -> Iterator[BinaryIO]:
    """``path`` open for reading where it is a regular file of at most ``most`` bytes (opened
    without blocking, its kind read from the open file: a FIFO there hung ``diff`` and
    ``--baseline`` until killed), else a one-line InvalidInput naming ``flag``."""
    try:
        with open_regular(path, follow=True, most=most) as f:
            yield f
    except FileNotFoundError as exc:
        raise InvalidInput(flag, str(path), f"a readable file ({exc.strerror})") from None
    except NotRegular as exc:
        wanted = {Refusal.UNOPENABLE: f"a readable file ({exc.reason})",
                  Refusal.NOT_REGULAR: "a regular file (not a FIFO, device or socket)",
                  Refusal.TOO_LARGE: f"a file of at most {most >> 20} MiB (it has "
                                     f"{exc.size >> 20} MiB)"}[exc.refusal]
        raise InvalidInput(flag, str(path), wanted) from None


def read_csv(path: Path, flag: str) -> pd.DataFrame:
    """A CSV table of dyncheck's (``#`` lines are comments, empty cells NaN, :data:`TEXTS`
    as text); a one-line InvalidInput naming ``flag`` and the path when it cannot be read or
    parsed."""
    try:
        with regular_file(path, flag, most=CSV_MOST) as f:
            return pd.read_csv(f, keep_default_na=False, na_values=[""], comment="#",
                               dtype=TEXTS)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InvalidInput(flag, str(path), f"a CSV file ({reason})") from None
    except OSError as exc:
        raise InvalidInput(flag, str(path), f"a readable file ({exc.strerror})") from None


def _kind(path: Path, frame: pd.DataFrame, flag: str) -> RunKind:
    for kind in RunKind:
        if {*KEYS[kind], ERROR[kind], "tolerance", "verdict"} <= set(frame.columns):
            return kind
    raise InvalidInput(flag, str(path), "a discrepancies.csv of `run` or a CSV of `check`")


def _normalise(rows: pd.DataFrame, kind: RunKind, flag: str, path: Path) -> pd.DataFrame:
    key = KEYS[kind]
    out = rows[key].copy()
    for col in key:
        if col == "dt":
            out[col] = pd.to_numeric(out[col], errors="coerce")
        else:
            out[col] = texts(out[col])
    try:
        out["error"] = rows[ERROR[kind]].astype(float)
        out["tolerance"] = rows["tolerance"].astype(float).fillna(0.0)
    except ValueError as exc:
        raise InvalidInput(flag, str(path), f"numeric errors and tolerances ({exc})") from None
    checked_signs(out, ["error", "tolerance"], flag=flag, path=path)
    out["verdict"] = rows["verdict"].astype(str)
    out["_k"] = checked_keys(out, key, flag=flag, path=path)
    return out.set_index("_k")


def checked_signs(frame: pd.DataFrame, columns: list[str], *, flag: str, path: Path) -> None:
    """Errors and tolerances are sizes: a negative one (an edited file) would make every
    comparison pass, so it is refused naming the column and the first data row."""
    for col in columns:
        negative = frame[col].to_numpy() < 0
        if negative.any():
            row = int(np.flatnonzero(negative)[0]) + 1
            raise InvalidInput(flag, str(path), f"a {col} >= 0 on every row (data row {row}: "
                               "edited?)")


def checked_keys(frame: pd.DataFrame, key: list[str], *, flag: str, path: Path) -> pd.Series:
    """:func:`keys` of a table whose verdicts are all known and whose keys are unique; else a
    one-line InvalidInput naming the first bad data row."""
    bad = ~frame["verdict"].isin(VERDICTS)
    if bad.any():
        row = int(np.flatnonzero(bad.to_numpy())[0]) + 1
        value = frame["verdict"].iloc[row - 1]
        raise InvalidInput(
            flag, str(path),
            f"verdicts in {VERDICTS} (data row {row} has {value!r}: truncated or edited?)",
        )
    out = keys(frame, key)
    dup = out.duplicated()
    if dup.any():
        row = int(np.flatnonzero(dup.to_numpy())[0]) + 1
        raise InvalidInput(flag, str(path), f"one row per key (data row {row} repeats a key)")
    return out


def keys(frame: pd.DataFrame, key: list[str]) -> pd.Series:
    """One string per row joining its key columns — a number column (a step) to 7 digits, a
    text column as read, an empty cell as "" in either — the one key of a row for everything
    that compares two tables (``diff``, ``baseline``, ``report --check``)."""
    parts = [
        frame[c].map(lambda x: "" if pd.isna(x) else f"{x:.6e}")
        if frame[c].dtype.kind == "f"
        else texts(frame[c])
        for c in key
    ]
    out = parts[0]
    for p in parts[1:]:
        out = out + "|" + p
    return out


@dataclass(frozen=True, kw_only=True)
class Paired:
    """Two tables' rows matched on their key (:func:`keys`), keys sorted: ``a`` and ``b`` the
    rows of the keys both have once (same order), ``vanished`` / ``appeared`` the keys of one
    side only, ``repeated`` the keys a side has more than once (left out of the rest)."""

    a: pd.DataFrame
    b: pd.DataFrame
    vanished: list[str]
    appeared: list[str]
    repeated: list[str]


def paired(a: pd.DataFrame, b: pd.DataFrame, key: list[str] | None = None) -> Paired:
    """The one pairing of rows for everything that compares two tables (``diff``,
    ``baseline``, ``report --check``): tables indexed by :func:`keys` already (``key`` None)
    or keyed here on the columns ``key``."""
    if key is not None:
        a, b = a.set_axis(keys(a, key)), b.set_axis(keys(b, key))
    repeated = sorted(set(a.index[a.index.duplicated()]) | set(b.index[b.index.duplicated()]))
    ka, kb = set(a.index) - set(repeated), set(b.index) - set(repeated)
    common = sorted(ka & kb)
    return Paired(a=a.loc[common], b=b.loc[common], vanished=sorted(ka - kb),
                  appeared=sorted(kb - ka), repeated=repeated)


def read_versions(folder: Path) -> dict[str, str]:
    """The versions recorded in a folder's ``provenance.json`` (empty when it has none)."""
    path = folder / PROVENANCE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return {}
    return {str(k): str(v) for k, v in data.items()} if isinstance(data, dict) else {}


def version_changes(a: dict[str, str], b: dict[str, str]) -> list[str]:
    """``name old -> new`` for every library whose version differs (dates and commits left
    out, and engines one side did not use; names and values compared with spaces as
    underscores, as a baseline's header has them)."""

    def norm(d: dict[str, str]) -> dict[str, str]:
        return {k.replace(" ", "_"): v.replace(" ", "_") for k, v in d.items()}

    na, nb = norm(a), norm(b)
    skip = {"date_(UTC)", "dyncheck_commit", "implementations"}
    unused = NOT_USED.replace(" ", "_")
    names = [k for k in dict.fromkeys([*na, *nb])
             if k not in skip and unused not in (na.get(k), nb.get(k))]
    return [
        f"{k} {na.get(k, 'absent')} -> {nb.get(k, 'absent')}"
        for k in names
        if na.get(k) != nb.get(k)
    ]


def check_factor(factor: float) -> None:
    """``--tolerance`` must be a finite factor > 1 (NaN is not; infinity would let nothing
    move, a silent pass)."""
    if not 1.0 < factor < float("inf"):
        raise InvalidInput("--tolerance", factor, "a finite factor > 1")


def diff(a: RunTables, b: RunTables, *, factor: float = FACTOR) -> pd.DataFrame:
    """One row per key of either side: its key columns, ``error_a``, ``error_b``, ``ratio``
    (b / a), ``tolerance``, ``verdict_a``, ``verdict_b``, ``move`` and a ``note``."""
    if a.kind != b.kind:
        raise InvalidInput("RUN_B", str(b.path), f"the output of `{a.kind}`, like RUN_A")
    check_factor(factor)
    key = KEYS[a.kind]
    p = paired(a.rows, b.rows)  # keys unique on each side (refused on loading otherwise)
    joined = pd.concat([
        p.a.add_suffix("_a").join(p.b.add_suffix("_b")),
        a.rows.loc[p.vanished].add_suffix("_a"),
        b.rows.loc[p.appeared].add_suffix("_b"),
    ])
    for col in key:
        joined[col] = joined[f"{col}_a"].combine_first(joined[f"{col}_b"])
    tol = np.fmax(joined["tolerance_a"].to_numpy(), joined["tolerance_b"].to_numpy())
    ea, eb = joined["error_a"].to_numpy(), joined["error_b"].to_numpy()
    tiny = np.finfo(float).tiny
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.fmax(eb, tiny) / np.fmax(ea, tiny)
    moves, notes = [], []
    for i, (_, row) in enumerate(joined.iterrows()):
        move, note = _move(row, ea[i], eb[i], ratio[i], tol[i], factor)
        moves.append(move)
        notes.append(note)
    out = joined[key].copy()
    out["error_a"], out["error_b"], out["ratio"], out["tolerance"] = ea, eb, ratio, tol
    out["verdict_a"] = joined["verdict_a"].fillna("")
    out["verdict_b"] = joined["verdict_b"].fillna("")
    out["move"], out["note"] = moves, notes
    if a.kind is RunKind.RUN:
        out = _schemes(out, factor)
    return out.sort_values(key, kind="stable").reset_index(drop=True)


def _move(
    row: pd.Series, ea: float, eb: float, ratio: float, tol: float, factor: float
) -> tuple[Move, str]:
    va, vb = row["verdict_a"], row["verdict_b"]
    if pd.isna(va):
        return Move.APPEARED, f"new row ({vb})"
    if pd.isna(vb):
        return Move.VANISHED, f"row gone (was {va})"
    if _RANK[va] != _RANK[vb]:
        move = Move.REGRESSED if _RANK[vb] > _RANK[va] else Move.IMPROVED
        return move, f"verdict {va} -> {vb}"
    if not (np.isfinite(ea) and np.isfinite(eb)):
        if np.isfinite(ea) == np.isfinite(eb):
            return Move.UNCHANGED, ""
        return (Move.REGRESSED, "error no longer finite") if np.isfinite(ea) else (
            Move.IMPROVED, "error finite again")
    if max(ea, eb) <= tol:
        return Move.UNCHANGED, ""
    if ratio > factor:
        return Move.REGRESSED, f"error x{ratio:.3g}"
    if ratio < 1.0 / factor:
        return Move.IMPROVED, f"error x{ratio:.3g}"
    return Move.UNCHANGED, ""


def _schemes(out: pd.DataFrame, factor: float) -> pd.DataFrame:
    """Trajectory groups whose moved errors differ as dt^p, p ≥ SCHEME_SLOPE: a changed scheme."""
    traj = out["integrator"].astype(str).ne("") & out["dt"].notna()
    group = ["case", "quantity", "impl_a", "impl_b", "integrator"]
    for _, idx in out[traj].groupby(group, sort=False).groups.items():
        rows = out.loc[idx]
        if not rows["move"].isin([Move.REGRESSED, Move.IMPROVED]).any():
            continue
        delta = (rows["error_b"] - rows["error_a"]).abs().to_numpy()
        dt = rows["dt"].to_numpy(dtype=float)
        ok = np.isfinite(delta) & (delta > 0) & (dt > 0)
        if ok.sum() < 2 or np.unique(dt[ok]).size < 2:
            continue
        slope = float(np.polyfit(np.log(dt[ok]), np.log(delta[ok]), 1)[0])
        if slope >= SCHEME_SLOPE:
            moved = idx[out.loc[idx, "move"].ne(Move.UNCHANGED).to_numpy()]
            out.loc[moved, "move"] = Move.DEFINITION_CHANGED
            out.loc[moved, "note"] = (
                f"difference of errors ∝ dt^{slope:.2f} over {int(ok.sum())} steps: the "
                "integration scheme changed, not the model"
            )
    return out


def moved(table: pd.DataFrame) -> pd.DataFrame:
    """The rows that moved (everything but ``unchanged``)."""
    return table[table["move"].ne(Move.UNCHANGED)]


def summary(table: pd.DataFrame) -> dict[str, int]:
    """Rows per move, every move named (zeros included), in :class:`Move` order."""
    counts = table["move"].value_counts()
    return {m.value: int(counts.get(m, 0)) for m in Move}


def markdown(
    a: RunTables, b: RunTables, table: pd.DataFrame, *, factor: float, every: bool = False
) -> str:
    """The diff as a Markdown page: versions that changed, counts, then every moved row
    (``every``: every row)."""
    unrecorded = [markdown_code(t.path) for t in (a, b) if not t.versions]
    changes = version_changes(a.versions, b.versions) if not unrecorded else []
    versions = (
        f"not recorded in {' and '.join(unrecorded)}"
        if unrecorded
        else "; ".join(changes) or "none (a move is a change of dyncheck's code or inputs)"
    )
    counts = summary(table)
    shown = _display(table if every else moved(table), a.kind)
    lines = [
        f"# dyncheck diff: {markdown_code(a.path)} → {markdown_code(b.path)}",
        "",
        f"{len(table)} rows joined ({a.kind}); a row moved when its verdict changed or its "
        f"error, above its tolerance, changed by more than x{factor:g}.",
        "",
        f"**Versions changed:** {versions}",
        "",
        " · ".join(f"**{n}** {m}" for m, n in counts.items()),
        "",
    ]
    if shown.empty:
        lines.append("_nothing moved_")
    else:
        lines.append(markdown_table(shown))
    return "\n".join(lines) + "\n"


def _display(table: pd.DataFrame, kind: RunKind) -> pd.DataFrame:
    show = table.copy()
    show["pair"] = show["impl_a"] + " vs " + show["impl_b"]
    for col in ("error_a", "error_b", "ratio", "tolerance"):
        show[col] = show[col].map(lambda x: "" if pd.isna(x) else f"{x:.3e}")
    if kind is RunKind.RUN:
        show["dt"] = show["dt"].map(lambda x: "" if pd.isna(x) else f"{x:g}")
        cols = ["case", "quantity", "pair", "integrator", "dt"]
    else:
        cols = ["model", "section", "subject", "field", "pair"]
    return show[[*cols, "error_a", "error_b", "ratio", "move", "note"]]


def text(
    a: RunTables, b: RunTables, table: pd.DataFrame, *, factor: float, every: bool = False
) -> str:
    """The same as :func:`markdown`, for a terminal (Markdown reads as plain text)."""
    page = markdown(a, b, table, factor=factor, every=every)
    return re.sub(r"\*\*(.+?)\*\*", r"\1", page)
