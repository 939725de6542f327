"""The report's tables (report/tables.py): the order table — per case × implementation ×
integrator, the observed order at the finest pair of steps both in the asymptotic range, and
the verdict of that run's trajectory row — and the verdict matrices, whose cell is its rows'
worst verdict and worst relative error.

Expected values: small studies and rows written out by hand (the cells typed here)."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from dyncheck.report.tables import family_matrix, instantaneous_matrix, order_table


def _point(case, impl, integrator, dt, error, order, asymptotic, nominal=4):
    return {"case": case, "impl": impl, "integrator": integrator, "dt": dt, "error": error,
            "observed_order": order, "nominal_order": nominal, "reference_error": 1e-14,
            "asymptotic": asymptotic}


def _row(case, impl, integrator, verdict):
    return {"case": case, "quantity": "trajectory", "impl_a": "reference", "impl_b": impl,
            "integrator": integrator, "verdict": verdict}


CONV = pd.DataFrame([
    # listed finest first: the table sorts by step, coarsest first
    _point("a", "mujoco", "rk4", 0.005, 1e-9, 4.01, True),
    _point("a", "mujoco", "rk4", 0.01, 1.6e-8, 3.9, True),
    _point("a", "mujoco", "rk4", 0.02, 2.5e-7, float("nan"), False),
    _point("a", "pinocchio", "euler", 0.002, 1e-3, 1.2, False, nominal=1),
    _point("a", "pinocchio", "euler", 0.004, 2e-3, float("nan"), True, nominal=1),
    _point("b", "mujoco", "rk4", 0.01, 1e-8, 3.0, True),
    _point("b", "mujoco", "rk4", 0.02, 8e-8, float("nan"), True),
])
ROWS = pd.DataFrame([
    _row("a", "mujoco", "rk4", "passed"),
    _row("a", "pinocchio", "euler", "failed"),
    _row("b", "mujoco", "rk4", "failed"),
    {**_row("b", "mujoco", "rk4", "passed"), "quantity": "constraint_drift"},  # not the run's
    {**_row("b", "mujoco", "rk4", "passed"), "impl_a": "book"},  # another pair
])


def test_each_run_gets_its_finest_asymptotic_order_and_its_trajectory_verdict():
    t = order_table(CONV, ROWS)
    got = {(r["case"], r["implementation"], r["integrator"]): r for r in t.to_dict("records")}
    assert set(got) == {("a", "mujoco", "rk4"), ("a", "pinocchio", "euler"), ("b", "mujoco", "rk4")}
    a = got["a", "mujoco", "rk4"]
    assert a["observed order"] == 4.01 and a["verdict"] == "passed"
    assert a["finest dt"] == 0.005 and a["error at finest dt"] == 1e-9 and a["nominal order"] == 4
    p = got["a", "pinocchio", "euler"]
    assert math.isnan(p["observed order"]) and p["verdict"] == "failed"  # no asymptotic pair
    b = got["b", "mujoco", "rk4"]
    assert b["observed order"] == 3.0 and b["verdict"] == "failed"


def test_an_explained_run_gives_its_reason_beside_its_order():
    """#48: "rk4-held-force | nominal 1 | observed 0.999 | explained" needs its why."""
    conv = pd.DataFrame([_point("k", "mujoco", "rk4-held-force", 0.01, 1e-3, 0.999, True,
                                nominal=1),
                         _point("k", "mujoco", "rk4-held-force", 0.02, 2e-3, float("nan"), True,
                                nominal=1)])
    rows = pd.DataFrame([{**_row("k", "mujoco", "rk4-held-force", "explained"),
                          "convention": "state-dependent force held over RK4 stages"}])
    t = order_table(conv, rows)
    assert t["why"].tolist() == ["state-dependent force held over RK4 stages"]
    assert order_table(CONV, ROWS)["why"].eq("").all()  # passed or failed: no reason given


def test_one_case_only():
    t = order_table(CONV, ROWS, case="b")
    assert t["case"].tolist() == ["b"] and t["verdict"].tolist() == ["failed"]


def _inst(case, quantity, a, b, verdict, err, tol=1e-14):
    return {"case": case, "quantity": quantity, "impl_a": a, "impl_b": b, "integrator": "",
            "verdict": verdict, "max_rel_err": err, "tolerance": tol}


