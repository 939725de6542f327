"""Pinocchio on users' files: the composite joint its MJCF parser makes of a body's several
joints, whose analytic derivatives are wrong (a defect declared, its own finite differences
handed with them). Expected values: Pinocchio's own central differences of ``rnea`` (an
independent computation of the same derivative)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.pinocchio.model import PinocchioModel
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


CHAIN = """<mujoco model="p"><worldbody>
  <body name="cart" pos="0 0 0"><joint name="s" type="slide" axis="1 0 0"/>
    <inertial pos="0 0 0" mass="3" diaginertia="0.01 0.01 0.01"/>
    <body name="bob" pos="0 0 1"><joint name="h" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -0.5" mass="2" diaginertia="0.01 0.01 0.01"/></body></body>
</worldbody></mujoco>"""
"""A slide carrying a hinge (Pinocchio's MJCF parser reads one top-level tree)."""


def _chain(tmp_path: Path, **options) -> PinocchioModel:
    path = tmp_path / "p.xml"
    path.write_text(CHAIN)
    return PinocchioModel(read(path), **options)


def test_a_field_on_bodies_is_its_generalized_force_by_hand(tmp_path):
    """Σ Jᵀ F of forces at the centres of mass, against the derivation by hand: the hinge
    about y at the bob's origin (1 m above the cart), its centre of mass r = 0.5 below it,
    turned by θ: p = (x − r sin θ, 0, 1 − r cos θ), J_θ = (−r cos θ, 0, r sin θ); the slide
    carries both bodies' forces' x components."""
    model = _chain(tmp_path)
    x, theta, r = 0.2, 0.4, 0.5
    forces = {"bob": np.array([1.5, -2.0, 0.7]), "cart": np.array([0.3, 4.0, -1.0])}
    seen: dict[str, np.ndarray] = {}

    def field(where: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        seen.update(where)
        return forces

    tau = model.body_forces(np.array([[x, theta]]), np.zeros((1, 2)), field)[0]
    np.testing.assert_allclose(seen["bob"], [x - r * np.sin(theta), 0, 1 - r * np.cos(theta)],
                               rtol=0, atol=1e-15)
    jacobian = np.array([-r * np.cos(theta), 0.0, r * np.sin(theta)])
    eps = np.finfo(float).eps
    assert abs(tau[1] - jacobian @ forces["bob"]) <= 16 * eps
    assert abs(tau[0] - forces["bob"][0] - forces["cart"][0]) <= 16 * eps


def test_its_cords_close_the_kkt_system_with_its_own_m_and_h(tmp_path):
    """A coupling C v = 0 between the slide and the hinge, held by Pinocchio's constrained
    forward dynamics: C v̇ = 0, and M v̇ + h = τ + Cᵀ λ with the multiplier it reports
    (expected: Pinocchio's own crba and rnea of the same model, the KKT system's rows)."""
    from dyncheck.cases.multibody import Coupling

    model = _chain(tmp_path)
    model.couple([Coupling(name="c", coefs=(("h", 1.0), ("s", -0.5)))])
    rng = np.random.default_rng(3)
    q, v, tau = (rng.uniform(-1, 1, (4, 2)) for _ in range(3))
    vdot = model.forward(q, v, tau)
    f = model.constraint_forces(q, v, tau)
    d = model.dynamics(q, v, np.zeros_like(v))
    rows = np.array([[-0.5, 1.0]])  # (s, h): Pinocchio's velocity order is the file's
    np.testing.assert_allclose(vdot @ rows.T, 0.0, atol=1e-14)
    residual = np.einsum("sij,sj->si", d.mass_matrix, vdot) + d.bias - tau - f @ rows
    np.testing.assert_allclose(residual, 0.0, atol=1e-13)


def test_the_case_as_stated_holds_exact_point_masses_and_its_gravity(tmp_path):
    """``inertias=`` and ``gravity=``: the pendulum's bob as a point mass (M = m ℓ² exactly,
    the book's closed form, where the file's floor adds 1e-8) under the gravity given (its
    MJCF parser reads none: h = m g ℓ sin θ with g = 3)."""
    case = get_case("simple_pendulum")
    path = tmp_path / "pendulum.xml"
    path.write_text(to_mjcf(case.multibody()))
    floored = PinocchioModel(read(path))
    exact = PinocchioModel(read(path), gravity=np.array([0.0, 0.0, -3.0]),
                           inertias={"bob": np.zeros((3, 3))})
    theta = np.array([[0.7]])
    zero = np.zeros((1, 1))
    m, ell = case.m, case.l
    eps = np.finfo(float).eps
    assert abs(exact.dynamics(theta, zero, zero).mass_matrix[0, 0, 0] - m * ell**2) <= 4 * eps
    assert abs(floored.dynamics(theta, zero, zero).mass_matrix[0, 0, 0] - m * ell**2
               - case.multibody().mjcf_point_inertia) <= 4 * eps
    h = exact.dynamics(theta, zero, zero).bias[0, 0]
    assert abs(h - m * 3.0 * ell * np.sin(0.7)) <= 8 * eps


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_its_stepping_is_mujocos_definition_in_order(tmp_path, integrator):
    """MuJoCo's definitions on Pinocchio's forward dynamics: the error at t = 0.4 s against
    its own DOP853 at 1e-13 falls by 2^p when the step halves (p = 1, 4; ±0.3); its
    ``implicitfast`` is its ``euler`` (nothing damped), run for run."""
    model = _chain(tmp_path)
    q0, v0 = np.array([0.1, 0.6]), np.array([0.5, 0.0])
    exact = model.solve(q0, v0, np.array([0.0, 0.4]), rtol=1e-13)[0][-1]
    errors = []
    for dt in (0.02, 0.01):
        q, _ = model.simulate(q0, v0, dt, round(0.4 / dt), integrator=integrator)
        errors.append(float(np.abs(q[-1] - exact).max()))
    order = {"euler": 1, "rk4": 4}[integrator]
    assert abs(np.log2(errors[0] / errors[1]) - order) <= 0.3, errors
    assert model.definitions["implicitfast"] == "euler"
    same = model.simulate(q0, v0, 0.01, 40, integrator="implicitfast")[0]
    np.testing.assert_array_equal(same, model.simulate(q0, v0, 0.01, 40, integrator="euler")[0])


def test_an_unbounded_revolute_joint_is_not_stepped(tmp_path):
    """A URDF continuous joint is Pinocchio's (cos θ, sin θ): its stepping is refused, in
    words, before any step."""
    from dyncheck.errors import Unsupported

    path = tmp_path / "wheel.urdf"
    path.write_text("""<robot name="w"><link name="base"/><link name="wheel">
      <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0"
      iyz="0"/></inertial></link>
      <joint name="spin" type="continuous"><parent link="base"/><child link="wheel"/>
      <axis xyz="0 0 1"/></joint></robot>""")
    model = PinocchioModel(read(path))
    with pytest.raises(Unsupported, match="unbounded revolute"):
        model.simulate(np.array([1.0, 0.0]), np.zeros(1), 0.01, 3, integrator="euler")


@pytest.mark.parametrize(("x", "within"), [(0.0, 1e-13), (1e3, 1e-8), (1e6, 1e-2)])
def test_abas_derivatives_lose_digits_as_the_square_of_the_distance(tmp_path, x, within):
    """Pinocchio's ``computeABADerivatives`` works in world axes: its M⁻¹ against the inverse
    of ``crba``'s M (an independent computation in local frames) loses digits as (X/ℓ)² —
    ε (X/ℓ)² is 5.5e-15, 5.5e-11, 5.5e-5 for ℓ ≈ 2 m — which the check's derivative bounds
    declare (``PinocchioModel.derivatives``' ``about_origin``). Each bound is 100 times
    that, and at 1000 km the error exceeds what ε X/ℓ would allow (1e-10)."""
    from tests.check.test_derivatives import FAR

    path = tmp_path / "far.xml"
    path.write_text(FAR.format(x=x))
    model = pin.buildModelFromMJCF(str(path))
    data = model.createData()
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(20):
        q, v = rng.uniform(-3, 3, model.nq), rng.uniform(-3, 3, model.nv)
        pin.computeABADerivatives(model, data, q, v, np.zeros(model.nv))
        upper = np.asarray(data.Minv)
        minv = np.triu(upper) + np.triu(upper, 1).T
        mass = pin.crba(model, data, q)
        exact = np.linalg.inv(np.triu(mass) + np.triu(mass, 1).T)
        worst = max(worst, float(np.abs(minv - exact).max() / np.abs(exact).max()))
    assert worst <= within
    if x >= 1e6:
        assert worst > 1e-10  # beyond a bound linear in X/ℓ: the square is the engine's
