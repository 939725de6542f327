"""The report check compares results, not bytes: round-off from another machine passes, any
change of a result fails (expected outcomes are constructed here by perturbing the committed
report, independently of the code that wrote it)."""

from __future__ import annotations

import io
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dyncheck import report_check
from dyncheck.__main__ import main
from dyncheck.results import to_csv

REPORTS = Path(__file__).resolve().parents[2] / "reports"
EPS = float(np.finfo(float).eps)


@pytest.fixture(scope="module")
def committed() -> dict[str, str]:
    return report_check.read_report(REPORTS)


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
    assert report_check.compare(committed, perturbed) == []


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

    moved = report_check.compare(committed, _edit(committed, "discrepancies.csv", edit))
    assert [m.field for m in moved] == ["verdict"]


def test_one_order_moved_by_a_tenth_fails(committed):
    def edit(c):
        read = c["asymptotic"] & c.groupby(["case", "impl", "integrator"])["asymptotic"].shift(-1)
        i = int(np.flatnonzero(read.fillna(False).to_numpy(bool))[0])
        c.loc[i, "observed_order"] += 0.1

    moved = report_check.compare(committed, _edit(committed, "convergence.csv", edit))
    assert [m.field for m in moved] == ["observed_order"]


def test_removed_row_fails(committed):
    moved = report_check.compare(
        committed, _edit(committed, "discrepancies.csv", lambda d: d.drop(index=3))
    )
    assert [(m.field, m.new) for m in moved] == [("row", "vanished")]


def test_explained_difference_moved_by_one_percent_fails(committed):
    """An error far above round-off (MuJoCo's soft constraint, ~10 %) is a result."""

    def edit(d):
        i = _first(d, verdict="explained", quantity="constraint_force")
        d.loc[i, ["max_rel_err", "max_abs_err"]] *= 1.01

    moved = report_check.compare(committed, _edit(committed, "discrepancies.csv", edit))
    assert {m.field for m in moved} == {"max_rel_err", "max_abs_err"}


def test_changed_page_word_and_number_fail(committed):
    page = committed["README.md"]
    worded = page.replace("passed", "x", 1)
    assert report_check.compare(committed, {**committed, "README.md": worded})
    bumped = re.sub(r"\b(1\.000)\b", "1.100", page, count=1)
    assert bumped != page
    assert report_check.compare(committed, {**committed, "README.md": bumped})


def test_missing_page_fails(committed):
    fewer = {k: v for k, v in committed.items() if k != "printed-equations.md"}
    moved = report_check.compare(committed, fewer)
    assert [(m.file, m.new) for m in moved] == [("printed-equations.md", "not written")]


def test_check_from_a_run_folder_on_another_machine(tmp_path, capsys):
    """`report --check --from DIR` compares two folders without running anything."""
    run_dir = tmp_path / "run"
    shutil.copytree(REPORTS, run_dir)
    for name, text in other_machine(report_check.read_report(REPORTS), seed=1).items():
        (run_dir / name).write_text(text)
    assert main(["report", "--check", "--from", str(run_dir)]) == 0
    assert "up to date" in capsys.readouterr().out
    csv = run_dir / "discrepancies.csv"
    csv.write_text(csv.read_text().replace(",passed,", ",failed,", 1))
    assert main(["report", "--check", "--from", str(run_dir)]) == 1
    out = capsys.readouterr().out
    assert "moved: discrepancies.csv:" in out and "verdict 'passed' -> 'failed'" in out


def _partial_run(run_dir: Path, left_out: tuple[str, ...], *, say: bool) -> None:
    """The committed report as a run of every implementation but ``left_out`` writes it:
    their rows cut from the tables (constructed here with pandas, not by freshness), the
    pages left as they are, and (``say``) its provenance listing what it ran."""
    shutil.copytree(REPORTS, run_dir)
    for name in ("discrepancies.csv", "convergence.csv", "conservation.csv"):
        t = _frame((REPORTS / name).read_text())
        keep = np.ones(len(t), bool)
        for column in ("impl", "impl_a", "impl_b"):
            if column in t.columns:
                keep &= ~t[column].isin(left_out).to_numpy()
        assert not keep.all() or name == "conservation.csv"  # the ports have rows to cut
        (run_dir / name).write_text(to_csv(t[keep]))
    from dyncheck.roster import IMPLEMENTATIONS

    provenance = run_dir / "provenance.json"
    listed = {"implementations": ", ".join(n for n in IMPLEMENTATIONS if n not in left_out)}
    provenance.write_text(json.dumps(listed if say else {}))


PORTS = ("mjx-f64", "mjx", "mujoco-warp")


def test_check_of_a_run_without_the_accelerator_engines_compares_the_rows_it_has(
    tmp_path, capsys
):
    """The README's first command leaves MuJoCo's ports out: `report --check --from` its
    folder passes, naming them; a result of an implementation it ran still fails when moved."""
    run_dir = tmp_path / "run"
    _partial_run(run_dir, PORTS, say=True)
    assert main(["report", "--check", "--from", str(run_dir)]) == 0
    out = capsys.readouterr().out
    assert "not run here: mjx, mjx-f64, mujoco-warp" in out and "up to date" in out
    csv = run_dir / "discrepancies.csv"
    text = csv.read_text()
    row = next(line for line in text.splitlines() if ",drake," in line and ",passed," in line)
    csv.write_text(text.replace(row, row.replace(",passed,", ",failed,"), 1))
    assert main(["report", "--check", "--from", str(run_dir)]) == 1
    assert "verdict 'passed' -> 'failed'" in capsys.readouterr().out


