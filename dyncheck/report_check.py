"""Is a report what the code computes? Two report folders compared on what matters.

Two runs of the same code on machines whose round-off differs (another CPU, another BLAS, a
reordered sum) give errors of ~1e-16 in other digits and, where several states tie at
round-off, another ``worst_state``; nothing in the results changed. A byte-for-byte check
would call that stale; this one does not, and still catches every change of a result:

- **tables** (``discrepancies.csv``, ``convergence.csv``, ``conservation.csv``), joined on
  their keys: the same rows on both sides; equal verdicts, conventions, nominal orders and
  asymptotic flags; errors equal within the row's *band* (below); observed orders within
  ±:data:`ORDER_BAND` where they are read (both steps of the pair asymptotic); the text of
  notes and tolerance bases equal once their numbers are compared as numbers;
  ``worst_state`` only where the error is above its band (below it every state ties);
- **pages** (Markdown), line by line: the same words, and every number equal to
  :data:`PROSE_RTOL` or both below :data:`PROSE_FLOOR` (a round-off figure);
- **figures** are drawn from the same numbers and are not compared pixel by pixel.

A row's band: its own tolerance where it has one (the round-off bound it was judged by, in
relative units); otherwise (order-study rows, judged by their order) the accumulated round-off
of the longest run, :data:`TRAJECTORY_FLOOR`, plus :data:`RELATIVE_BAND` of the value.

Rows of a float32 implementation (MJX, MuJoCo Warp: ``adapters.FLOAT32``) are held to the same
derivations with float32's ε: XLA and Warp compile for the CPU they run on (vector width, fused
multiply-adds), so two CPUs round a float32 run differently, and its trajectory errors,
drifts and the numbers printed from them agree only to the run's accumulated float32
round-off, :data:`TRAJECTORY_FLOOR32` (a page's table cell whose row or column names such an
implementation likewise). A tolerance derived from an error estimate (its basis says
"estimate") agrees to :data:`ESTIMATE_RTOL`: an adaptive solver's estimate moves when round-off
flips one of its step decisions.
"""

from __future__ import annotations

import io
import math
import re
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from dyncheck import diff
from dyncheck.errors import InvalidInput
from dyncheck.precision import EPS32
from dyncheck.results import CONVERGENCE_KEY, DISCREPANCY_KEY, texts
from dyncheck.tolerances import REFERENCE_MARGIN, accumulated


def _longest_run() -> int:
    """Steps of the longest fixed-step run of any case (16 000: torque_free, 4 s at 0.25 ms)."""
    from dyncheck.cases import CASES

    return max(
        round(c().trajectory.duration / min(dts))
        for c in CASES.values()
        for dts in c().trajectory.steps.values()
    )


TRAJECTORY_FLOOR = accumulated(_longest_run()).rtol
"""Accumulated round-off of the longest run (64 ε × steps, relative to the coordinates'
scale): two machines' errors of a run may differ by this much."""
TRAJECTORY_FLOOR32 = accumulated(_longest_run(), eps=EPS32).rtol
"""The same for a float32 run (64 ε₃₂ × 16 000 steps ≈ 0.12): the bound the run itself judges
a float32 trajectory by ("within accumulated round-off: 64 float32 eps x N steps")."""
ADAPTIVE = "dop853"
"""The integrator of the adaptive runs judged against their error estimates."""
ESTIMATE_RTOL = 0.25
"""Two machines' error estimates of the same adaptive run agree to this: |y(rtol) − y(rtol/4)|
estimates the error at rtol only to its own 1/4 part, and a step accepted on one machine and
rejected on the other moves it further by a fraction of itself (measured: 5 % on the spherical
pendulum's DOP853 at rtol 3.5e-8 between two CPUs)."""
RELATIVE_BAND = 1e-6
"""Of an error far above round-off (a truncation error, a modelling difference), the part two
machines may differ in: round-off of the trajectory relative to the error itself is < 1e-8."""
ORDER_BAND = 0.02
"""Observed orders of accuracy read in the asymptotic range agree to this."""
PROSE_RTOL = 1e-2
"""Numbers in pages and notes are printed to 3–4 significant digits."""
PROSE_FLOOR = 1e-10
"""A printed number below this is a round-off figure (the longest run accumulates
:data:`TRAJECTORY_FLOOR` ≈ 2e-11; the smallest modelling effect dyncheck explains is ~1e-9):
two such numbers agree whatever their digits."""
VOLATILE = ("| date (UTC)", "| dyncheck commit")
"""Provenance lines that change with every run without the results changing."""
PAGES_NOT_COMPARED = (
    "benchmark.md",
    "benchmark-suite.md",
    "benchmark-ports.md",
    "benchmark-check.md",
    "versions.md",
    "versions-newton-pybullet.md",
    "versions-models.md",
    "reliability.md",
    "errata.md",
)
"""Pages of the report folder that a run does not write (``dyncheck bench``, the scripts
under ``benchmarks/``, ``versions``, ``errata`` and the fault-table test do; each has its own
freshness check, the timings none: they are of this machine)."""
TABLES_NOT_COMPARED = ("benchmark.csv", "benchmark-suite.csv", "baseline.csv")

