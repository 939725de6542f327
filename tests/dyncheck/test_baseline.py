"""Regression baselines, the committed report's freshness, and parallel runs."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest

from dyncheck import baseline
from dyncheck.__main__ import main
from dyncheck.cases import get_case
from dyncheck.cases.pendulums import SimplePendulum
from dyncheck.errors import InvalidInput
from dyncheck.report import folder as report
from dyncheck.results import DISCREPANCY_KEY
from dyncheck.run import run

REPORTS = Path(__file__).resolve().parents[2] / "reports"


def test_committed_baseline_has_no_regression(full_run):
    """The repository's baseline was made with the pinned engines: nothing moved."""
    changes = baseline.compare(full_run.discrepancies, baseline.load(REPORTS / "baseline.csv"))
    assert changes.empty, changes.to_string()


def test_committed_report_is_up_to_date(full_run):
    """`dyncheck report --check`: the committed tables and pages are what the code computes."""
    assert report.check(full_run, REPORTS) == []


@pytest.mark.slow
def test_stale_report_is_detected(tmp_path):
    result = run([get_case("simple_pendulum")], ["reference", "book"])
    report.write(result, tmp_path)
    assert report.check(result, tmp_path) == []
    csv = tmp_path / "discrepancies.csv"
    csv.write_text(csv.read_text().replace("passed", "failed", 1))
    moved = report.check(result, tmp_path)
    assert [(m.file, m.field, m.old, m.new) for m in moved] == [
        ("discrepancies.csv", "verdict", "failed", "passed")
    ]


@dataclass(frozen=True)
class _HeavierModel(SimplePendulum):
    """The book's simple pendulum, but the engines are given a bob 1 % heavier."""

    def multibody(self):
        import dataclasses

        mb = super().multibody()
        bob = dataclasses.replace(mb.bodies[0], mass=self.m * 1.01)
        return dataclasses.replace(mb, bodies=(bob,))


@pytest.mark.slow
def test_one_percent_heavier_model_regresses():
    base = baseline.load(REPORTS / "baseline.csv")
    result = run([_HeavierModel()], ["reference", "mujoco", "pinocchio"])
    changes = baseline.compare(result.discrepancies, base, cases=["simple_pendulum"])
    assert len(changes) > 0
    assert changes.change.str.startswith("regressed: verdict passed -> failed").any()
    assert changes.row.str.contains("simple_pendulum|mass_matrix|reference|mujoco").any()


def test_rows_that_appear_or_vanish_are_reported():
    base = baseline.load(REPORTS / "baseline.csv")
    sub = base[base.case == "simple_pendulum"].iloc[1:]
    changes = baseline.compare(sub, base, cases=["simple_pendulum"])
    assert list(changes.change.str.split(":").str[0]) == ["vanished"]


@pytest.mark.parametrize("content", ["", "not,a,baseline\n1,2,3\n", "\x00\x01garbage"])
def test_malformed_baseline_is_usage_error(tmp_path, content, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    with pytest.raises(InvalidInput, match="--baseline must be"):
        baseline.load(bad)
    out = tmp_path / "rep"
    assert main(["run", "simple_pendulum", "--baseline", str(bad), "--out", str(out)]) == 2
    assert "--baseline must be" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_jobs_give_identical_results():
    cases = [get_case("simple_pendulum"), get_case("spherical_pendulum")]
    impls = ["reference", "book", "mujoco", "pinocchio"]
    one, two = run(cases, impls, jobs=1), run(cases, impls, jobs=2)
    pd.testing.assert_frame_equal(one.discrepancies, two.discrepancies)
    pd.testing.assert_frame_equal(one.convergence, two.convergence)
    assert list(one.discrepancies[DISCREPANCY_KEY[0]].unique()) == [
        "simple_pendulum",
        "spherical_pendulum",
    ]


def test_a_run_without_the_accelerator_engines_is_compared_on_its_own_rows():
    """`run --baseline` after the README's first command (MuJoCo's ports left out): the
    committed baseline's port rows are not "vanished"; the rows the run has are compared (the
    current rows built here from the baseline itself with pandas, one of them then moved)."""
    from dyncheck.adapters import ACCELERATORS

    full = baseline.load(REPORTS / "baseline.csv")
    ports = full["impl_a"].isin(ACCELERATORS) | full["impl_b"].isin(ACCELERATORS)
    assert ports.any()
    current = full[~ports].reset_index(drop=True)
    ran = sorted({*current["impl_a"].dropna(), *current["impl_b"].dropna()})
    assert baseline.compare(current, full, impls=ran).empty
    assert not baseline.compare(current, full).empty  # unnarrowed: the port rows vanished
    moved = current.copy()
    at = int(moved.index[moved["verdict"] == "passed"][0])
    moved.loc[at, "verdict"] = "failed"
    assert len(baseline.compare(moved, full, impls=ran)) == 1
