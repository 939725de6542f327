"""The derivatives of the closed dynamics (:mod:`dyncheck.check.closure_derivatives`, #78):
MuJoCo's own ∂v̇/∂(q, v) with its equalities on (``mjd_transitionFD`` of its constrained
Euler step) against central differences of the referee's soft model of its reading, on the
models of tests/check/test_closures.py (whose soft model is tested there against MuJoCo's
accelerations). Expected: agreement within each side's measured finite-difference error,
which is far below the derivatives (the bound is not vacuous); a planted 0.1 % error in one
derivative found; a rotation's chart stated once as not compared; none without
``--derivatives``."""

from __future__ import annotations

import pytest

from dyncheck.adapters.offers import Offer
from dyncheck.check.model_check import check_model
from tests.check.test_closures import MODELS
from tests.conftest import loader

OFFERING = [e for e in ("mujoco",) if Offer.CLOSED_DERIVATIVES in loader(e).offers]


def _row(engine: str, name: str, tmp_path):
    path = tmp_path / f"{name}.xml"
    path.write_text(MODELS[name])
    result = check_model(path, impls=(engine, "reference"), states=8, isolate=False,
                         derivatives=True)
    rows = result.rows[(result.rows["section"] == "closures")
                       & (result.rows["subject"] == "derivatives")]
    assert len(rows) == 1
    return rows.iloc[0]


@pytest.mark.parametrize("engine", OFFERING)
@pytest.mark.parametrize("name", ["four_bar", "fingers", "tendon"])
def test_its_derivatives_with_its_constraints_are_the_referees(engine, name, tmp_path):
    row = _row(engine, name, tmp_path)
    assert row["verdict"] == "passed", row["note"]
    assert row["tolerance"] < 1e-5


@pytest.mark.parametrize("engine", OFFERING)
def test_a_derivative_off_by_a_thousandth_is_found(engine, tmp_path, monkeypatch):
    cls = loader(engine)
    honest = cls.closed_derivatives

    def off(self, q, v, tau):
        found = honest(self, q, v, tau)
        found[:, :, 0, 0] *= 1.001
        return found

    monkeypatch.setattr(cls, "closed_derivatives", off)
    row = _row(engine, "four_bar", tmp_path)
    assert row["verdict"] == "failed" and "cause unknown" in row["note"]


@pytest.mark.parametrize("engine", OFFERING)
def test_a_ball_joint_is_stated_once_as_not_compared(engine, tmp_path):
    row = _row(engine, "ball_loop", tmp_path)
    assert row["verdict"] == "skipped" and "'shoulder' turns in a rotation's chart" in \
        row["note"]


def test_no_derivatives_row_unless_asked(tmp_path):
    path = tmp_path / "four_bar.xml"
    path.write_text(MODELS["four_bar"])
    result = check_model(path, impls=("mujoco", "reference"), states=8, isolate=False)
    assert "derivatives" not in set(result.rows[result.rows["section"] == "closures"]
                                    ["subject"])