_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|\bnan\b|\binf\b")


@dataclass(frozen=True, kw_only=True)
class Moved:
    """One result that differs between the committed report and the run."""

    file: str
    key: str
    field: str
    old: str
    new: str

    def __str__(self) -> str:
        return f"{self.file}: {self.key}: {self.field} {self.old!r} -> {self.new!r}"


def _numbers_agree(a: float, b: float, rtol: float, floor: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if abs(a) <= floor and abs(b) <= floor:
        return True
    return abs(a - b) <= rtol * max(abs(a), abs(b))


def _skeleton(text: str) -> tuple[str, list[float]]:
    """The words of a line (white space and table rules folded) and its numbers."""
    numbers = [float(m) for m in _NUMBER.findall(text)]
    words = _NUMBER.sub("#", text)
    words = re.sub(r"\s+", "", words)
    return re.sub(r"-{2,}", "-", words), numbers


def text_moved(
    old: str, new: str, rtol: float = PROSE_RTOL, floor: float = PROSE_FLOOR
) -> str | None:
    """Why two texts differ beyond printed round-off, or None when they agree (numbers within
    ``rtol``, or both below ``floor``)."""
    if old == new:  # most of a report's lines, read again: no numbers to parse
        return None
    so, no = _skeleton(old)
    sn, nn = _skeleton(new)
    if so != sn or len(no) != len(nn):
        return "words"
    for a, b in zip(no, nn, strict=True):
        if not _numbers_agree(a, b, rtol, floor):
            return f"number {a:g} -> {b:g}"
    return None


def names_float32(text: str) -> bool:
    """Whether ``text`` names a float32 implementation (``mjx``, not ``mjx-f64``)."""
    from dyncheck.adapters import FLOAT32

    return any(word in FLOAT32 for word in re.split(r"[\s|,;:()\[\]]+", text))


def _cells(line: str) -> list[str]:
    return line.strip().strip("|").split("|")


def _table_row_moved(old: str, new: str, header: list[str]) -> str | None:
    """:func:`text_moved` of a table row, cell by cell, by the rules the tables it shows are
    compared by: numbers against the float32 floor where the row or the column names a float32
    implementation; an adaptive run's (``dop853``) to :data:`ESTIMATE_RTOL`; an observed order
    only in the asymptotic range (its row's ``asymptotic`` is True), as in ``convergence.csv``."""
    if _skeleton(old)[0] != _skeleton(new)[0]:
        return "words"
    a, b = _cells(old), _cells(new)
    if len(a) != len(b) or len(a) != len(header):
        return text_moved(old, new)
    names = [h.strip() for h in header]
    row32 = names_float32(old)
    rtol = ESTIMATE_RTOL if ADAPTIVE in old.split() else PROSE_RTOL
    unread = "asymptotic" in names and a[names.index("asymptotic")].strip() != "True"
    for x, y, column in zip(a, b, names, strict=True):
        if column == "observed_order" and unread:
            continue
        floor = TRAJECTORY_FLOOR32 if row32 or names_float32(column) else PROSE_FLOOR
        why = text_moved(x, y, rtol, floor)
        if why is not None:
            return why
    return None


def _is_rule(line: str) -> bool:
    return line.startswith("|") and set(line) <= set("|:- ")


def pages_moved(name: str, old: str, new: str) -> list[Moved]:
    keep = [line for line in old.splitlines() if not line.startswith(VOLATILE)]
    fresh = [line for line in new.splitlines() if not line.startswith(VOLATILE)]
    out = []
    header: list[str] | None = None  # the cells of the table the line is in
    for i, (a, b) in enumerate(zip(keep, fresh, strict=False)):
        if not a.startswith("|"):
            header = None
        elif i + 1 < len(keep) and _is_rule(keep[i + 1]):
            header = _cells(a)
        if a == b:
            continue
        tabled = header is not None and not _is_rule(a) and _cells(a) != header
        why = _table_row_moved(a, b, header) if tabled and header else text_moved(a, b)
        if why is not None:
            at = next((k for k, (x, y) in enumerate(zip(a, b, strict=False)) if x != y), 0)
            start = max(0, at - 20)
            out.append(
                Moved(
                    file=name,
                    key=f"line {i + 1}",
                    field=why,
                    old=a[start : start + 80],
                    new=b[start : start + 80],
                )
            )
            break  # later lines are shifted or follow from this one
    if not out and len(keep) != len(fresh):
        out.append(
            Moved(file=name, key="lines", field="count", old=str(len(keep)), new=str(len(fresh)))
        )
    return out


def _read(text: str) -> pd.DataFrame:
    return pd.read_csv(io.StringIO(text), keep_default_na=False, na_values=[""])


def _joined(
    name: str, old: str, new: str, key: list[str]
) -> tuple[list[Moved], pd.DataFrame, pd.DataFrame]:
    a, b = _read(old), _read(new)
    moved = []
    if list(a.columns) != list(b.columns):
        moved.append(
            Moved(
                file=name,
                key="",
                field="columns",
                old=str(list(a.columns)),
                new=str(list(b.columns)),
            )
        )
        return moved, a.iloc[:0], b.iloc[:0]
    p = diff.paired(a, b, key)
    for k in p.vanished:
        moved.append(Moved(file=name, key=k, field="row", old="present", new="vanished"))
    for k in p.appeared:
        moved.append(Moved(file=name, key=k, field="row", old="absent", new="appeared"))
    for k in p.repeated:
        moved.append(Moved(file=name, key=k, field="row", old="", new="duplicated"))
    return moved, p.a, p.b


def _floors(*impls: pd.Series) -> np.ndarray:
    """Per row: the accumulated round-off of the longest run in the precision of the less
    precise of its implementations."""
    from dyncheck.adapters import FLOAT32

    f32 = np.zeros(len(impls[0]), bool)
    for column in impls:
        f32 |= column.isin(FLOAT32).to_numpy()
    return np.where(f32, TRAJECTORY_FLOOR32, TRAJECTORY_FLOOR)


def _band(
    value_a: np.ndarray, value_b: np.ndarray, tolerance: np.ndarray, floor: np.ndarray
) -> np.ndarray:
    """Per row: its own tolerance, else the trajectory floor plus a relative part."""
    loose = floor + RELATIVE_BAND * np.fmax(np.abs(value_a), np.abs(value_b))
    return np.where(np.isfinite(tolerance), tolerance, loose)


def _within(a: np.ndarray, b: np.ndarray, band: np.ndarray) -> np.ndarray:
    """Equal within ``band``, both below it (round-off), or both NaN."""
    with np.errstate(invalid="ignore"):
        close = (np.abs(a - b) <= band) | ((np.abs(a) <= band) & (np.abs(b) <= band))
    return close | (np.isnan(a) & np.isnan(b))


def _fmt(x: object) -> str:
    return f"{x:.6g}" if isinstance(x, float) else str(x)


def _moved_rows(
    name: str, a: pd.DataFrame, b: pd.DataFrame, field: str, bad: np.ndarray
) -> list[Moved]:
    return [
        Moved(file=name, key=k, field=field, old=_fmt(a.at[k, field]), new=_fmt(b.at[k, field]))
        for k in a.index[bad]
    ]


def _labels_moved(name: str, a: pd.DataFrame, b: pd.DataFrame, fields: tuple) -> list[Moved]:
    out = []
    for field in fields:
        sa, sb = texts(a[field]), texts(b[field])
        out += _moved_rows(name, a, b, field, (sa != sb).to_numpy())
    return out


def _texts_moved(
    name: str, a: pd.DataFrame, b: pd.DataFrame, field: str, rtol: np.ndarray, floor: np.ndarray
) -> list[Moved]:
    sa, sb = texts(a[field]), texts(b[field])
    bad = [
        x != y and text_moved(x, y, r, f) is not None
        for x, y, r, f in zip(sa, sb, rtol, floor, strict=True)
    ]
    return _moved_rows(name, a, b, field, np.array(bad, bool))


def _col(frame: pd.DataFrame, field: str) -> np.ndarray:
    return frame[field].to_numpy(float)


def discrepancies_moved(name: str, old: str, new: str) -> list[Moved]:
    moved, a, b = _joined(name, old, new, DISCREPANCY_KEY)
    moved += _labels_moved(name, a, b, ("verdict", "convention"))
    floor = _floors(a["impl_a"], a["impl_b"])
    estimated = a["tolerance_basis"].fillna("").astype(str).str.contains("estimate").to_numpy()
    rtol = np.where(estimated, ESTIMATE_RTOL, PROSE_RTOL)
    prose_floor = np.where(floor > TRAJECTORY_FLOOR, floor, PROSE_FLOOR)
    moved += _texts_moved(name, a, b, "tolerance_basis", rtol, prose_floor)
    moved += _texts_moved(name, a, b, "note", np.full(len(a), PROSE_RTOL), prose_floor)
    tol_a, tol_b = _col(a, "tolerance"), _col(b, "tolerance")
    with np.errstate(invalid="ignore"):
        gap = np.abs(tol_a - tol_b)
        tol_ok = (
            (gap <= rtol * np.fmax(tol_a, tol_b))
            | (estimated & (gap <= floor))  # an estimate at round-off
            | (np.isnan(tol_a) & np.isnan(tol_b))
        )
    moved += _moved_rows(name, a, b, "tolerance", ~tol_ok)
    ea, eb = _col(a, "max_rel_err"), _col(b, "max_rel_err")
    band = _band(ea, eb, tol_a, floor)
    moved += _moved_rows(name, a, b, "max_rel_err", ~_within(ea, eb, band))
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(ea > 0, _col(a, "max_abs_err") / ea, 0.0)
    scale = np.nan_to_num(scale)
    abs_ok = _within(_col(a, "max_abs_err"), _col(b, "max_abs_err"), band * scale)
    moved += _moved_rows(name, a, b, "max_abs_err", ~abs_ok)
    with np.errstate(invalid="ignore"):
        located = np.fmin(ea, eb) > 2 * band  # below that, every state ties at round-off
    differs = (a["worst_state"].to_numpy() != b["worst_state"].to_numpy()) & located
    moved += _moved_rows(name, a, b, "worst_state", differs)
    return moved


def convergence_moved(name: str, old: str, new: str) -> list[Moved]:
    moved, a, b = _joined(name, old, new, CONVERGENCE_KEY)
    # coarsest step first: the order at a step pairs it with the coarser step before it
    a = a.sort_values(CONVERGENCE_KEY, ascending=[True, True, True, False])
    b = b.loc[a.index]
    floors = dict(zip(a.index, _floors(a["impl"]), strict=True))
    previous: dict[tuple[str, str, str], bool] = {}
    for k in a.index:
        ra, rb = a.loc[k], b.loc[k]
        run = (ra["case"], ra["impl"], ra["integrator"])
        for field in ("nominal_order", "asymptotic"):
            if str(ra[field]) != str(rb[field]):
                moved.append(
                    Moved(file=name, key=k, field=field, old=str(ra[field]), new=str(rb[field]))
                )
        ea, eb = float(ra["error"]), float(rb["error"])
        noise = REFERENCE_MARGIN * max(float(ra["reference_error"]), float(rb["reference_error"]))
        band = _band(np.array(ea), np.array(eb), np.array(math.nan), floors[k])
        if not (_within(np.array(ea), np.array(eb), band) or max(ea, eb) <= noise):
            moved.append(Moved(file=name, key=k, field="error", old=_fmt(ea), new=_fmt(eb)))
        asym = bool(ra["asymptotic"]) and bool(rb["asymptotic"])
        read = asym and previous.get(run, False)
        pa, pb = float(ra["observed_order"]), float(rb["observed_order"])
        if read and not abs(pa - pb) <= ORDER_BAND:
            moved.append(
                Moved(file=name, key=k, field="observed_order", old=_fmt(pa), new=_fmt(pb))
            )
        previous[run] = asym
    return moved


def conservation_moved(name: str, old: str, new: str) -> list[Moved]:
    moved, a, b = _joined(name, old, new, ["case", "impl", "integrator", "dt"])
    floor = _floors(a["impl"])
    for field in ("max_energy_drift", "max_momentum_drift"):
        x, y = _col(a, field), _col(b, field)
        nan = np.full(len(x), np.nan)
        moved += _moved_rows(name, a, b, field, ~_within(x, y, _band(x, y, nan, floor)))
    return moved


TABLES: dict[str, Callable[[str, str, str], list[Moved]]] = {
    "discrepancies.csv": discrepancies_moved,
    "convergence.csv": convergence_moved,
    "conservation.csv": conservation_moved,
}


RAN = "implementations"
"""The key of a run's ``provenance.json`` that lists the implementations it was asked for."""
IMPL_COLUMNS = ("impl", "impl_a", "impl_b")


def _implementations(table: pd.DataFrame) -> set[str]:
    return {str(x) for c in IMPL_COLUMNS if c in table.columns for x in table[c].dropna()}


def narrowed(
    old: Mapping[str, str], new: Mapping[str, str], ran: Collection[str]
) -> tuple[dict[str, str], dict[str, str], list[str]]:
    """A run of fewer implementations than the report ``old`` holds (the README's first
    command leaves out the engines built for accelerators), made comparable: ``old``'s tables
    cut to the rows whose implementations all ran, the pages of both sides left out (each sums
    up every implementation of its run), and the implementations of ``old`` not run. A run of
    every implementation ``old`` holds is returned as it is, with no implementation left out."""
    ran = set(ran)
    tables = {name: _read(text) for name, text in old.items() if name in TABLES}
    held = set().union(*(_implementations(t) for t in tables.values()))
    left_out = sorted(held - ran)
    if not left_out:
        return dict(old), dict(new), []
    cut = {}
    for name, t in tables.items():
        keep = np.ones(len(t), bool)
        for column in IMPL_COLUMNS:
            if column in t.columns:
                keep &= (t[column].isna() | t[column].astype(str).isin(ran)).to_numpy()
        cut[name] = t[keep].to_csv(index=False)
    return cut, {name: text for name, text in new.items() if name in TABLES}, left_out


def ran_in(folder: Path) -> list[str] | None:
    """The implementations a report folder's run was asked for (its ``provenance.json``), or
    None where it does not say (a report written before runs recorded it: every one)."""
    from dyncheck.diff import read_versions

    listed = read_versions(folder).get(RAN)
    return None if listed is None else [n for n in listed.split(", ") if n]


def compare(old: Mapping[str, str], new: Mapping[str, str]) -> list[Moved]:
    """What moved from the report ``old`` to the run ``new`` (file name → text; figures and
    the files a run does not write left out). Empty when they agree."""
    moved = []
    for name in sorted(new):
        if name not in old:
            moved.append(Moved(file=name, key="", field="file", old="missing", new="written"))
        elif name in TABLES:
            moved += TABLES[name](name, old[name], new[name])
        elif name.endswith(".md"):
            moved += pages_moved(name, old[name], new[name])
    for name in sorted(set(old) - set(new)):
        moved.append(Moved(file=name, key="", field="file", old="present", new="not written"))
    return moved


def read_report(folder: Path) -> dict[str, str]:
    """The tables and pages of a report folder that a run writes, as text."""
    out = {}
    for path in sorted(folder.glob("*")):
        if path.suffix not in (".csv", ".md") or path.name in (
            *PAGES_NOT_COMPARED,
            *TABLES_NOT_COMPARED,
        ):
            continue
        try:
            out[path.name] = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InvalidInput("report file", str(path), f"a readable UTF-8 text ({exc})") from None
    return out
