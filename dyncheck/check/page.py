"""A model check as files: ``<out>/<model>.csv`` (every row) and ``<out>/<model>.md`` (the
page: summary, what was changed before loading, findings first, then every row, versions)."""

from __future__ import annotations

import platform
from dataclasses import replace
from pathlib import Path

import pandas as pd

from dyncheck.check import causes
from dyncheck.check.causes import Beside
from dyncheck.check.rows import CheckResult, Section, accepted
from dyncheck.check.verdicts import per_engine
from dyncheck.escaping import file_name, markdown, markdown_code, markdown_table
from dyncheck.results import (
    PROVENANCE,
    Verdict,
    provenance_json,
    to_csv,
    within,
    write_together,
)

INDEX = "index"
"""The name of the index of several models checked together (:mod:`.index`), beside their
pages."""

TITLES = {
    Section.LOAD: "Loading",
    Section.DESCRIPTION: "Model reading (each engine's tree against MuJoCo's)",
    Section.VALIDITY: "Physical validity",
    Section.DYNAMICS: "Dynamics",
    Section.CLOSURES: "Closures (the dynamics with the file's constraints, against the referee's "
                      "constrained method at states on them)",
    Section.ACTUATION: "Actuation (each engine's actuators against the first reading of them; "
                       "their force and step Jacobian in the controls against the referee)",
    Section.DERIVATIVES: "Derivatives (canonical chart; MuJoCo's by its own finite differences)",
    Section.WITH_FIX: "With the fix (each engine that reads the file in part or otherwise, run "
                      "on a copy with every fix its causes name that edits the file)",
}


def _versions(result: CheckResult) -> dict[str, str]:
    """The provenance of the engines the check used (:func:`engine_versions_of`)."""
    return engine_versions_of(result.impls)


def engine_versions_of(impls: tuple[str, ...]) -> dict[str, str]:
    """The provenance of ``impls``' engines, from their packages' metadata (an engine is
    never imported here for it: the engines ran in processes of their own, and importing
    Drake alone costs 0.3 s)."""
    from importlib.metadata import PackageNotFoundError, version

    from dyncheck.adapters import LABELS, MODELS
    from dyncheck.provenance import versions

    used = {}
    for name in impls:
        if name in MODELS and name in LABELS:
            try:
                used[LABELS[name]] = version(MODELS[name].package)
            except PackageNotFoundError:
                used[LABELS[name]] = "not installed"
    return versions(used)


ACCEPTED = "accepted"
"""The count of failed rows an ``--accept`` entry accepts (named only where there are any)."""


def counts(result: CheckResult) -> dict[str, int]:
    """Rows per verdict, the one rule of a page's first lines and the index: ``failed``
    counts the failed rows nothing accepts, ``accepted`` (where nonzero) the others."""
    verdicts = result.rows["verdict"]
    out = {v.value: int((verdicts == v.value).sum()) for v in Verdict}
    still = len(result.open_failures)
    if still != out[Verdict.FAILED]:
        out[ACCEPTED] = out[Verdict.FAILED] - still
        out[Verdict.FAILED] = still
    return out


def summary_line(result: CheckResult) -> str:
    c = counts(result)
    return f"{result.model}: " + ", ".join(f"{n} {v}" for v, n in c.items())


def _outcome(result: CheckResult, c: dict[str, int]) -> str:
    if not result.ok:
        return "differences found** (failed rows below)."
    if c.get(ACCEPTED):
        return (f"no new difference** ({c[ACCEPTED]} known findings accepted: the rows marked "
                "accepted below, with their reasons).")
    return "the engines agree** (every row passed or is explained)."


def _table(frame: pd.DataFrame, columns: list[str]) -> str:
    if frame.empty:
        return "_none_"
    shown = frame[columns].copy()
    for col in ("error", "tolerance"):
        if col in shown:
            shown[col] = shown[col].map(lambda x: f"{x:.3g}")
    return markdown_table(shown)