INSTANT = pd.DataFrame([
    _inst("a", "mass_matrix", "reference", "mujoco", "passed", 1e-15),
    _inst("a", "mass_matrix", "reference", "mujoco", "failed", 2e-3),   # one bad row: failed
    _inst("a", "mass_matrix", "reference", "mujoco", "passed", 4e-3, 5e-3),  # worst: any row's
    _inst("a", "bias", "reference", "mujoco", "explained", float("nan")),
    _inst("a", "bias", "reference", "mujoco", "passed", float("nan")),  # no error: verdict only
    _inst("a", "mass_matrix", "reference", "pinocchio", "skipped", float("nan")),
    _inst("b", "mass_matrix", "reference", "mujoco", "explained", 3e-9),
    {**_inst("a", "trajectory", "reference", "mujoco", "failed", 1.0), "integrator": "rk4"},
])


def test_a_cell_is_its_rows_worst_verdict_and_worst_error():
    m = instantaneous_matrix(INSTANT, "a").set_index("quantity")
    # the worst verdict, and the worst error with that row's own tolerance (relative)
    assert m.loc["mass_matrix", "reference vs mujoco"] == "failed 4.0e-03 (tol 5.0e-03)"
    assert m.loc["bias", "reference vs mujoco"] == "explained"
    assert m.loc["mass_matrix", "reference vs pinocchio"] == "skipped"
    assert list(m.index) == ["mass_matrix", "bias"]  # in the rows' order; no trajectory row


def test_the_family_matrix_has_a_column_per_case_and_blanks_where_a_pair_is_absent():
    m = family_matrix(INSTANT, trajectories=False).set_index("pair")
    assert m.loc["reference vs mujoco", "a"] == "failed 4.0e-03 (tol 5.0e-03)"
    assert m.loc["reference vs mujoco", "b"] == "explained 3.0e-09 (tol 1.0e-14)"
    assert m.loc["reference vs pinocchio", "b"] == ""
    # a trajectory row's tolerance is not relative (an order study's, an absolute drift):
    # its cell gives the error alone
    t = family_matrix(INSTANT, trajectories=True).set_index("pair")
    assert t.loc["reference vs mujoco", "a"] == "failed 1.0e+00"


def test_a_skipped_row_has_no_error_and_a_row_about_one_implementation_says_alone():
    rows = pd.DataFrame([
        _inst("a", "derivatives", "mjx", float("nan"), "skipped", 0.0, 0.0),
        _inst("a", "mass_matrix", "reference", "mujoco", "skipped", 0.0, 0.0),
        _inst("a", "mass_matrix", "reference", "mujoco", "passed", 1e-16),
    ])
    m = family_matrix(rows, trajectories=False).set_index("pair")
    assert m.loc["mjx alone", "a"] == "skipped"  # not "skipped 0.0e+00", not "mjx vs "
    # the skipped row is the worst verdict; the error is the checked row's
    assert m.loc["reference vs mujoco", "a"] == "skipped 1.0e-16 (tol 1.0e-14)"


def test_an_unknown_verdict_is_an_error_not_a_cell():
    with pytest.raises(ValueError, match="unknown verdict 'great'"):
        instantaneous_matrix(pd.concat([INSTANT, pd.DataFrame(
            [_inst("a", "bias", "reference", "mujoco", "great", 0.0)])]), "a")


def test_a_case_without_instantaneous_rows_has_an_empty_matrix_not_an_error():
    """`run CASE --impl reference` compares nothing instantaneous: the page says none (the
    first version of the tolerance cells raised on an empty group)."""
    only_runs = INSTANT[INSTANT["quantity"] == "trajectory"]
    assert instantaneous_matrix(only_runs, "a").empty
    assert family_matrix(only_runs, trajectories=False).empty


def test_the_per_engine_lines_count_each_engines_rows_by_verdict():
    """#80: the report opens with one line per engine. Five rows written here: mujoco is on
    four (two passed, one explained by convention "c", one failed on forward), pinocchio on
    two (one shared with mujoco, one skipped); the book's side is the judge, not a line."""
    from dyncheck.report.tables import per_engine

    rows = pd.DataFrame({
        "impl_a": ["reference", "reference", "mujoco", "reference", "book"],
        "impl_b": ["mujoco", "mujoco", "pinocchio", "pinocchio", "reference"],
        "verdict": ["passed", "explained", "passed", "skipped", "passed"],
        "convention": [None, "c", None, None, None],
        "quantity": ["mass_matrix", "bias", "forward", "forward", "forward"],
    })
    rows = pd.concat([rows, pd.DataFrame({"impl_a": ["reference"], "impl_b": ["mujoco"],
                                          "verdict": ["failed"], "convention": [None],
                                          "quantity": ["forward"]})], ignore_index=True)
    lines = per_engine(rows, ("reference", "book", "pinocchio", "mujoco"))
    assert lines == [
        "- **pinocchio** — 2 rows: 1 passed, 0 explained, 0 failed, 1 skipped",
        "- **mujoco** — 4 rows: 2 passed, 1 explained (c ×1), 1 failed (forward), 0 skipped",
    ]
