"""`dyncheck diff`: two runs joined row by row, each move classified.

The runs are synthetic tables whose moves are known by construction (an error multiplied, a
verdict changed, a row dropped, a trajectory whose error changes as dt² — the signature of a
changed second-order term of a scheme — or by a constant — a changed model), and the two real
runs of the committed version matrix (``tests/dyncheck/diff_runs``, made under two MuJoCo
releases by ``dyncheck versions``).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from dyncheck import diff
from dyncheck.__main__ import main
from dyncheck.results import PROVENANCE, to_csv

DTS = [1e-3, 5e-4, 2.5e-4, 1.25e-4]
TOL = 1.4e-14


def _rows(traj: list[float], *, mass_err: float = 1e-16, verdict: str = "passed") -> pd.DataFrame:
    rows = [
        dict(case="pendulum", quantity="mass_matrix", impl_a="reference", impl_b="engine",
             integrator="", dt=float("nan"), max_abs_err=mass_err, max_rel_err=mass_err,
             tolerance=TOL, tolerance_basis="round-off: 64 eps", verdict=verdict,
             convention="", note="", worst_state=0, worst_state_values=""),
        dict(case="pendulum", quantity="bias_forces", impl_a="reference", impl_b="engine",
             integrator="", dt=float("nan"), max_abs_err=2e-16, max_rel_err=2e-16,
             tolerance=TOL, tolerance_basis="round-off: 64 eps", verdict="passed",
             convention="", note="", worst_state=0, worst_state_values=""),
    ]
    for dt, err in zip(DTS, traj, strict=True):
        rows.append(dict(case="pendulum", quantity="trajectory", impl_a="reference",
                         impl_b="engine", integrator="euler", dt=dt, max_abs_err=err,
                         max_rel_err=err, tolerance=float("nan"), tolerance_basis="order 1",
                         verdict="explained", convention="", note="", worst_state=0,
                         worst_state_values=""))
    return pd.DataFrame(rows)


EULER = [0.3 * dt for dt in DTS]
"""A first-order scheme's error, C·dt (exact by construction)."""


def _write(folder: Path, frame: pd.DataFrame, **versions: str) -> Path:
    folder.mkdir(parents=True)
    (folder / "discrepancies.csv").write_text(to_csv(frame))
    (folder / PROVENANCE).write_text(json.dumps({"python": "3.11.7", **versions}))
    return folder


def _diff(tmp_path: Path, old: pd.DataFrame, new: pd.DataFrame) -> pd.DataFrame:
    a = diff.load(_write(tmp_path / "a", old, mujoco="3.3.7"), "RUN_A")
    b = diff.load(_write(tmp_path / "b", new, mujoco="4.0.0"), "RUN_B")
    return diff.diff(a, b)


def _move(table: pd.DataFrame, quantity: str) -> set[str]:
    return set(table.loc[table["quantity"] == quantity, "move"])


def test_equal_runs_are_unchanged_and_exit_0(tmp_path, capsys):
    a = _write(tmp_path / "a", _rows(EULER), mujoco="4.0.0")
    b = _write(tmp_path / "b", _rows(EULER), mujoco="4.0.0")
    assert main(["diff", str(a), str(b)]) == 0
    out = capsys.readouterr().out
    assert "6 unchanged" in out and "nothing moved" in out
    assert "none (a move is a change of dyncheck's code or inputs)" in out


def test_round_off_below_tolerance_is_unchanged(tmp_path):
    """Two builds' round-off (1e-16 → 9e-15, x90 but under 64 ε) is the same result."""
    table = _diff(tmp_path, _rows(EULER, mass_err=1e-16), _rows(EULER, mass_err=9e-15))
    assert _move(table, "mass_matrix") == {diff.Move.UNCHANGED}


def test_error_beyond_tolerance_regresses_exit_1_and_named(tmp_path, capsys):
    a = _write(tmp_path / "a", _rows(EULER), mujoco="3.3.7")
    b = _write(tmp_path / "b", _rows(EULER, mass_err=1e-9, verdict="failed"), mujoco="4.0.0")
    md = tmp_path / "diff.md"
    assert main(["diff", str(a), str(b), "--markdown", str(md)]) == 1
    out = capsys.readouterr().out
    assert "mujoco 3.3.7 -> 4.0.0" in out
    assert "mass_matrix" in out and "regressed" in out and "verdict passed -> failed" in out
    assert "bias_forces" not in out  # unchanged rows are not listed
    assert md.read_text().startswith("# dyncheck diff")


def test_improvement_is_a_move(tmp_path):
    table = _diff(tmp_path, _rows(EULER, mass_err=1e-9, verdict="failed"), _rows(EULER))
    assert _move(table, "mass_matrix") == {diff.Move.IMPROVED}


def test_change_vanishing_as_dt_squared_is_a_changed_scheme(tmp_path):
    """A fourth-order scheme (error 10³·dt⁴) replaced by a second-order one (40·dt²): the move
    shrinks with the step at order 2 — a changed definition, not a changed model."""
    rk4 = [1e3 * dt**4 for dt in DTS]
    order2 = [40 * dt**2 for dt in DTS]
    table = _diff(tmp_path, _rows(rk4), _rows(order2))
    traj = table[table["quantity"] == "trajectory"]
    moved = traj[traj["move"] != diff.Move.UNCHANGED]
    assert len(moved) > 0
    assert set(moved["move"]) == {diff.Move.DEFINITION_CHANGED}
    assert moved["note"].str.contains("dt^2.00", regex=False).all()


