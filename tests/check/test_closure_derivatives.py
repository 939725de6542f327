"""The derivatives of the closed dynamics (:mod:`dyncheck.check.closure_derivatives`, #78):
MuJoCo's own ∂v̇/∂(q, v) with its equalities on (``mjd_transitionFD`` of its constrained
Euler step) against central differences of the referee's soft model of its reading, on the
models of tests/check/test_closures.py (whose soft model is tested there against MuJoCo's
accelerations). Expected: agreement within each side's measured finite-difference error,
which is far below the derivatives (the bound is not vacuous); a planted 0.1 % error in one
derivative found, on a hinge and on a ball's chart; an engine's own chart mapped into
MuJoCo's; none without ``--derivatives``."""

from __future__ import annotations

import pytest

from dyncheck.adapters.offers import Offer
from dyncheck.check.model_check import check_model
from tests.check.test_closures import FOUR_BAR, MODELS
from tests.conftest import loader

FLOATING_FOUR_BAR = FOUR_BAR.replace(
    '<body name="ground">', '<body name="ground"><freejoint name="base"/>'
    '<geom type="box" size=".6 .1 .05" pos=".5 0 0" mass="3"/>')
"""The four-bar on a free base: its loop through a free joint's chart (MuJoCo's: world
displacement, a turn in the body's axes; Pinocchio's free flyer: SE(3), its velocities in
the body's axes)."""

OFFERING = [e for e in ("mujoco",) if Offer.CLOSED_DERIVATIVES in loader(e).offers]


def _row(engine: str, name: str, tmp_path):
    path = tmp_path / f"{name}.xml"
    path.write_text(FLOATING_FOUR_BAR if name == "floating_four_bar" else MODELS[name])
    result = check_model(path, impls=(engine, "reference"), states=8, isolate=False,
                         derivatives=True)
    rows = result.rows[(result.rows["section"] == "closures")
                       & (result.rows["subject"] == "derivatives")]
    assert len(rows) == 1
    return rows.iloc[0]


@pytest.mark.parametrize("engine", OFFERING)
@pytest.mark.parametrize("name", ["four_bar", "fingers", "tendon", "ball_loop",
                                  "floating_four_bar"])
def test_its_derivatives_with_its_constraints_are_the_referees(engine, name, tmp_path):
    """In every direction (soft models), a ball's and a free base's directions in MuJoCo's
    chart included."""
    row = _row(engine, name, tmp_path)
    assert row["verdict"] == "passed", row["note"]
    assert row["tolerance"] < 1e-5


@pytest.mark.parametrize("engine", OFFERING)
def test_a_soft_weld_is_compared_along_its_manifold(engine, tmp_path):
    """The weld's rotation error is written otherwise by the referee (log) and MuJoCo (the
    quaternion's vector): across the manifold their soft answers differ at first order (a
    relative 1e-3 measured), along it they agree within the measured bound."""
    row = _row(engine, "weld", tmp_path)
    assert row["verdict"] == "passed", row["note"]
    assert row["tolerance"] < 1e-3


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
@pytest.mark.parametrize("column", [0, 2])
def test_a_derivative_off_by_a_thousandth_in_a_balls_chart_is_found(engine, column, tmp_path,
                                                                     monkeypatch):
    """∂v̇/∂q along the ball's first and third chart directions, each planted 0.1 % off."""
    cls = loader(engine)
    honest = cls.closed_derivatives

    def off(self, q, v, tau):
        found = honest(self, q, v, tau)
        found[:, :, :, column] *= 1.001
        return found

    monkeypatch.setattr(cls, "closed_derivatives", off)
    row = _row(engine, "ball_loop", tmp_path)
    assert row["verdict"] == "failed"


