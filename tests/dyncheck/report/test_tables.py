"""The report's order table (report/tables.py, ``order_table``): per case × implementation ×
integrator, the observed order at the finest pair of steps both in the asymptotic range, and
the verdict of that run's trajectory row.

Expected values: a small study written out by hand (the orders and verdicts typed here)."""

from __future__ import annotations

import math

import pandas as pd

from dyncheck.report.tables import order_table


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


def test_one_case_only():
    t = order_table(CONV, ROWS, case="b")
    assert t["case"].tolist() == ["b"] and t["verdict"].tolist() == ["failed"]
