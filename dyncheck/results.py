"""Result records, the long tables they form, and atomic writing."""

from __future__ import annotations

import errno
import json
import os
import tempfile
from collections.abc import Iterable
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import pandas as pd

from dyncheck.vocabulary import SEVERITY, Verdict  # noqa: F401  (re-exported)

MEANINGS: dict[str, str] = {
    Verdict.PASSED: "the two sides agree within the row's tolerance, derived from its basis "
    "(round-off scaled by conditioning, an integrator's order, a finite difference's "
    "truncation, float32's ε)",
    Verdict.EXPLAINED: "the two sides differ by more than the tolerance, and the difference "
    "is a named property of an engine, of the book or of the mathematics (the row's "
    "`convention` and `note`) whose predicted size leaves a residual within the tolerance",
    Verdict.FAILED: "the two sides differ by more than the tolerance and nothing known "
    "predicts it: a finding",
    Verdict.SKIPPED: "not compared: an engine or extra is missing, refuses the model or does "
    "not offer the quantity (the `note` says which); never counted as passed",
}
"""What each verdict means, for the report's glossary and ``--help``."""

VERDICTS = tuple(v.value for v in Verdict)
NAN = float("nan")


@dataclass(frozen=True, kw_only=True)
class Discrepancy:
    """One case × quantity × pair of implementations (× integrator × step for trajectories).

    ``impl_a`` is the trusted side (``desired``), ``impl_b`` the one checked against it.
    Errors: ``max_abs_err`` in the quantity's units (book coordinates); ``max_rel_err`` divided
    by the quantity's scale (max |desired|). ``worst_state`` is the index of the sampled state
    (or, for trajectories, of the grid time) where the largest error occurred, and
    ``worst_state_values`` that state (book coordinates), to reproduce it.
    """

    case: str
    quantity: str
    impl_a: str
    impl_b: str
    integrator: str
    dt: float
    max_abs_err: float
    max_rel_err: float
    tolerance: float
    tolerance_basis: str
    verdict: str
    convention: str
    note: str
    worst_state: int
    worst_state_values: str = ""

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")

    @classmethod
    def measured(cls, *, case: str, quantity: str, impl_a: str, impl_b: str, error: float,
                 scale: float, tolerance: float, basis: str, verdict: str,
                 convention: str = "", note: str = "", integrator: str = "",
                 dt: float = NAN, worst_state: int = -1,
                 worst_state_values: str = "") -> Discrepancy:
        """A row with its error: ``error`` in the quantity's units, relative to ``scale``
        (its ``max_rel_err``); an instantaneous quantity has no integrator or step."""
        return cls(case=case, quantity=quantity, impl_a=impl_a, impl_b=impl_b,
                   integrator=integrator, dt=dt, max_abs_err=error,
                   max_rel_err=error / scale, tolerance=tolerance, tolerance_basis=basis,
                   verdict=verdict, convention=convention, note=note,
                   worst_state=worst_state, worst_state_values=worst_state_values)

    @classmethod
    def unmeasured(cls, *, case: str, quantity: str, impl_a: str, impl_b: str, verdict: str,
                   note: str, convention: str = "", integrator: str = "", dt: float = NAN,
                   tolerance: float = NAN, basis: str = "") -> Discrepancy:
        """A row with no error to show: skipped (its ``note`` says why), or failed before
        any number."""
        return cls(case=case, quantity=quantity, impl_a=impl_a, impl_b=impl_b,
                   integrator=integrator, dt=dt, max_abs_err=NAN, max_rel_err=NAN,
                   tolerance=tolerance, tolerance_basis=basis, verdict=verdict,
                   convention=convention, note=note, worst_state=-1)


@dataclass(frozen=True, kw_only=True)
class ConvergencePoint:
    """One step of an order-of-accuracy study: the max configuration error (rad) over the
    comparison grid against the reference of the implementation's own model."""

    case: str
    impl: str
    integrator: str
    dt: float
    error: float
    observed_order: float
    nominal_order: int
    reference_error: float
    asymptotic: bool


PROVENANCE = "provenance.json"
"""The file ``run`` and ``check`` write beside their tables: the versions that made them, for
``dyncheck diff`` (the pages show the same as a table)."""


def provenance_json(versions: dict[str, str]) -> str:
    """``versions`` as the text of :data:`PROVENANCE`."""
    return json.dumps(versions, indent=2, ensure_ascii=False) + "\n"