def test_constant_change_is_a_regression_not_a_scheme(tmp_path):
    """B = A + 0.05 at every step: a changed model (it does not vanish as dt → 0)."""
    table = _diff(tmp_path, _rows(EULER), _rows([e + 0.05 for e in EULER]))
    traj = table[table["quantity"] == "trajectory"]
    assert diff.Move.REGRESSED in set(traj["move"])
    assert diff.Move.DEFINITION_CHANGED not in set(traj["move"])


def test_rows_that_appear_or_vanish(tmp_path):
    old, new = _rows(EULER), _rows(EULER)
    table = _diff(tmp_path, old, new.iloc[1:])
    assert _move(table, "mass_matrix") == {diff.Move.VANISHED}
    table = _diff(tmp_path / "2", old.iloc[1:], new)
    assert _move(table, "mass_matrix") == {diff.Move.APPEARED}


def test_tolerance_factor(tmp_path):
    """An error above tolerance that grew x5 moves at --tolerance 2, not at the default 10."""
    traj = [e * 5 for e in EULER]
    a = _write(tmp_path / "a", _rows(EULER))
    b = _write(tmp_path / "b", _rows(traj))
    assert main(["diff", str(a), str(b)]) == 0
    assert main(["diff", str(a), str(b), "--tolerance", "2"]) == 1


def _check_rows(error: float) -> pd.DataFrame:
    return pd.DataFrame([
        dict(model="arm", section="dynamics", subject="mass_matrix", field="M",
             impl_a="reference", impl_b="mujoco", value_a="", value_b="", error=error,
             tolerance=1e-13, basis="round-off", verdict="passed" if error < 1e-13 else "failed",
             note="", worst_state=3),
    ])


def test_check_outputs_diff_by_model_and_field(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    (a / "arm.csv").write_text(to_csv(_check_rows(1e-15)))
    (b / "arm.csv").write_text(to_csv(_check_rows(1e-6)))
    assert main(["diff", str(a), str(b)]) == 1
    assert "arm" in capsys.readouterr().out
    shutil.copy(a / "arm.csv", b / "arm.csv")
    assert main(["diff", str(a), str(b)]) == 0


def test_a_baseline_file_diffs_against_a_run(tmp_path):
    """`dyncheck diff reports/baseline.csv RUN`: a baseline is the old side of a diff."""
    from dyncheck import baseline

    b = _write(tmp_path / "b", _rows(EULER))
    baseline.write(_rows(EULER), tmp_path / "base.csv", versions={"mujoco": "4.0.0"})
    assert main(["diff", str(tmp_path / "base.csv"), str(b)]) == 0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["diff", "/nonexistent/a", "{b}"], "RUN_A must be an existing output folder"),
        (["diff", "{a}", "{empty}"], "RUN_B must be a folder holding"),
        (["diff", "{a}", "{check}"], "RUN_B must be the output of `run`"),
        (["diff", "{a}", "{b}", "--tolerance", "0.5"], "--tolerance must be a finite factor > 1"),
        (["diff", "{a}", "{b}", "--tolerance", "nan"], "--tolerance must be a finite factor > 1"),
        (["diff", "{a}", "{garbage}"], "RUN_B must be"),
        (["diff", "{a}", "{dup}"], "RUN_B must be one row per key"),
    ],
)
def test_bad_input_is_one_line_exit_2(tmp_path, capsys, argv, message):
    _write(tmp_path / "a", _rows(EULER))
    _write(tmp_path / "b", _rows(EULER))
    (tmp_path / "empty").mkdir()
    (tmp_path / "check").mkdir()
    (tmp_path / "check" / "arm.csv").write_text(to_csv(_check_rows(1e-15)))
    (tmp_path / "garbage").mkdir()
    (tmp_path / "garbage" / "discrepancies.csv").write_bytes(b"\x00\xff\xfe garbage")
    dup = _rows(EULER)
    _write(tmp_path / "dup", pd.concat([dup, dup.iloc[:1]]))
    paths = {k: str(tmp_path / k) for k in ("a", "b", "empty", "check", "garbage", "dup")}
    assert main([arg.format(**paths) for arg in argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err


RUNS = Path(__file__).parent / "diff_runs"


def test_two_real_runs_under_mujoco_3_17_and_4_0(capsys):
    """Runs made by `dyncheck versions` (rigid_body_free and spherical_pendulum kept): MuJoCo
    4.0.0 changed RK4 on ball and free joints (stages combined on the rotation group, changelog
    9a7f240f0). The diff must name the version change and classify exactly those rows as a
    changed definition — their difference shrinks as dt², the order-2 scheme's error — and
    leave the instantaneous quantities (M, h, dynamics: no change of model) unchanged."""
    assert main(["diff", str(RUNS / "mujoco-3.17.0"), str(RUNS / "mujoco-4.0.0")]) == 1
    out = capsys.readouterr().out
    assert "mujoco 3.17.0 -> 4.0.0" in out
    table = diff.diff(diff.load(RUNS / "mujoco-3.17.0", "A"), diff.load(RUNS / "mujoco-4.0.0", "B"))
    moved = diff.moved(table)
    assert set(moved["move"]) == {diff.Move.DEFINITION_CHANGED}
    assert set(moved["integrator"]) == {"rk4"}
    assert set(moved["case"]) == {"rigid_body_free", "spherical_pendulum"}
    instantaneous = table[table["integrator"] == ""]
    assert set(instantaneous["move"]) == {diff.Move.UNCHANGED}
