"""The report check compares results, not bytes: round-off from another machine passes, any
change of a result fails (expected outcomes are constructed here by perturbing the committed
report, independently of the code that wrote it)."""

from __future__ import annotations

import io
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dyncheck import freshness
from dyncheck.cli import main
from dyncheck.results import to_csv

REPORTS = Path(__file__).resolve().parents[2] / "reports"
EPS = float(np.finfo(float).eps)


@pytest.fixture(scope="module")
def committed() -> dict[str, str]:
    return freshness.read_report(REPORTS)


def _frame(text: str) -> pd.DataFrame:
    return pd.read_csv(io.StringIO(text), keep_default_na=False, na_values=[""])


def other_machine(report: dict[str, str], seed: int = 0) -> dict[str, str]:
    """The report as a machine with other round-off would write it: every error moved by a few
    ulps; every error at round-off (below its row's tolerance) redrawn within it, with its worst
    state anywhere; tiny figures in pages redrawn."""
    rng = np.random.default_rng(seed)
    out = dict(report)
    d = _frame(report["discrepancies.csv"])
    for col in ("max_abs_err", "max_rel_err"):
        d[col] = d[col] * (1 + 4 * EPS * rng.uniform(-1, 1, len(d)))
    roundoff = d["max_rel_err"] <= d["tolerance"]
    redraw = rng.uniform(0, 1, len(d))
    scale = d["max_abs_err"] / d["max_rel_err"].where(d["max_rel_err"] > 0)
    d.loc[roundoff, "max_rel_err"] = (redraw * d["tolerance"])[roundoff]
    d.loc[roundoff & scale.notna(), "max_abs_err"] = (d["max_rel_err"] * scale)[
        roundoff & scale.notna()
    ]
    d.loc[roundoff, "worst_state"] = rng.integers(0, 16, int(roundoff.sum()))
    out["discrepancies.csv"] = to_csv(d)
    c = _frame(report["convergence.csv"])
    c["error"] = c["error"] * (1 + 1e-9 * rng.uniform(-1, 1, len(c)))
    out["convergence.csv"] = to_csv(c)
    for name, text in report.items():
        if name.endswith(".md"):
            out[name] = re.sub(
                r"(\d\.\d+)e-1[5-7]",
                lambda m: f"{float(m.group(1)) * rng.uniform(0.2, 3):.1f}e-16",
                text,
            )
    return out


def test_round_off_of_another_machine_passes(committed):
    perturbed = other_machine(committed)
    assert perturbed["discrepancies.csv"] != committed["discrepancies.csv"]
    assert freshness.compare(committed, perturbed) == []


def _edit(report: dict[str, str], name: str, edit) -> dict[str, str]:
    frame = _frame(report[name])
    changed = edit(frame)  # edits in place, or returns a new frame
    return {**report, name: to_csv(frame if changed is None else changed)}


def _first(frame: pd.DataFrame, **where) -> int:
    mask = np.ones(len(frame), bool)
    for k, v in where.items():
        mask &= frame[k] == v
    return int(np.flatnonzero(mask)[0])


def test_one_changed_verdict_fails(committed):
    def edit(d):
        d.loc[_first(d, verdict="passed"), "verdict"] = "failed"

    moved = freshness.compare(committed, _edit(committed, "discrepancies.csv", edit))
    assert [m.field for m in moved] == ["verdict"]


def test_one_order_moved_by_a_tenth_fails(committed):
    def edit(c):
        read = c["asymptotic"] & c.groupby(["case", "impl", "integrator"])["asymptotic"].shift(-1)
        i = int(np.flatnonzero(read.fillna(False).to_numpy(bool))[0])
        c.loc[i, "observed_order"] += 0.1

    moved = freshness.compare(committed, _edit(committed, "convergence.csv", edit))
    assert [m.field for m in moved] == ["observed_order"]


def test_removed_row_fails(committed):
    moved = freshness.compare(
        committed, _edit(committed, "discrepancies.csv", lambda d: d.drop(index=3))
    )
    assert [(m.field, m.new) for m in moved] == [("row", "vanished")]


def test_explained_difference_moved_by_one_percent_fails(committed):
    """An error far above round-off (MuJoCo's soft constraint, ~10 %) is a result."""

    def edit(d):
        i = _first(d, verdict="explained", quantity="constraint_force")
        d.loc[i, ["max_rel_err", "max_abs_err"]] *= 1.01

    moved = freshness.compare(committed, _edit(committed, "discrepancies.csv", edit))
    assert {m.field for m in moved} == {"max_rel_err", "max_abs_err"}


def test_changed_page_word_and_number_fail(committed):
    page = committed["README.md"]
    assert freshness.compare(committed, {**committed, "README.md": page.replace("passed", "x", 1)})
    bumped = re.sub(r"\b(1\.000)\b", "1.100", page, count=1)
    assert bumped != page
    assert freshness.compare(committed, {**committed, "README.md": bumped})


def test_missing_page_fails(committed):
    fewer = {k: v for k, v in committed.items() if k != "printed-equations.md"}
    moved = freshness.compare(committed, fewer)
    assert [(m.file, m.new) for m in moved] == [("printed-equations.md", "not written")]


def test_check_from_a_run_folder_on_another_machine(tmp_path, capsys):
    """`report --check --from DIR` compares two folders without running anything."""
    run_dir = tmp_path / "run"
    shutil.copytree(REPORTS, run_dir)
    for name, text in other_machine(freshness.read_report(REPORTS), seed=1).items():
        (run_dir / name).write_text(text)
    assert main(["report", "--check", "--from", str(run_dir)]) == 0
    assert "up to date" in capsys.readouterr().out
    csv = run_dir / "discrepancies.csv"
    csv.write_text(csv.read_text().replace(",passed,", ",failed,", 1))
    assert main(["report", "--check", "--from", str(run_dir)]) == 1
    out = capsys.readouterr().out
    assert "moved: discrepancies.csv:" in out and "verdict 'passed' -> 'failed'" in out


@pytest.mark.parametrize("flag", ["--from", "--out"])
def test_check_refuses_a_missing_folder_before_any_work(tmp_path, flag, capsys):
    args = ["report", "--check", flag, str(tmp_path / "nowhere")]
    if flag == "--out":
        args += ["--from", str(REPORTS)]
    assert main(args) == 2
    assert f"{flag} must be an existing report folder" in capsys.readouterr().err