DISCREPANCY_KEY = ["case", "quantity", "impl_a", "impl_b", "integrator", "dt"]
CONVERGENCE_KEY = ["case", "impl", "integrator", "dt"]


def table(records: Iterable[Any], record_type: type, key: list[str]) -> pd.DataFrame:
    """Records as a DataFrame with the record's columns, sorted by ``key``."""
    columns = [f.name for f in fields(record_type)]
    frame = pd.DataFrame([asdict(r) for r in records], columns=columns)
    return frame.sort_values(key, kind="stable").reset_index(drop=True)


def _as_umask_gives(fd: int) -> None:
    """A temporary file (``mkstemp`` makes it 0600) given the mode a plainly created file
    would have: 0666 less the process's umask, so that CI artifacts and shared report folders
    are readable as the user set them up."""
    mask = os.umask(0o022)  # (read by setting: Python 3.11 has no os.get_umask)
    os.umask(mask)
    os.fchmod(fd, 0o666 & ~mask)


def within(out: Path, name: str) -> Path:
    """``out / name``, checked to be a file directly in ``out`` whatever ``name`` holds (an
    absolute name, a separator or ``..`` would leave the output folder: refused)."""
    path = out / name
    if path.parent != out or name in ("", ".", "..") or os.path.isabs(name):
        raise OSError(errno.EPERM, "an output name that leaves the output folder: not "
                      "written", str(path))
    return path


def write_atomic(path: Path, content: str | bytes) -> None:
    """Write to a temporary file in the same folder, then rename over ``path``; where the
    write fails, the temporary file and any folder made for it are removed again."""
    if path.is_symlink() or (path.exists() and not path.is_file()):  # (checked up front too)
        raise OSError(errno.EPERM, "not a regular file (a symlink or a special file): not "
                      "replaced", str(path))
    made = [p for p in (path.parent, *path.parent.parents) if not p.exists()]
    path.parent.mkdir(parents=True, exist_ok=True)
    mode = "wb" if isinstance(content, bytes) else "w"
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        _as_umask_gives(fd)
        with os.fdopen(fd, mode) as f:
            f.write(content)
        os.replace(tmp, path)
    except OSError as exc:  # a full disk or a size limit: named with the file it was writing
        if os.path.exists(tmp):
            os.unlink(tmp)
        for folder in made:  # innermost first
            if folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
        if exc.filename is None:
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_together(files: dict[Path, str | bytes]) -> None:
    """Write several files as one: each to a temporary file beside its target first, then —
    only once every one is written — each renamed over its target (a rename writes no data:
    no size limit or full disk can stop it half-way). A write that fails leaves every target
    as it was and no temporary file behind: a report is replaced as a whole or not at all."""
    staged: list[tuple[str, Path]] = []
    made: list[Path] = []
    try:
        for path, content in files.items():
            if path.is_symlink() or (path.exists() and not path.is_file()):
                raise OSError(errno.EPERM, "not a regular file (a symlink or a special file): "
                              "not replaced", str(path))
            made += [p for p in (path.parent, *path.parent.parents)
                     if not p.exists() and p not in made]
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
            staged.append((tmp, path))
            try:
                _as_umask_gives(fd)
                with os.fdopen(fd, "wb" if isinstance(content, bytes) else "w") as f:
                    f.write(content)
            except OSError as exc:
                if exc.filename is None:
                    raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
                raise
    except BaseException:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
        for folder in sorted(made, key=lambda p: len(p.parts), reverse=True):
            if folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
        raise
    for tmp, path in staged:
        os.replace(tmp, path)


def to_csv(frame: pd.DataFrame) -> str:
    """Deterministic CSV text: fixed float format, LF line ends, no text cell a spreadsheet
    would read as a formula (:func:`~dyncheck.escaping.csv_safe`)."""
    from dyncheck.escaping import csv_safe

    return csv_safe(frame).to_csv(index=False, float_format="%.6e", lineterminator="\n")


def texts(column: pd.Series) -> pd.Series:
    """A column read from a CSV as text, ``""`` where a cell is empty — also for a column
    that pandas read as floats because every cell of it was empty (filling a float column
    with a string is refused by pandas ≥ 4)."""
    return column.astype(object).where(column.notna(), "").astype(str)
