"""Pinocchio on users' files: the composite joint its MJCF parser makes of a body's several
joints, whose analytic derivatives are wrong (a defect declared, its own finite differences
handed with them). Expected values: Pinocchio's own central differences of ``rnea`` (an
independent computation of the same derivative)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from dyncheck.adapters.mjcf import to_mjcf
from dyncheck.adapters.model_files import read
from dyncheck.adapters.pinocchio_model import PinocchioModel
from dyncheck.cases import get_case


@pytest.fixture
def several_joints_on_a_body(tmp_path: Path) -> Path:
    path = tmp_path / "cylindrical.xml"
    path.write_text(to_mjcf(get_case("cylindrical_coordinates").multibody()))
    return path


def test_a_composite_joints_derivative_in_q_is_not_computed(several_joints_on_a_body):
    """The fact the declared defect rests on: Pinocchio's analytic ∂τ/∂q of a composite joint
    differs from its own finite differences. When a release computes it, this fails: remove
    the declaration in ``PinocchioModel.derivatives``."""
    model = pin.buildModelFromMJCF(str(several_joints_on_a_body))
    assert any(j.shortname() == "JointModelComposite" for j in model.joints)
    data = model.createData()
    rng = np.random.default_rng(1)
    q, v, a = (rng.normal(size=n) for n in (model.nq, model.nv, model.nv))
    pin.computeRNEADerivatives(model, data, q, v, a)
    analytic = np.array(data.dtau_dq)
    h = 1e-6
    fd = np.column_stack([
        (pin.rnea(model, data, pin.integrate(model, q, h * e), v, a)
         - pin.rnea(model, data, pin.integrate(model, q, -h * e), v, a)) / (2 * h)
        for e in np.eye(model.nv)])
    assert np.abs(fd).max() > 1.0
    assert np.abs(analytic - fd).max() > 0.5 * np.abs(fd).max()


def test_its_derivatives_declare_the_defect_and_carry_its_own_differences(
        several_joints_on_a_body):
    """The derivatives of a model with a composite joint say so, and hand Pinocchio's own
    one-sided differences: within their truncation (step × |∂²τ/∂q²| ~ 1e-6 relative) of
    central differences of ``rnea`` computed here; the analytic ones are not."""
    loaded = PinocchioModel(read(several_joints_on_a_body))
    rng = np.random.default_rng(2)
    q = rng.normal(size=(2, loaded.tree.nq))
    v, a = rng.normal(size=(2, loaded.tree.nv)), rng.normal(size=(2, loaded.tree.nv))
    found = loaded.derivatives(q, v, a)
    assert "composite joint" in found.defect and found.own_differences is not None
    model, data, h = loaded.model, loaded.model.createData(), 1e-6
    for s in range(2):
        central = np.column_stack([
            (pin.rnea(model, data, pin.integrate(model, q[s], h * e), v[s], a[s])
             - pin.rnea(model, data, pin.integrate(model, q[s], -h * e), v[s], a[s])) / (2 * h)
            for e in np.eye(model.nv)])
        scale = np.abs(central).max()
        assert np.abs(found.own_differences.inverse_q[s] - central).max() < 1e-4 * scale
        assert np.abs(found.inverse_q[s] - central).max() > 0.1 * scale


def test_the_body_pinocchio_keeps_from_a_scene_with_includes_is_read_from_its_model(tmp_path):
    """A scene whose included part comes first: Pinocchio skips the <include> and keeps the
    first body of the file itself ('arm'); the row names 'arm' kept and 'table' dropped —
    it said the reverse, taking the first body of the inlined model. Expected: the bodies
    Pinocchio's own model holds."""
    from dyncheck.check.model_check import check_model

    (tmp_path / "part.xml").write_text(
        '<mujoco><worldbody><body name="table" pos="1 0 0"><joint name="slide" type="slide" '
        'axis="1 0 0"/><inertial pos="0 0 0" mass="3" diaginertia="0.1 0.1 0.1"/></body>'
        "</worldbody></mujoco>")
    (tmp_path / "scene.xml").write_text(
        '<mujoco model="scene"><include file="part.xml"/><worldbody><body name="arm" '
        'pos="0 0 1"><joint name="shoulder" type="hinge" axis="0 1 0"/><inertial '
        'pos="0 0 -0.5" mass="1" diaginertia="0.1 0.1 0.01"/></body></worldbody></mujoco>')
    rows = check_model(tmp_path / "scene.xml", states=10, impls=("mujoco", "pinocchio")).rows
    missing = rows[(rows["field"] == "joint") & (rows["impl_b"] == "pinocchio")]
    assert list(missing["subject"]) == ["slide"]
    note = missing["note"].iloc[0]
    assert "first body under <worldbody> ('arm')" in note and "('table')" in note
    assert "<include> elements, which Pinocchio skips" in note
