"""dyncheck's integrators are MuJoCo's, on the rotation group too. Expected values come from
another engine: MuJoCo's own ``mj_step`` on the same model, one step from a generic state; the
naive stage sum (MuJoCo 3.x) must be far from it, so the check can fail."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.adapters.integrators import Addresses, integrate
from dyncheck.cases import get_case
from dyncheck.cases.quaternions import dexp_inv, quat_exp, quat_mul
from dyncheck.implementations import make_implementation

XML = """<mujoco><option integrator="{integrator}" timestep="{h}" gravity="0.3 -0.2 -9.81"/>
<worldbody><body pos="0 0 1"><joint type="{joint}"/>
<geom type="box" size="0.3 0.2 0.1" pos="0.1 0.05 -0.2" mass="2"/>
<geom type="sphere" size="0.05" pos="0 0.3 0.1" mass="0.5"/></body></worldbody></mujoco>"""


def _mujoco_step(joint: str, integrator: str, h: float, naive: bool = False):
    """(MuJoCo's one step, dyncheck's one step) from the same generic state."""
    m = mujoco.MjModel.from_xml_string(XML.format(integrator=integrator, h=h, joint=joint))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(7)
    q0 = rng.normal(size=m.nq)
    k = m.nq - 4
    q0[k:] /= np.linalg.norm(q0[k:])
    v0 = 3 * rng.normal(size=m.nv)

    def acc(q, v, _held=None):
        d.qpos[:], d.qvel[:] = q, v
        mujoco.mj_forward(m, d)
        return d.qacc.copy()

    name = {"Euler": "euler", "RK4": "rk4"}[integrator]
    qs, vs = integrate(acc, q0, v0, h, 1, name, layout=Addresses.of([joint]), naive_group=naive)
    d.qpos[:], d.qvel[:] = q0, v0
    mujoco.mj_forward(m, d)
    mujoco.mj_step(m, d)
    return (d.qpos.copy(), d.qvel.copy()), (qs[-1], vs[-1])


@pytest.mark.parametrize("joint", ["ball", "free", "hinge", "slide"])
@pytest.mark.parametrize("integrator", ["Euler", "RK4"])
def test_one_step_is_mujocos(joint, integrator):
    """A coarse step (h = 0.05 s, |ω| h ≈ 0.3 rad) so that any other definition shows: on the
    rotation group (ball, free) and on a vector state (hinge, slide: RK4 on y = (q, v) as one
    array)."""
    (q_mj, v_mj), (q, v) = _mujoco_step(joint, integrator, 0.05)
    assert_allclose(q, q_mj, rtol=0, atol=1e-15 * 64)
    assert_allclose(v, v_mj, rtol=0, atol=1e-14 * 64)


@pytest.mark.parametrize("integrator", ["rk4", "rk4-held-force"])
def test_vector_rk4_is_the_general_tableau_bit_for_bit(integrator, monkeypatch):
    """The vector path performs the general path's operations element by element in the same
    order: the same numbers to the last bit (expected: the general tableau, forced here), on a
    nonlinear three-coordinate system over 200 steps."""
    from dyncheck.adapters import integrators

    def acc(q, v, held=None):
        force = np.sin(q) * np.cos(q[::-1]) + 0.3 * v * np.abs(v)
        return -force if held is None else held - force

    def freeze(q, v):
        return 0.1 * np.tanh(q)

    q0, v0 = np.array([0.4, -1.1, 2.3]), np.array([0.7, 0.2, -1.5])
    args = (acc, q0, v0, 0.013, 200, integrator)
    fast = integrate(*args, freeze=freeze)
    monkeypatch.setattr(integrators, "_rk4_vector", integrators._rk4)
    general = integrate(*args, freeze=freeze)
    assert all(np.array_equal(a, b) for a, b in zip(fast, general, strict=True))


@pytest.mark.parametrize("joint", ["ball", "free"])
def test_stage_velocities_summed_without_dexp_inv_are_not_mujocos(joint):
    (q_mj, _), (q, _) = _mujoco_step(joint, "RK4", 0.05, naive=True)
    assert np.abs(q - q_mj).max() > 1e-9


def test_dexp_inv_is_the_rate_of_exponential_coordinates():
    """θ(t) with q₀ exp(θ(t)) rotating at body rate ω: θ̇ = dexp⁻¹(θ) ω, checked by central
    differences of log(exp(θ) exp(h ω)) — an independent derivation from the group law."""
    theta, omega, h = np.array([0.4, -0.7, 0.2]), np.array([1.3, 0.5, -0.8]), 1e-6

    def log(quat):
        w, xyz = quat[0], quat[1:]
        n = np.linalg.norm(xyz)
        return 2 * np.arctan2(n, w) * xyz / n

    base = quat_exp(theta)
    fwd = log(quat_mul(base, quat_exp(h * omega)))
    back = log(quat_mul(base, quat_exp(-h * omega)))
    assert_allclose(dexp_inv(theta, omega), (fwd - back) / (2 * h), rtol=1e-8)
    small = np.array([3e-5, -1e-5, 2e-5])  # the series branch
    fwd = log(quat_mul(quat_exp(small), quat_exp(h * omega)))
    back = log(quat_mul(quat_exp(small), quat_exp(-h * omega)))
    assert_allclose(dexp_inv(small, omega), (fwd - back) / (2 * h), rtol=1e-6)


@pytest.mark.parametrize("case", ["rigid_body_ball", "rigid_body_free", "torque_free"])
def test_pinocchio_runs_mujocos_rk4_to_round_off(case):
    """Pinocchio's dynamics under dyncheck's RK4 against MuJoCo's RK4: the same map of the
    same model, so only round-off separates them (accumulated over the steps)."""
    c = get_case(case)
    dt = c.trajectory.steps["rk4"][0]
    _, qa = make_implementation("mujoco", c).simulate(dt, "rk4")
    _, qb = make_implementation("pinocchio", c).simulate(dt, "rk4")
    steps = len(qa) - 1
    assert np.abs(qa - qb).max() <= 64 * np.finfo(float).eps * steps * np.abs(qa).max()