def test_an_engines_chart_is_mapped_into_mujocos(tmp_path):
    """Pinocchio's free flyer holds its linear velocity in the body's axes and moves q by
    SE(3)'s exponential (``pin.integrate``); MuJoCo's chart moves a free body by its world
    displacement. Central differences of Pinocchio's own closed dynamics in its chart,
    mapped by ``_mapped`` (T, and T's and Ṫ v's own derivatives), are the differences of the
    same dynamics taken in MuJoCo's chart (the expected value: one function differentiated
    two ways), to 1e-3 of them: at step 1e-4 truncation is ~1e-8, but Pinocchio's iterative
    solver leaves ~1e-7 m/s² between nearby states, ~1e-3 of the differences (measured
    8.6e-5 · 2.6 here). Without the map's own derivatives the free base's columns are off
    by O(1)."""
    from dataclasses import replace

    import numpy as np
    import pinocchio as pin

    from dyncheck.adapters import layout
    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.model_tree import canonical
    from dyncheck.check import closure_derivatives as cd
    from dyncheck.check import closures as checked
    from dyncheck.check.closure_rows import in_canonical
    from dyncheck.referee.computed import canonical_reading
    from tests.check.test_closures import _draws

    path = tmp_path / "floating.xml"
    path.write_text(FLOATING_FOUR_BAR)
    mj, pe = loader("mujoco")(read(path)), loader("pinocchio")(read(path))
    canon = canonical(mj.tree)
    tree = canonical_reading(canon, pe.tree)
    q, v = _draws(mj, seed=2)
    states = checked.on_constraints(tree, q, v, reach=1.0)
    states = replace(states, q=states.q[:2], v=states.v[:2])
    _, q_e, v_e, _ = layout.engine_states(canon, pe.tree, states.q, states.v,
                                                np.zeros_like(states.v))
    m, nv, step = pe.model, pe.model.nv, 1e-4
    zero = np.zeros((1, nv))
    own = np.zeros((len(q_e), 2, nv, 2 * nv))
    for i in range(len(q_e)):
        for k in range(2 * nv):
            dx = np.zeros(2 * nv)
            dx[k] = step
            ahead, behind = (pe.closed(pin.integrate(m, q_e[i], sign * dx[:nv])[None],
                                       (v_e[i] + sign * dx[nv:])[None], zero).vdot[0]
                             for sign in (1.0, -1.0))
            own[i, :, :, k] = (ahead - behind) / (2 * step)
    vdot = in_canonical(canon, pe, states, np.zeros_like(states.v))[1].vdot
    mapped = cd._mapped(canon, pe.tree, tree, q=states.q, v=states.v, found=own, vdot=vdot)

    def canonical(qq, vv):
        return in_canonical(canon, pe, replace(states, q=qq, v=vv), np.zeros_like(vv))[1].vdot

    theirs = cd.differences(canonical(*cd._perturbed(tree, states.q, states.v, step=step)),
                            len(states.q), nv, step=step)
    scale = np.abs(theirs[:, 0]).max()
    assert np.abs(mapped[:, 0] - theirs[:, 0]).max() <= 1e-3 * scale
    assert np.abs(own[:, 0] - theirs[:, 0]).max() > 1e-2 * scale  # (the map is not identity)


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


def test_pinocchios_mimic_derivatives_are_its_own_or_its_limit_in_its_words(tmp_path):
    """The URDF gripper's mimic joint: Pinocchio 4.1 refuses mimic joints in
    ``computeABADerivatives``: one skipped row quoting it (measured on its mimic model); a
    Pinocchio that takes them is compared on the manifold like any rigid reading and must
    agree (its derivatives of the reduced ABA are those of its own mimic dynamics)."""
    if Offer.CLOSED_DERIVATIVES not in loader("pinocchio").offers:
        pytest.skip("pinocchio offers no derivatives of its constrained dynamics")
    row = _row("pinocchio", "mimic", tmp_path)
    if row["verdict"] == "skipped":
        assert "computeABADerivatives on its mimic model says 'This algorithm does not " \
               "support Joint Mimic" in row["note"] and "(measured)" in row["note"]
    else:
        assert row["verdict"] == "passed", row["note"]
