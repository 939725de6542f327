"""Drake's reading of an MJCF (adapters/drake/model.py): the cause of a lost armature is
checked on the file — what drives the joint — before it is stated. Expected values: the
file written here (its actuators) and Drake's own plant (which joints it holds an actuator
on)."""

from __future__ import annotations

import importlib.util

import pytest

from dyncheck.check.model_check import check_model

pytestmark = pytest.mark.skipif(importlib.util.find_spec("pydrake") is None,
                                reason="needs the 'drake' extra")

ARM = """<mujoco model="arm"><worldbody>
  <body name="l1" pos="0 0 1"><joint name="j1" type="hinge" axis="0 1 0" armature="0.1"/>
    <inertial pos="0 0 -0.3" mass="1" diaginertia="0.05 0.05 0.01"/>
    <body name="l2" pos="0 0 -0.6"><joint name="j2" type="hinge" axis="0 1 0" armature="0.1"/>
      <inertial pos="0 0 -0.3" mass="1" diaginertia="0.05 0.05 0.01"/>
      <body name="l3" pos="0 0 -0.6"><joint name="j3" type="hinge" axis="0 1 0"
        armature="0.1"/><inertial pos="0 0 -0.3" mass="1" diaginertia="0.05 0.05 0.01"/>
      </body></body></body></worldbody>
  <actuator><general name="g1" joint="j1" gainprm="10"/><motor name="m2" joint="j2"/>
  </actuator></mujoco>"""


def test_a_lost_armature_names_what_drives_the_joint(tmp_path):
    """j1 driven by <general> (Drake ignores it): the row names that actuator and the fix —
    it said "'j1' has none"; j2 driven by <motor>: Drake keeps its armature (no row); j3
    with no actuator: "has none"."""
    path = tmp_path / "arm.xml"
    path.write_text(ARM)
    rows = check_model(path, states=10, impls=("mujoco", "drake")).rows
    armature = rows[(rows["section"] == "description") & (rows["field"] == "armature")
                    & (rows["impl_b"] == "drake")]
    by_joint = dict(zip(armature["subject"], armature["note"], strict=True))
    assert set(by_joint) == {"j1", "j3"}, by_joint
    assert "<general> 'g1'" in by_joint["j1"] and "has none" not in by_joint["j1"]
    assert "<motor>" in by_joint["j1"]  # the fix
    assert "has none" in by_joint["j3"]


PENDULUM = """<mujoco model="p"><option gravity="0 0 -9.81"/><worldbody>
  <body name="bob" pos="0 0 1"><joint name="h" type="hinge" axis="0 1 0"/>
    <inertial pos="0 0 -0.5" mass="2" diaginertia="0.01 0.01 0.01"/></body>
  <body name="cart" pos="0 0 0"><joint name="s" type="slide" axis="1 0 0"/>
    <inertial pos="0 0 0" mass="3" diaginertia="0.01 0.01 0.01"/></body>
</worldbody></mujoco>"""


def _pendulum(tmp_path):
    from dyncheck.adapters.drake.model import DrakeModel
    from dyncheck.adapters.formats.files import read

    path = tmp_path / "p.xml"
    path.write_text(PENDULUM)
    return DrakeModel(read(path))


def test_a_field_on_bodies_is_its_generalized_force_by_hand(tmp_path):
    """Σ Jᵀ F of forces at the centres of mass (the run's external field), against the
    derivation by hand: a hinge about y at the bob's origin, its centre of mass r = 0.5 below
    it, turned by θ: J = ∂p/∂θ = (−r cos θ, 0, r sin θ) for p = (−r sin θ, 0, −r cos θ) — so
    τ_h = J · F; the slide along x carries the cart's force's x component."""
    import numpy as np

    model = _pendulum(tmp_path)
    theta, r = 0.4, 0.5
    forces = {"bob": np.array([1.5, -2.0, 0.7]), "cart": np.array([0.3, 4.0, -1.0])}
    seen: dict[str, np.ndarray] = {}

    def field(where: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        seen.update(where)
        return forces

    q = np.zeros((1, model.plant.num_positions()))
    hinge = model.plant.GetJointByName("h")
    q[0, hinge.position_start()] = theta
    tau = model.body_forces(q, np.zeros((1, model.plant.num_velocities())), field)[0]
    expected_bob = np.array([-r * np.sin(theta), 0.0, 1.0 - r * np.cos(theta)])
    np.testing.assert_allclose(seen["bob"], expected_bob, rtol=0, atol=1e-15)
    jacobian = np.array([-r * np.cos(theta), 0.0, r * np.sin(theta)])
    slide = model.plant.GetJointByName("s").velocity_start()
    assert abs(tau[hinge.velocity_start()] - jacobian @ forces["bob"]) <= 16 * np.finfo(float).eps
    assert tau[slide] == forces["cart"][0]


def test_its_cords_close_the_kkt_system_with_its_own_m_and_h(tmp_path):
    """A coupling C v = 0 between the hinge and the slide, closed by its loader: v̇ keeps
    C v̇ = 0, and M v̇ + h = τ + Cᵀ f with the multiplier it reports (expected: Drake's own
    M and h of the same plant, the KKT system's two rows)."""
    import numpy as np

    from dyncheck.cases.multibody import Coupling

    model = _pendulum(tmp_path)
    model.couple([Coupling(name="c", coefs=(("h", 1.0), ("s", -0.5)))])
    rng = np.random.default_rng(3)
    q = rng.uniform(-1, 1, (4, 2))
    v, tau = rng.uniform(-1, 1, (4, 2)), rng.uniform(-1, 1, (4, 2))
    vdot = model.forward(q, v, tau)
    f = model.constraint_forces(q, v, tau)
    d = model.dynamics(q, v, np.zeros_like(v))
    rows = np.zeros((1, 2))
    rows[0, model.plant.GetJointByName("h").velocity_start()] = 1.0
    rows[0, model.plant.GetJointByName("s").velocity_start()] = -0.5
    np.testing.assert_allclose(vdot @ rows.T, 0.0, atol=1e-14)
    residual = np.einsum("sij,sj->si", d.mass_matrix, vdot) + d.bias - tau - f @ rows
    np.testing.assert_allclose(residual, 0.0, atol=1e-13)


@pytest.mark.parametrize("integrator", ["euler", "rk2", "rk3"])
def test_its_own_integrators_step_as_their_order_says(tmp_path, integrator):
    """Drake's fixed-step integrators through its loader: the error at t = 0.4 s against a
    run of DOP853 at 1e-13 (scipy, on Drake's own forward dynamics) falls by 2^p when the
    step halves, p the scheme's order (1, 2, 3), to within ±0.3."""
    import numpy as np
    from scipy.integrate import solve_ivp

    model = _pendulum(tmp_path)
    q0, v0 = np.array([0.6, 0.0]), np.array([0.0, 0.5])
    n = len(q0)

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        a = model.forward(x[None, :n], x[None, n:], np.zeros((1, n)))[0]
        return np.concatenate([x[n:], a])

    exact = solve_ivp(rhs, (0, 0.4), np.concatenate([q0, v0]), method="DOP853", rtol=1e-13,
                      atol=1e-13).y[:n, -1]
    errors = []
    for dt in (0.01, 0.005):
        q, _ = model.simulate(q0, v0, dt, round(0.4 / dt), integrator=integrator)
        errors.append(float(np.abs(q[-1] - exact).max()))
    order = {"euler": 1, "rk2": 2, "rk3": 3}[integrator]
    assert abs(np.log2(errors[0] / errors[1]) - order) <= 0.3, errors
