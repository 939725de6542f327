"""Several models checked at once: which files (folders searched), the page name of each (no
two alike), and the index page — one line per model, one column per engine — rewritten as each
model is done, so an interrupted run keeps what it finished."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ROOT_TAG
from dyncheck.adapters.registration import Format
from dyncheck.check import baseline
from dyncheck.check.page import INDEX, counts
from dyncheck.check.rows import CheckResult
from dyncheck.check.verdicts import Agreement, EngineVerdict, Reading, per_engine
from dyncheck.errors import InvalidInput
from dyncheck.escaping import file_name, markdown, markdown_link, markdown_table
from dyncheck.results import to_csv, write_atomic
from dyncheck.vocabulary import Verdict

MODEL_SUFFIXES = (".xml", ".urdf", ".mjcf")
MAX_MODELS = 10_000
"""Most files one ``check`` takes from folders (a folder of more is refused, named)."""

READING = {Reading.ALIKE: "read alike", Reading.DIFFERENTLY: "read differently",
           Reading.PART: "holds part", Reading.REFUSED: "refused", Reading.SKIPPED: "not run"}
AGREEMENT = {Agreement.AGREE: "computes what it read",
             Agreement.EXPLAINED: "computes differently as explained",
             Agreement.DIFFER: "computes differently", Agreement.NOT_COMPARED: "not compared"}


def _root(path: Path) -> ET.Element | None:
    try:
        return parsing.root(path.read_bytes())
    except (ET.ParseError, OSError):
        return None


def in_folder(folder: Path) -> list[Path]:
    """The model files under ``folder``: MJCF and URDF roots, MJCF files that another one
    includes left out (fragments: materials, assets, shared bodies), and files with a model's
    suffix that are not XML at all — a broken model is refused on its own line, never
    skipped without a word (well-formed XML of another kind, a launch file, is no model).
    Each file parsed once."""
    candidates: list[tuple[Path, ET.Element | None]] = []
    for path in sorted(folder.rglob("*")):
        if path.suffix.lower() in MODEL_SUFFIXES and path.is_file() and not path.is_symlink():
            root = _root(path)
            if root is None or root.tag in ROOT_TAG.values():
                candidates.append((path, root))
            if len(candidates) > MAX_MODELS:
                raise InvalidInput("PATH", str(folder), f"a folder of at most {MAX_MODELS} "
                                   "model files")
    found = included(candidates)
    return [p for p, _ in candidates if p.resolve() not in found]


def included(candidates: list[tuple[Path, ET.Element | None]]) -> set[Path]:
    """The files the MJCF files among ``candidates`` (path, parsed root) ``<include>``."""
    return {(path.parent / i.get("file", "")).resolve() for path, root in candidates
            if root is not None and root.tag == ROOT_TAG[Format.MJCF]
            for i in root.iter("include")}


def without_fragments(paths: list[Path]) -> list[Path]:
    """``paths`` less the files that another model file beside one of them (in its folder)
    or among them includes — MJCF fragments (materials, assets, shared bodies) a pre-commit
    hook is handed when they change, which are no model of their own."""
    beside = {f for p in paths if p.parent.is_dir() for f in p.parent.iterdir()
              if f.suffix.lower() in MODEL_SUFFIXES and f.is_file() and not f.is_symlink()}
    found = included([(f, _root(f)) for f in sorted(beside | set(paths))])
    return [p for p in paths if p.resolve() not in found]


RESERVED = (INDEX, baseline.PAGE)
"""Page names a model never gets: the index's own files and the baseline's page (a model
named ``index.xml`` in a folder would lose its page and CSV to the index)."""


def page_names(paths: list[Path], given: list[str | None] | None = None) -> list[str]:
    """One page name per file: its stem (or the name ``given`` for it, such as a robot's);
    where stems collide, the fewest enclosing folders that tell the files apart
    (``suite__hopper``), else the suffix (``a-urdf``), else both; names still alike — the same
    file given twice, or names that differ only in what :func:`file_name` erases — get
    ``-2``, ``-3``. Every name is one file name (:func:`file_name`), none is a
    :data:`RESERVED` one, and no two are alike even on a file system that ignores case."""
    given = given if given is not None else [None] * len(paths)
    names = [file_name(g) if g else file_name(p.stem) for p, g in zip(paths, given,
                                                                       strict=True)]
    groups: dict[str, list[int]] = {}
    for i, name in enumerate(names):
        if not given[i]:
            groups.setdefault(name.casefold(), []).append(i)
    for members in groups.values():
        distinct = len({paths[i].resolve() for i in members})
        if distinct > 1:
            for i, name in zip(members, _told_apart([paths[i] for i in members], distinct),
                               strict=True):
                names[i] = name
    return _numbered(names)


def _told_apart(paths: list[Path], distinct: int) -> list[str]:
    """The names of same-stem files: with the fewest enclosing folders (never the file
    system's root) and the suffix that make them ``distinct``; the plain stems where none
    does (the numbering then tells them apart)."""
    parents = [p.resolve().parent.parts[1:] for p in paths]  # (parts[0]: the root, '/')
    suffixes = [p.suffix.lstrip(".") for p in paths]
    for depth in range(0, max(len(p) for p in parents) + 1):
        folders = ["__".join(p[len(p) - depth:]) if depth else "" for p in parents]
        for with_suffix in (False, True):
            tried = [file_name((f"{f}__" if f else "") + p.stem
                               + (f"-{x}" if with_suffix else ""))
                     for f, x, p in zip(folders, suffixes, paths, strict=True)]
            if len({t.casefold() for t in tried}) == distinct:
                return tried
    return [file_name(p.stem) for p in paths]


def _numbered(names: list[str]) -> list[str]:
    """``names`` made unique (case ignored) and kept off :data:`RESERVED`: a later alike
    name gets ``-2``, ``-3`` … (the first free one)."""
    taken = {r.casefold() for r in RESERVED}
    out = []
    for name in names:
        chosen, n = name, 1
        while chosen.casefold() in taken:
            n += 1
            chosen = f"{name}-{n}"
        taken.add(chosen.casefold())
        out.append(chosen)
    return out


@dataclass(frozen=True, kw_only=True)
class Entry:
    """One model's line: its page (empty where it was refused), file, and answers."""

    model: str
    file: str
    page: str
    counts: dict[str, int]
    verdicts: tuple[EngineVerdict, ...]
    refused: str = ""

    @property
    def outcome(self) -> str:
        if self.refused:
            return "refused"
        if self.counts.get(Verdict.FAILED, 0):
            return "differences found"
        return "known findings accepted" if self.counts.get("accepted", 0) else "engines agree"


def entry(result: CheckResult, page: str, file: str) -> Entry:
    return Entry(model=result.model, file=file, page=page, counts=counts(result),
                 verdicts=tuple(per_engine(result.rows, result.impls)))


def refused(model: str, file: str, why: str) -> Entry:
    return Entry(model=model, file=file, page="", counts={}, verdicts=(), refused=why)


def common_folder(paths: list[Path]) -> Path:
    return Path(os.path.commonpath([str(p.resolve().parent) for p in paths]))


def _cell(verdict: EngineVerdict | None) -> str:
    if verdict is None:
        return ""
    if verdict.reading in (Reading.REFUSED, Reading.SKIPPED):
        return READING[verdict.reading]
    return f"{READING[verdict.reading]} · {AGREEMENT[verdict.agreement]}"


def frame(entries: list[Entry], engines: tuple[str, ...]) -> pd.DataFrame:
    rows = []
    for e in sorted(entries, key=lambda e: e.model):
        by = {v.engine: v for v in e.verdicts}
        rows.append({"model": e.model, "file": e.file, "outcome": e.outcome,
                     **{engine: _cell(by.get(engine)) for engine in engines},
                     "rows": ", ".join(f"{n} {v}" for v, n in e.counts.items() if n),
                     "refused": e.refused, "page": f"{e.page}.md" if e.page else ""})
    return pd.DataFrame(rows)


def coverage(entries: list[Entry], engines: tuple[str, ...]) -> str:
    """On how many of the models the first engine read (MuJoCo, where asked for: the models
    it compiles) the referee judged each engine on the whole model: on its reading of the
    file, or of a copy with the fixes its causes name (:attr:`EngineVerdict.whole`)."""
    present = [e for e in engines if any(v.engine == e for x in entries for v in x.verdicts)]
    if not present:
        return ""
    first = present[0]
    read = [x for x in entries if any(v.engine == first and v.reading not in (
        Reading.REFUSED, Reading.SKIPPED) for v in x.verdicts)]
    whole = {engine: sum(any(v.engine == engine and v.whole for v in x.verdicts)
                         for x in read) for engine in present}
    counted = ", ".join(f"{engine} {n}" for engine, n in whole.items())
    return (f"Of the {len(read)} models {first} read, the referee judged each engine on the "
            "whole model (on its reading of the file, or of a copy with every fix its causes "
            f"name that edits the file) on: {counted}.")


def index_page(entries: list[Entry], engines: tuple[str, ...]) -> str:
    table = frame(entries, engines)
    shown = table.copy()
    shown["model"] = [markdown_link(m, p) if p else markdown(m)
                      for m, p in zip(table["model"], table["page"], strict=True)]
    shown["outcome"] = [o + (f": {markdown(r)}" if r else "")
                        for o, r in zip(table["outcome"], table["refused"], strict=True)]
    shown = shown.drop(columns=["page", "refused"])
    agree = sum(e.outcome == "engines agree" for e in entries)
    refusals = sum(bool(e.refused) for e in entries)
    lines = [
        f"# Model checks: {len(entries)} models",
        "",
        f"{agree} with every engine in agreement, {len(entries) - agree - refusals} with "
        f"differences found, {refusals} refused. One line per model; per engine: how it read "
        "the model, against MuJoCo's reading (read alike / read differently / holds part / "
        "refused / not run), then whether it computes what it read: its dynamics against the "
        "referee, the book's general method, on that engine's own reading (computes what it "
        "read / computes differently as explained / computes differently / not compared). "
        "Each model's page gives the reasons and the fixes in its first lines.",
        "",
        coverage(entries, engines),
        "",
        markdown_table(shown, escaped=("model", "outcome")),
        "",
    ]
    return "\n".join(lines)


def write(entries: list[Entry], engines: tuple[str, ...], out: Path) -> Path:
    write_atomic(out / f"{INDEX}.csv", to_csv(frame(entries, engines)))
    write_atomic(out / f"{INDEX}.md", index_page(entries, engines))
    return out / f"{INDEX}.md"
