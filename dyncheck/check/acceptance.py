"""Known findings a CI gate accepts (``check --accept FILE``), as a snapshot tool's users
know them: a TOML file beside the models, one ``[[accept]]`` table per finding::

    [[accept]]
    model = "arm*"                      # the model's name, file name or path (fnmatch)
    engine = "ENGINE"                   # an implementation of the row's pair (fnmatch)
    label = "actuation actuator * gear" # the row's "section subject field" (fnmatch)
    reason = "the engine's gear scales only the rotor inertia"
    expires = 2027-06-30                # optional: after it, the finding fails again

A failed row that an entry matches stays failed on the page, marked accepted with the reason;
it no longer fails the command. An entry that matches no failed row of the models it names is
reported (the finding it accepted no longer occurs), as is an expired one. The file is parsed
by ``tomllib``: reading it executes nothing.
"""

from __future__ import annotations

import datetime as dt
import tomllib
from dataclasses import dataclass, replace
from fnmatch import fnmatchcase
from pathlib import Path

import pandas as pd

from dyncheck.check.rows import CheckResult
from dyncheck.errors import InvalidInput
from dyncheck.vocabulary import Verdict

FLAG = "--accept"
FIELDS = ("model", "engine", "label", "reason")
"""Every entry's text fields, all required (``expires`` is optional)."""


@dataclass(frozen=True, kw_only=True)
class Acceptance:
    """One accepted finding: patterns for the model, engine and row label, and why."""

    index: int
    """Its place in the file, from 1 (``accept[1]`` in messages)."""
    model: str
    engine: str
    label: str
    reason: str
    expires: dt.date | None = None

    @property
    def name(self) -> str:
        return (f"accept[{self.index}] (model {self.model!r}, engine {self.engine!r}, "
                f"label {self.label!r})")

    def expired(self, today: dt.date) -> bool:
        return self.expires is not None and today > self.expires

    def names_model(self, result: CheckResult) -> bool:
        return any(fnmatchcase(text, self.model)
                   for text in (result.model, result.path.name, str(result.path)))

    def matches(self, row: pd.Series) -> bool:
        pair = [str(row[c]) for c in ("impl_a", "impl_b") if isinstance(row[c], str) and row[c]]
        engines = any(fnmatchcase(e, self.engine) for e in pair)
        return engines and fnmatchcase(label(row), self.label)


def label(row: pd.Series) -> str:
    """A row's label, as an entry's ``label`` pattern matches it."""
    return f"{row['section']} {row['subject']} {row['field']}"


def load(path: Path) -> tuple[Acceptance, ...]:
    """The entries of ``path``, every field checked before any work: a one-line InvalidInput
    naming the file and the entry's field otherwise."""
    if not path.is_file():
        raise InvalidInput(FLAG, str(path), "an existing TOML file of [[accept]] entries")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InvalidInput(FLAG, str(path), f"a TOML file ({exc})") from None
    except OSError as exc:
        raise InvalidInput(FLAG, str(path), f"a readable file ({exc.strerror})") from None
    extra = sorted(set(data) - {"accept"})
    if extra:
        raise InvalidInput(f"{FLAG} {path}", extra[0], "an [[accept]] table (the only key)")
    entries = data.get("accept", [])
    if not isinstance(entries, list):
        raise InvalidInput(f"{FLAG} {path}: accept", entries, "an array of tables [[accept]]")
    return tuple(_entry(path, i, e) for i, e in enumerate(entries, start=1))


def _entry(path: Path, index: int, entry: object) -> Acceptance:
    where = f"{FLAG} {path}: accept[{index}]"
    if not isinstance(entry, dict):
        raise InvalidInput(where, entry, "a table of model, engine, label, reason")
    unknown = sorted(set(entry) - {*FIELDS, "expires"})
    if unknown:
        raise InvalidInput(f"{where}.{unknown[0]}", entry[unknown[0]],
                           f"absent (the fields are {', '.join(FIELDS)}, expires)")
    texts = {}
    for name in FIELDS:
        value = entry.get(name)
        if not isinstance(value, str) or not value.strip():
            raise InvalidInput(f"{where}.{name}", value, "a non-empty string")
        texts[name] = value.strip()
    expires = entry.get("expires")
    if isinstance(expires, str):
        try:
            expires = dt.date.fromisoformat(expires)
        except ValueError:
            raise InvalidInput(f"{where}.expires", expires, "a date, YYYY-MM-DD") from None
    if expires is not None and (not isinstance(expires, dt.date)
                                or isinstance(expires, dt.datetime)):
        raise InvalidInput(f"{where}.expires", expires, "a date, YYYY-MM-DD")
    return Acceptance(index=index, expires=expires, **texts)


def apply(result: CheckResult, entries: tuple[Acceptance, ...], today: dt.date
          ) -> tuple[CheckResult, set[int]]:
    """``result`` with each failed row that a live entry matches marked accepted (its
    ``accepted`` column the entry's reason), and the indices of the entries that matched."""
    live = [e for e in entries if e.names_model(result) and not e.expired(today)]
    if not live:
        return result, set()
    rows = result.rows.copy()
    used: set[int] = set()
    for i, row in rows.iterrows():
        if row["verdict"] != Verdict.FAILED:
            continue
        entry = next((e for e in live if e.matches(row)), None)
        if entry is not None:
            used.add(entry.index)
            until = f", until {entry.expires.isoformat()}" if entry.expires else ""
            rows.at[i, "accepted"] = f"{entry.reason} ({entry.name}{until})"
    return replace(result, rows=rows), used


def unused(entries: tuple[Acceptance, ...], results: list[CheckResult], used: set[int],
           today: dt.date) -> list[str]:
    """One line per entry that names a model checked here and accepted nothing: expired, or
    its finding no longer occurs (an entry whose models were not checked says nothing)."""
    out = []
    for e in entries:
        if e.index in used or not any(e.names_model(r) for r in results):
            continue
        if e.expired(today):
            out.append(f"{e.name} expired on {e.expires}: its finding fails again ({e.reason})")
        else:
            out.append(f"{e.name} accepts no failed row: the finding no longer occurs "
                       f"(remove the entry): {e.reason}")
    return out
