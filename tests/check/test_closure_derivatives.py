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
    assert row["verdict"] == "failed"
    assert "not the derivative of its own constrained dynamics" in row["note"]


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


def test_pinocchios_row_says_whether_its_routine_is_its_own_dynamics_derivative(tmp_path):
    """Pinocchio's ``computeConstraintDynamicsDerivatives`` on the four-bar, against central
    differences of its own ``constraintDynamics`` computed here (step 1e-6, along every
    coordinate; the expected value is Pinocchio's own forward dynamics): where they agree
    its row must pass; where they do not, the row must fail naming its routine, measured.
    (Pinocchio 3.x on this loop: its ∂v̇/∂q of the crank is off by a factor of order one.)"""
    import numpy as np

    pin_engine = loader("pinocchio")
    if Offer.CLOSED_DERIVATIVES not in pin_engine.offers:
        pytest.skip("pinocchio offers no derivatives of its constrained dynamics")
    from dyncheck.adapters.formats.files import read

    path = tmp_path / "four_bar.xml"
    path.write_text(MODELS["four_bar"])
    engine = pin_engine(read(path))
    q, v, tau = np.array([[0.4, -1.1, 0.9]]), np.array([[0.3, -0.2, 0.5]]), np.zeros((1, 3))
    analytic = engine.closed_derivatives(q, v, tau)[0, 0]
    step, own = 1e-6, np.zeros((3, 6))
    for k in range(6):
        dx = np.zeros(6)
        dx[k] = step
        ahead = engine.closed(q + dx[None, :3], v + dx[None, 3:], tau).vdot[0]
        behind = engine.closed(q - dx[None, :3], v - dx[None, 3:], tau).vdot[0]
        own[:, k] = (ahead - behind) / (2 * step)
    consistent = np.abs(analytic - own).max() <= 1e-4 * max(np.abs(own).max(), 1.0)
    row = _row("pinocchio", "four_bar", tmp_path)
    if consistent:
        assert row["verdict"] == "passed", row["note"]
    else:
        assert row["verdict"] == "failed"
        assert "not the derivative of its own constrained dynamics" in row["note"]