def page(result: CheckResult, versions: dict[str, str] | None = None, *,
         indexed: bool = False, there: Beside | None = None) -> str:
    """The Markdown page (``versions``: the provenance, read now when not given;
    ``indexed``: written beside the index of several models, which it links to; ``there``:
    the catalogue and tutorials beside its folder, which the causes link to)."""
    versions = _versions(result) if versions is None else versions
    rows = result.rows
    c = counts(result)
    lines = [
        f"# Model check: {markdown_code(result.model)}",
        "",
        *([f"[All models checked together]({INDEX}.md)", ""] if indexed else []),
        f"File: {markdown_code(result.path.name)} · {result.states} sampled states · "
        + " · ".join(f"**{n} {v}**" for v, n in c.items()),
        "",
        "**Outcome: " + _outcome(result, c),
        "",
        "## Per engine",
        "",
        *(f"- **{markdown(v.engine)}** — {markdown(v.line())}"
          for v in per_engine(rows, result.impls)),
        "",
        "## How it was checked",
        "",
        *(f"- {markdown(note)}" for note in result.notes),
        "- each engine read the file through its own parser; the neutral trees (joints matched "
        "by name, world axes at the reference configuration) are compared field by field; the "
        "reference is the book's general method (§2.2, (2.2.23)–(2.2.24), (2.2.39)–(2.2.40)) "
        "on that tree",
        "",
        "## Findings (failed and explained rows)",
        "",
        _table(_marked(rows[rows["verdict"].isin([Verdict.FAILED, Verdict.EXPLAINED])]),
               ["section", "subject", "field", "impl_a", "impl_b", "value_a", "value_b",
                "error", "verdict", "note"]),
        "",
        *causes.lines(rows, there or Beside()),
    ]
    for section in Section:
        part = rows[rows["section"] == section.value]
        if section in (Section.DERIVATIVES, Section.ACTUATION, Section.CLOSURES,
                       Section.WITH_FIX) and not len(part):
            continue  # not asked for, or nothing to check: no section that reads "none"
        lines += [f"## {TITLES[section]}", "",
                  _table(_marked(part), ["subject", "field", "impl_a", "impl_b", "error",
                                         "tolerance", "verdict", "note"]), ""]
    lines += ["## Time (seconds on this machine, loading and evaluating)", "",
              pd.DataFrame([result.seconds]).to_markdown(index=False, floatfmt=".3f"), "",
              "## Versions", ""]
    lines += [f"- {markdown(k)}: {markdown(v)}" for k, v in versions.items()]
    lines += [f"- machine: {platform.processor() or platform.machine()}", ""]
    return "\n".join(lines)


def _marked(rows: pd.DataFrame) -> pd.DataFrame:
    """Rows as shown: an accepted failed row's verdict reads ``failed (accepted: REASON)``."""
    if not accepted(rows).any():
        return rows
    shown = rows.copy()
    reason = shown["accepted"].fillna("").astype(str)
    shown["verdict"] = shown["verdict"].where(reason.eq(""),
                                              shown["verdict"] + " (accepted: " + reason + ")")
    return shown


def without_paths(result: CheckResult) -> CheckResult:
    """The result with the model's folder cut from every note and value (engine messages
    name files by absolute path): no path of the machine that made it on a page."""
    folder = str(result.path.resolve().parent) + "/"
    given = str(result.path.parent) + "/"

    def cut(text: object) -> object:
        if not isinstance(text, str):
            return text
        text = text.replace(folder, "")
        return text.replace(given, "") if given not in ("./", "/") else text

    rows = result.rows.copy()
    for column in ("note", "value_a", "value_b"):
        rows[column] = rows[column].map(cut)
    return replace(result, rows=rows, notes=tuple(str(cut(n)) for n in result.notes))


def write(result: CheckResult, out: Path, *, name: str | None = None,
          indexed: bool = False) -> list[Path]:
    """The page, its CSV and the provenance, written as one (:func:`write_together`: never
    one model's page beside another's CSV; ``name``: the files' name, by default the
    model's; ``indexed``: the page links to the index of the models checked with it)."""
    name = name or file_name(result.model)
    result = without_paths(result)
    csv_path, md_path = within(out, f"{name}.csv"), within(out, f"{name}.md")
    versions = _versions(result)
    md = page(result, versions, indexed=indexed, there=causes.beside(out))
    write_together({csv_path: to_csv(result.rows), md_path: md,
                    out / PROVENANCE: provenance_json(versions)})
    return [csv_path, md_path, out / PROVENANCE]
