"""Results a CI system reads: JUnit XML (``--junit FILE``: one test suite per case or model,
one test case per group of rows — a quantity of one pair of implementations — failed with its
two values and its cause, an explained row's cause in the test case's system-out, skipped with
its reason, each suite and test case with the seconds its engines took where the command
measured them) and a JSON summary (``--json FILE``, ``--json -`` for standard output: the
counts, each suite's counts and every row, in the format :data:`SCHEMA` describes), for
``run`` and ``check`` alike. Written with ``junitparser`` (a maintained JUnit library) and
``json``; each file whole, then renamed.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TextIO

import pandas as pd
from junitparser import Failure, JUnitXml, Skipped, TestCase, TestSuite

from dyncheck.check.rows import accepted as accepted_rows
from dyncheck.results import Verdict, write_atomic


@dataclass(frozen=True, kw_only=True)
class Columns:
    """Where a results table keeps what a test case needs (``run`` and ``check`` differ)."""

    suite: str
    group: tuple[str, ...]
    error: str
    tolerance: str
    detail: tuple[str, ...]
    values: tuple[str, str] | None = None
    """The two compared values, where the rows keep them (a reading: "1.45 vs 1.51")."""


RUN = Columns(suite="case", group=("quantity", "impl_a", "impl_b", "integrator", "dt"),
              error="max_rel_err", tolerance="tolerance", detail=("tolerance_basis", "note"))
CHECK = Columns(suite="model", group=("section", "subject", "impl_a", "impl_b"),
                error="error", tolerance="tolerance", detail=("field", "basis", "note"),
                values=("value_a", "value_b"))

@dataclass(frozen=True, kw_only=True)
class Moves:
    """A check against a stored baseline: its file, the versions that changed since, and
    the rows that moved (:func:`dyncheck.check.baseline.compare`'s table)."""

    file: str
    versions_changed: tuple[str, ...]
    rows: pd.DataFrame


SCHEMA = "results.schema.json"
"""The JSON Schema of ``--json`` (in this package; ``schema_version`` names its version)."""
SCHEMA_VERSION = 1


def _text(value: object) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return str(value)


def _name(keys: tuple[object, ...], columns: tuple[str, ...]) -> str:
    parts = {c: _text(k) for c, k in zip(columns, keys, strict=True)}
    pair = " vs ".join(p for p in (parts.pop("impl_a", ""), parts.pop("impl_b", "")) if p)
    rest = " ".join(v for v in parts.values() if v)
    return f"{rest} ({pair})" if pair else rest


def _nonzero(value: object) -> bool:
    """An error worth printing beside two values: a number other than zero (a reading's
    rows carry 0: the values are the finding)."""
    try:
        return float(str(value)) != 0.0
    except (TypeError, ValueError):
        return bool(_text(value))


def _failure(values: dict[str, object], columns: Columns) -> str:
    """A failed row in one line that leads with what a reader compares: the two values
    where the row has them ("1.45 vs 1.51"), else the error against its tolerance; then the
    field, basis and cause."""
    detail = "; ".join(_text(values.get(c)) for c in columns.detail if _text(values.get(c)))
    error, tolerance = _text(values.get(columns.error)), _text(values.get(columns.tolerance))
    pair = [_text(values.get(c)) for c in columns.values or ()]
    if pair and all(pair):
        head = f"{pair[0]} vs {pair[1]}"
        if _nonzero(values.get(columns.error)):
            head += f" (error {error}, tolerance {tolerance})"
    else:
        head = f"error {error} > tolerance {tolerance}"
    return head + (f": {detail}" if detail else "")


def _case(name: str, suite: str, rows: pd.DataFrame, columns: Columns, *,
          seconds: float | None = None) -> TestCase:
    case = TestCase(name, classname=f"dyncheck.{suite}", time=seconds)
    accepted = accepted_rows(rows)
    failed = rows[(rows["verdict"] == Verdict.FAILED.value) & ~accepted]
    explained = rows[rows["verdict"] == Verdict.EXPLAINED.value]
    said = ["explained: " + "; ".join(_text(v) for c in columns.detail
                                      if _text(v := row._asdict().get(c)))
            for row in explained.itertuples(index=False)]
    said += [f"accepted: {_failure(row._asdict(), columns)} — {row.accepted}"
             for row in rows[accepted].itertuples(index=False)]
    if said:
        case.system_out = "\n".join(said)
    if not failed.empty:
        lines = [_failure(row._asdict(), columns) for row in failed.itertuples(index=False)]
        case.result = [Failure(lines[0], "dyncheck")]
        case.result[0].text = "\n".join(lines)
    elif (rows["verdict"] == Verdict.SKIPPED.value).all():
        reason = "; ".join(dict.fromkeys(_text(n) for n in rows["note"] if _text(n)))
        case.result = [Skipped(reason or Verdict.SKIPPED)]
    return case


WHOLE = "*"
"""The key of a suite's seconds measured as a whole (a run's case: its units of work), which
its test cases share equally."""


def _shares(keys: list[tuple[object, ...]], columns: Columns,
            took: dict[str, float] | None) -> list[float | None]:
    """Each group's share of the measured seconds: every engine's time on the model split
    equally among the groups that compare it, so that a suite's test cases add up to the time
    its engines took (None where the command measured none); a suite measured as a whole
    (:data:`WHOLE`) split equally among its groups."""
    if not took:
        return [None] * len(keys)
    if WHOLE in took:
        return [round(took[WHOLE] / len(keys), 6)] * len(keys)
    pairs = [[i for i in (_text(dict(zip(columns.group, k, strict=True)).get(c))
                          for c in ("impl_a", "impl_b")) if i in took] for k in keys]
    groups = {e: sum(e in p for p in pairs) for e in took}
    return [round(sum(took[e] / groups[e] for e in p), 6) if p else None for p in pairs]


def _baseline_suite(moves: Moves) -> TestSuite:
    """One failed test case per row that moved against the baseline (one passed test case
    where nothing moved)."""
    suite = TestSuite("baseline")
    for row in moves.rows.itertuples(index=False):
        case = TestCase(f"{row.model}: {row.row}", classname="dyncheck.baseline")
        case.result = [Failure(f"{row.move}: {row.note}", "moved")]
        suite.add_testcase(case)
    if moves.rows.empty:
        suite.add_testcase(TestCase(f"nothing moved against {moves.file}",
                                    classname="dyncheck.baseline"))
    suite.update_statistics()
    return suite


def junit(tables: dict[str, pd.DataFrame], columns: Columns,
          refused: dict[str, str] | None = None, *,
          seconds: dict[str, dict[str, float]] | None = None,
          moves: Moves | None = None) -> JUnitXml:
    """One suite per table (a case, a model), one test case per group of rows; a refused
    model (bad input: no rows) one suite of one failed test case, its reason the message.
    ``seconds``: per suite, the seconds each engine (and step) took, where measured — a test
    case's time is its share of its engines' (:func:`_shares`), a suite's the sum of its test
    cases' (the JSON summary has each suite's whole time)."""
    xml = JUnitXml("dyncheck")
    for name, why in (refused or {}).items():
        if name in tables:
            continue
        suite = TestSuite(name)
        case = TestCase("refused", classname=f"dyncheck.{name}")
        case.result = [Failure(_text(why), "refused")]
        suite.add_testcase(case)
        suite.update_statistics()
        xml.add_testsuite(suite)
    for suite_name, rows in tables.items():
        suite = TestSuite(suite_name)
        groups = [(tuple(k), g) for k, g in rows.groupby(list(columns.group), sort=False,
                                                          dropna=False)]
        shares = _shares([k for k, _ in groups], columns, (seconds or {}).get(suite_name))
        for (keys, group), share in zip(groups, shares, strict=True):
            suite.add_testcase(_case(_name(keys, columns.group), suite_name, group, columns,
                                     seconds=share))
        suite.update_statistics()
        xml.add_testsuite(suite)
    if moves is not None:
        xml.add_testsuite(_baseline_suite(moves))
    xml.update_statistics()
    return xml


def split(rows: pd.DataFrame, columns: Columns) -> dict[str, pd.DataFrame]:
    """A table of every case's or model's rows, one table each (in their order)."""
    return {str(k): g for k, g in rows.groupby(columns.suite, sort=False)}


def write_junit(path: Path, tables: dict[str, pd.DataFrame], columns: Columns, *,
                refused: dict[str, str] | None = None,
                seconds: dict[str, dict[str, float]] | None = None,
                moves: Moves | None = None) -> None:
    text = junit(tables, columns, refused, seconds=seconds, moves=moves).tostring()
    write_atomic(path, text.decode() if isinstance(text, bytes) else text)


def summary(tables: dict[str, pd.DataFrame], versions: dict[str, str],
            refused: dict[str, str] | None = None, *, command: str = "",
            seconds: dict[str, dict[str, float]] | None = None,
            moves: Moves | None = None) -> dict[str, object]:
    """The counts overall and per suite, refusals with their reason, the versions, each
    suite's seconds where measured and every row (NaN as null), under :data:`SCHEMA`'s
    version and dyncheck's; against a baseline, what moved (``baseline``)."""
    from dyncheck.provenance import dyncheck_version

    every = pd.concat(list(tables.values())) if tables else pd.DataFrame({"verdict": []})

    def counts(rows: pd.DataFrame) -> dict[str, int]:
        out = {v.value: int((rows["verdict"] == v.value).sum()) for v in Verdict}
        if "accepted" in rows:
            accepted = int(accepted_rows(rows).sum())
            if accepted:
                out[Verdict.FAILED.value] -= accepted
                out["accepted"] = accepted
        return out

    rows = json.loads(every.to_json(orient="records")) if len(every) else []
    extra: dict[str, object] = {} if moves is None else {"baseline": {
        "file": moves.file, "versions_changed": list(moves.versions_changed),
        "moved": json.loads(moves.rows.to_json(orient="records"))}}
    return {"schema_version": SCHEMA_VERSION,
            "dyncheck": dyncheck_version(),
            "command": command,
            "counts": counts(every),
            "suites": {name: counts(t) for name, t in tables.items()},
            "seconds": {name: round(sum(t.values()), 6) for name, t in (seconds or {}).items()
                        if name in tables},
            "refused": refused or {},
            "versions": versions,
            "rows": rows,
            **extra}


def schema() -> dict[str, object]:
    """The JSON Schema of :func:`summary`'s output (draft 2020-12)."""
    text = resources.files("dyncheck").joinpath(SCHEMA).read_text(encoding="utf-8")
    loaded: dict[str, object] = json.loads(text)
    return loaded


STDOUT = Path("-")
"""``--json -``: the summary to standard output (the command's other lines go to stderr)."""

_STDOUT: list[TextIO] = []
"""Standard output as the command found it, while :func:`json_on_stdout` holds it."""


@contextmanager
def json_on_stdout(path: Path | None) -> Iterator[None]:
    """With ``--json -``, standard output kept for the JSON alone while the block runs:
    everything else the command prints goes to standard error (a pipe into ``jq`` reads one
    document)."""
    if path != STDOUT:
        yield
        return
    _STDOUT.append(sys.stdout)
    sys.stdout = sys.stderr
    try:
        yield
    finally:
        sys.stdout = _STDOUT.pop()


def write_json(path: Path, tables: dict[str, pd.DataFrame], versions: dict[str, str], *,
               refused: dict[str, str] | None = None, command: str = "",
               seconds: dict[str, dict[str, float]] | None = None,
               moves: Moves | None = None) -> None:
    text = json.dumps(summary(tables, versions, refused, command=command, seconds=seconds,
                              moves=moves), indent=1) + "\n"
    if path == STDOUT:
        stream = _STDOUT[-1] if _STDOUT else sys.stdout
        stream.write(text)
        stream.flush()
    else:
        write_atomic(path, text)
