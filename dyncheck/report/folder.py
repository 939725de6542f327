"""The report folder: every file rendered in memory, compared with a committed folder
(``report --check``) or written atomically (temp file, then rename)."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

from dyncheck.provenance import versions
from dyncheck.report.figures import figures
from dyncheck.report.pages import (
    PAGES,
    case_page,
    conventions_page,
    errata,
    index_page,
    page_link,
)
from dyncheck.report.tables import (
    conservation_table,
    md,
)
from dyncheck.report_check import RAN, Moved, compare, narrowed, read_report
from dyncheck.results import PROVENANCE, provenance_json, to_csv, write_together
from dyncheck.run_result import RunResult


def render(
    result: RunResult, out: Path, *, date: str | None = None, drawn: bool = True
) -> dict[Path, str | bytes]:
    """Every file of the report, in memory (nothing is written); the figures those the run
    drew in its units of work, drawn here where it did not — none without ``drawn``."""
    date = date or datetime.now(UTC).strftime("%Y-%m-%d")
    files: dict[Path, str | bytes] = {
        out / "discrepancies.csv": to_csv(result.discrepancies),
        out / "convergence.csv": to_csv(result.convergence),
        out / "conservation.csv": to_csv(conservation_table(result)),
    }
    for case in result.cases:
        files[out / f"{case.name}.md"] = case_page(case, result)
        if not drawn:
            continue
        pngs = result.pngs.get(case.name) or figures(
            case, result.figures[case.name], result.convergence)
        for kind, png in pngs.items():
            files[out / "figures" / f"{case.name}_{kind}.png"] = png
    files[out / "conventions.md"] = conventions_page(result.conventions)
    written = {out / "conventions.md", out / "printed-equations.md", out / "README.md"}
    present = frozenset(link for _, link, _ in PAGES
                        if (out / link).is_file() or out / link in files or out / link in written)
    files[out / "README.md"] = index_page(result, date=date, present=present)
    files[out / PROVENANCE] = provenance_json(
        {"date (UTC)": date, **versions(result.engines), RAN: ", ".join(result.ran)})
    lead, table = errata(result.discrepancies)
    files[out / "printed-equations.md"] = "\n".join(
        [
            "# The book's printed equations of motion against the general method",
            "",
            "The errata of §2.2, formula by formula (every derivation step, identity and "
            "exercise), are in " + page_link("errata.md", "errata.md", present)
            + "; this page is the numeric check of the "
            "equations of motion the cases implement.",
            "",
            "Each printed equation of motion (and its T and V) is evaluated as `book` and compared "
            "with the general method (`reference`, Lagrange's equations (2.2.23)-(2.2.26) from the "
            "particle positions) at the seeded states of every case; a disagreement beyond "
            "round-off would be an erratum of the book.",
            "",
            lead,
            "",
            md(table),
            "",
        ]
    )
    return files


def rendered_text(result: RunResult, out: Path) -> dict[str, str]:
    """The tables and pages a run writes (figures left out), file name → text."""
    return {
        path.name: content
        for path, content in render(result, out, drawn=False).items()
        if isinstance(content, str) and path.parent == out and path.suffix in (".csv", ".md")
    }


def check(result: RunResult, out: Path) -> list[Moved]:
    """What moved between the committed report in ``out`` and what the code computes now,
    compared on results, not bytes (:mod:`dyncheck.report_check`); a run of fewer
    implementations than the report holds is compared on its own rows
    (:func:`~dyncheck.report_check.narrowed`)."""
    old, new, _ = narrowed(read_report(out), rendered_text(result, out), result.ran)
    return compare(old, new)


def write(result: RunResult, out: Path, *, date: str | None = None) -> list[Path]:
    """Write every file of the report under ``out``, after all of them are computed (a run
    killed before this point changes nothing), as one (:func:`write_together`: a write that
    fails — a full disk, a file-size limit — leaves the previous report whole)."""
    files = render(result, out, date=date)
    write_together(files)
    return list(files)


