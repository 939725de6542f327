"""Results a CI system reads: JUnit XML (``--junit FILE``: one test suite per case or model,
one test case per group of rows — a quantity of one pair of implementations — failed with its
numbers, skipped with its reason) and a JSON summary (``--json FILE``: the counts, each
suite's counts and every row), for ``run`` and ``check`` alike. Written with ``junitparser``
(a maintained JUnit library) and ``json``; each file whole, then renamed.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from junitparser import Failure, JUnitXml, Skipped, TestCase, TestSuite

from dyncheck.results import Verdict, write_atomic


@dataclass(frozen=True, kw_only=True)
class Columns:
    """Where a results table keeps what a test case needs (``run`` and ``check`` differ)."""

    suite: str
    group: tuple[str, ...]
    error: str
    tolerance: str
    detail: tuple[str, ...]


RUN = Columns(suite="case", group=("quantity", "impl_a", "impl_b", "integrator", "dt"),
              error="max_rel_err", tolerance="tolerance", detail=("tolerance_basis", "note"))
CHECK = Columns(suite="model", group=("section", "subject", "impl_a", "impl_b"),
                error="error", tolerance="tolerance", detail=("field", "basis", "note"))


def _text(value: object) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return str(value)


def _name(keys: tuple[object, ...], columns: tuple[str, ...]) -> str:
    parts = {c: _text(k) for c, k in zip(columns, keys, strict=True)}
    pair = " vs ".join(p for p in (parts.pop("impl_a", ""), parts.pop("impl_b", "")) if p)
    rest = " ".join(v for v in parts.values() if v)
    return f"{rest} ({pair})" if pair else rest


def _case(name: str, suite: str, rows: pd.DataFrame, columns: Columns) -> TestCase:
    case = TestCase(name, classname=f"dyncheck.{suite}")
    failed = rows[rows["verdict"] == Verdict.FAILED.value]
    if not failed.empty:
        lines = []
        for row in failed.itertuples(index=False):
            values = row._asdict()
            detail = "; ".join(_text(values.get(c)) for c in columns.detail if _text(values.get(c)))
            lines.append(f"error {_text(values.get(columns.error))} > tolerance "
                         f"{_text(values.get(columns.tolerance))}" + (f" ({detail})" if detail
                                                                          else ""))
        case.result = [Failure(lines[0], "dyncheck")]
        case.result[0].text = "\n".join(lines)
    elif (rows["verdict"] == Verdict.SKIPPED.value).all():
        reason = "; ".join(dict.fromkeys(_text(n) for n in rows["note"] if _text(n)))
        case.result = [Skipped(reason or Verdict.SKIPPED)]
    return case


def junit(tables: dict[str, pd.DataFrame], columns: Columns,
          refused: dict[str, str] | None = None) -> JUnitXml:
    """One suite per table (a case, a model), one test case per group of rows; a refused
    model (bad input: no rows) one suite of one failed test case, its reason the message."""
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
        for keys, group in rows.groupby(list(columns.group), sort=False, dropna=False):
            suite.add_testcase(_case(_name(tuple(keys), columns.group), suite_name, group,
                                     columns))
        suite.update_statistics()
        xml.add_testsuite(suite)
    xml.update_statistics()
    return xml


def split(rows: pd.DataFrame, columns: Columns) -> dict[str, pd.DataFrame]:
    """A table of every case's or model's rows, one table each (in their order)."""
    return {str(k): g for k, g in rows.groupby(columns.suite, sort=False)}


def write_junit(path: Path, tables: dict[str, pd.DataFrame], columns: Columns,
                refused: dict[str, str] | None = None) -> None:
    text = junit(tables, columns, refused).tostring()
    write_atomic(path, text.decode() if isinstance(text, bytes) else text)


def summary(tables: dict[str, pd.DataFrame], versions: dict[str, str],
            refused: dict[str, str] | None = None) -> dict[str, object]:
    """The counts overall and per suite, refusals with their reason, the versions and every
    row (NaN as null)."""
    every = pd.concat(list(tables.values())) if tables else pd.DataFrame({"verdict": []})

    def counts(rows: pd.DataFrame) -> dict[str, int]:
        return {v.value: int((rows["verdict"] == v.value).sum()) for v in Verdict}

    rows = json.loads(every.to_json(orient="records")) if len(every) else []
    return {"counts": counts(every),
            "suites": {name: counts(t) for name, t in tables.items()},
            "refused": refused or {},
            "versions": versions,
            "rows": rows}


def write_json(path: Path, tables: dict[str, pd.DataFrame], versions: dict[str, str],
               refused: dict[str, str] | None = None) -> None:
    write_atomic(path, json.dumps(summary(tables, versions, refused), indent=1) + "\n")