def test_rows_that_vanish_from_a_run_that_does_not_say_it_left_them_out_fail(tmp_path, capsys):
    """Only the run's own record of what it ran narrows the comparison: the same rows missing
    from a run that claims every implementation are rows that vanished."""
    run_dir = tmp_path / "run"
    _partial_run(run_dir, PORTS, say=False)
    assert main(["report", "--check", "--from", str(run_dir)]) == 1
    assert "'present' -> 'vanished'" in capsys.readouterr().out


@pytest.mark.parametrize("flag", ["--from", "--out"])
def test_check_refuses_a_missing_folder_before_any_work(tmp_path, flag, capsys):
    args = ["report", "--check", flag, str(tmp_path / "nowhere")]
    if flag == "--out":
        args += ["--from", str(REPORTS)]
    assert main(args) == 2
    assert f"{flag} must be an existing report folder" in capsys.readouterr().err


F32_FLOOR = 64 * float(np.finfo(np.float32).eps) * 16_000
"""64 ε₃₂ × the longest run's 16 000 steps (torque_free, 4 s at 0.25 ms): derived here from
the run's own bound for a float32 trajectory, independently of report_check.py."""


def _clear_of_noise(c: pd.DataFrame, impl: str) -> int:
    """The first RK4 row of ``impl`` whose error stands far above its reference's error and
    below the float32 floor."""
    rows = c[(c.impl == impl) & (c.integrator == "rk4") & (c.error > 1e6 * c.reference_error)]
    return int(rows.index[rows.error < F32_FLOOR / 2][0])


def _move_error(impl: str, factor: float):
    def edit(c):
        c.loc[_clear_of_noise(c, impl), "error"] *= factor

    return edit


def test_a_float32_run_moved_within_its_round_off_passes(committed):
    """Two CPUs round a float32 (MJX) run differently: its error moves within 64 ε₃₂ N."""
    edited = _edit(committed, "convergence.csv", _move_error("mjx", 1.7))
    assert report_check.compare(committed, edited) == []


def test_the_same_move_of_a_float64_run_fails(committed):
    moved = report_check.compare(
        committed, _edit(committed, "convergence.csv", _move_error("mujoco", 1.7))
    )
    assert [m.field for m in moved] == ["error"]


def test_a_float32_run_moved_beyond_its_round_off_fails(committed):
    def edit(c):
        c.loc[_clear_of_noise(c, "mjx"), "error"] += 2 * F32_FLOOR

    moved = report_check.compare(committed, _edit(committed, "convergence.csv", edit))
    assert [m.field for m in moved] == ["error"]


@pytest.mark.parametrize(("factor", "fails"), [(1.05, False), (1.5, True)])
def test_a_tolerance_from_an_error_estimate_agrees_to_the_estimates_accuracy(
    committed, factor, fails
):
    """An adaptive run's estimate |x(rtol) − x(rtol/4)| moves with its step decisions (5 %
    measured between two CPUs); a tolerance half as large again is a changed result."""

    def edit(d):
        rows = d[d.tolerance_basis.fillna("").str.contains("estimate") & (d.tolerance > 1e-9)]
        d.loc[rows.index[0], "tolerance"] *= factor

    moved = report_check.compare(committed, _edit(committed, "discrepancies.csv", edit))
    assert [m.field for m in moved] == (["tolerance"] if fails else [])


def test_a_round_off_tolerance_moved_by_five_percent_fails(committed):
    """A tolerance not from an estimate (64 ε κ(M)) is a derivation: 5 % is a change."""

    def edit(d):
        rows = d[d.tolerance_basis.fillna("").str.startswith("round-off: 64 eps x cond")]
        d.loc[rows.index[0], "tolerance"] *= 1.05

    moved = report_check.compare(committed, _edit(committed, "discrepancies.csv", edit))
    assert [m.field for m in moved] == ["tolerance"]


def _step_table_row(page: str, asymptotic: str) -> str:
    return next(
        line for line in page.splitlines()
        if line.startswith("| drake") and line.rstrip().endswith(f"| {asymptotic:<12} |")
    )


@pytest.mark.parametrize(("asymptotic", "fails"), [("False", False), ("True", True)])
def test_a_page_compares_an_observed_order_only_in_the_asymptotic_range(
    committed, asymptotic, fails
):
    """As in convergence.csv: an order computed from round-off-level errors is not read."""
    page = committed["atwood.md"]
    row = _step_table_row(page, asymptotic)
    cells = row.split("|")
    cells[5] = cells[5].replace(cells[5].strip(), f"{float(cells[5]) + 0.5:.3g}")
    edited = {**committed, "atwood.md": page.replace(row, "|".join(cells))}
    moved = report_check.compare(committed, edited)
    assert [m.file for m in moved] == (["atwood.md"] if fails else [])


def test_a_page_number_of_a_float32_implementation_is_compared_at_float32():
    header = "| pair | atwood |\n|:--|:--|\n"
    old = {"x.md": header + "| mujoco vs mjx | passed 8.2e-07 |\n"}
    assert report_check.compare(old, {"x.md": old["x.md"].replace("8.2e-07", "6.9e-07")}) == []
    f64 = {"x.md": header + "| mujoco vs mjx-f64 | passed 8.2e-07 |\n"}
    moved = report_check.compare(f64, {"x.md": f64["x.md"].replace("8.2e-07", "6.9e-07")})
    assert [m.field for m in moved] == ["number 8.2e-07 -> 6.9e-07"]
