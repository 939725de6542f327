"""Engine state conventions (each loader's tree's joint layouts, mapped by
:mod:`dyncheck.adapters.layout`), established by experiment on the installed versions: if an
engine changes its quaternion order or velocity frame, these fail and say so."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.adapters.model_tree import Axes, Orientation
from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import SphericalPendulumMap, quat_to_matrix
from dyncheck.comparison import compare_instantaneous
from dyncheck.implementations import make_implementation

ROT = np.array([np.cos(0.35), 0.3 * np.sin(0.35), -0.5 * np.sin(0.35), 0.812404 * np.sin(0.35)])
ROT /= np.linalg.norm(ROT)  # a generic rotation, (w, x, y, z)
OMEGA = np.array([0.3, -0.7, 1.1])  # body-frame angular velocity


def _mujoco():
    import mujoco

    adapter, q = _loaded("mujoco", "spherical_pendulum", ROT)
    m, d = adapter.engine.model, adapter.engine.data
    d.qpos[:] = q
    d.qvel[:] = OMEGA
    mujoco.mj_forward(m, d)
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, 1, vel, 0)  # world-aligned
    return d.xmat[1].reshape(3, 3), vel[:3]


def _pinocchio(name: str):
    import pinocchio as pin

    adapter, q = _loaded(name, "spherical_pendulum", ROT)
    m, d = adapter.engine.model, adapter.engine.data
    pin.forwardKinematics(m, d, q, OMEGA)
    j = m.frames[m.getFrameId("bob", pin.FrameType.BODY)].parentJoint
    world = pin.getVelocity(m, d, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).angular
    return d.oMi[j].rotation, world


@pytest.mark.parametrize("engine", ["mujoco", "pinocchio", "pinocchio-mjcf"])
def test_quaternion_order_and_velocity_frame(engine):
    """Feeding the quaternion in the order the layout states must give the rotation it means;
    the angular velocity seen in the world is R ω (ω in the body frame)."""
    R, omega_world = _mujoco() if engine == "mujoco" else _pinocchio(engine)
    assert_allclose(R, quat_to_matrix(ROT[None])[0], atol=1e-14)
    assert_allclose(omega_world, R @ OMEGA, atol=1e-14)
    ball = make_implementation(engine, get_case("spherical_pendulum")).adapter.tree.joints[0]
    assert ball.layout.angular_axes is Axes.LOCAL  # (a loader's layout is its tree's)


@pytest.mark.parametrize("name", ["pinocchio", "pinocchio-mjcf"])
def test_pinocchio_native_order_is_xyzw(name):
    """The loader's map puts the canonical (w, x, y, z) in Pinocchio's (x, y, z, w)."""
    assert_allclose(_loaded(name, "spherical_pendulum", ROT)[1], [ROT[1], ROT[2], ROT[3], ROT[0]])


@pytest.mark.parametrize(("engine", "wrong"), [("mujoco", "xyzw"), ("pinocchio", "wxyz")])
def test_a_loader_read_in_the_wrong_quaternion_order_is_caught(engine, wrong, monkeypatch):
    """An engine's loader with its tree saying the other storage order: the run's map feeds
    it the quaternion in the wrong order, and its rows fail."""
    from dyncheck.adapters.mujoco.model import MujocoModel
    from dyncheck.adapters.pinocchio.model import PinocchioModel

    loader = {"mujoco": MujocoModel, "pinocchio": PinocchioModel}[engine]
    tree_of = loader._tree

    def misread(self, notes):
        tree = tree_of(self, notes)
        joints = tuple(dataclasses.replace(j, layout=dataclasses.replace(
            j.layout, quat=Orientation(wrong))) for j in tree.joints)
        return dataclasses.replace(tree, joints=joints)

    monkeypatch.setattr(loader, "_tree", misread)
    _fails_on_the_ball(engine)


def _fails_on_the_ball(engine: str) -> None:
    case = get_case("spherical_pendulum")
    impls = {
        "reference": make_implementation("reference", case),
        engine: make_implementation(engine, case),
    }
    rows = compare_instantaneous(case, impls, case.sample_states())
    failed = {r.quantity for r in rows if r.verdict == "failed"}
    assert {"bias_forces", "forward_dynamics", "potential_energy"} <= failed


def test_world_frame_velocity_would_be_caught():
    """Giving the engine the world-frame angular velocity instead of the body-frame one."""
    case = get_case("spherical_pendulum")
    impl = make_implementation("mujoco", case)
    base = impl.map.base

    class WorldFrame:
        description = "wrong: world-frame angular velocity"
        to_engine, to_book, hessian_term = base.to_engine, base.to_book, base.hessian_term

        def jacobian(self, q):
            return base.rotation(q) @ base.jacobian(q)

    impl.map = dataclasses.replace(impl.map, base=WorldFrame())
    impls = {"reference": make_implementation("reference", case), "mujoco": impl}
    rows = compare_instantaneous(case, impls, case.sample_states())
    assert {r.quantity for r in rows if r.verdict == "failed"} >= {"kinetic_energy"}


def test_spherical_pendulum_map_derivatives():
    """J by central differences of the bob's motion, the (2.2.5)-type term by differences of
    J along a path; the quaternion round trip."""
    m = SphericalPendulumMap()
    rng = np.random.default_rng(4)
    q = np.column_stack([rng.uniform(0.3, 2.8, 6), rng.uniform(-3, 3, 6)])
    v = rng.uniform(-1, 1, (6, 2))
    assert_allclose(m.to_book(m.to_engine(q)), q, atol=1e-14)
    R = m.rotation(q)
    h = 1e-6
    r = lambda x: m._rhat(x)[0]  # noqa: E731
    rdot = (r(q + h * v) - r(q - h * v)) / (2 * h)
    omega_world = np.einsum("nij,nj->ni", R, np.einsum("nij,nj->ni", m.jacobian(q), v))
    assert_allclose(np.cross(omega_world, r(q)), rdot, atol=1e-9)
    assert_allclose(np.einsum("ni,ni->n", omega_world, r(q)), 0, atol=1e-15)  # no spin
    Jw = lambda x: np.einsum("nij,njk->nik", m.rotation(x), m.jacobian(x))  # noqa: E731
    dJ = (Jw(q + h * v) - Jw(q - h * v)) / (2 * h)
    H_world = np.einsum("nij,nj->ni", dJ, v)
    assert_allclose(np.einsum("nij,nj->ni", R, m.hessian_term(q, v)), H_world, atol=1e-8)


V_LIN = np.array([0.4, -1.0, 0.6])


def test_mujoco_free_joint_linear_velocity_is_world_frame():
    """MuJoCo's freejoint: qvel[:3] is the body origin's velocity in world axes, qvel[3:] the
    angular velocity in body axes; with no force the linear qacc is zero (p̈ = 0)."""
    import mujoco

    adapter, _ = _loaded("mujoco", "rigid_body_free", np.concatenate([[0.1, 0.2, 0.3], ROT]))
    m, d = adapter.engine.model, adapter.engine.data
    m.opt.gravity[:] = 0
    d.qpos[:] = np.concatenate([[0.1, 0.2, 0.3], ROT])
    d.qvel[:] = np.concatenate([V_LIN, OMEGA])
    mujoco.mj_forward(m, d)
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, 1, vel, 0)  # (ω, v) world-aligned
    R = d.xmat[1].reshape(3, 3)
    assert_allclose(vel[3:], V_LIN, atol=1e-14)
    assert_allclose(vel[:3], R @ OMEGA, atol=1e-14)
    assert_allclose(d.qacc[:3], 0, atol=1e-12)
    assert adapter.tree.joints[0].layout.linear_axes is Axes.WORLD


@pytest.mark.parametrize("name", ["pinocchio", "pinocchio-mjcf"])
def test_pinocchio_free_flyer_velocity_is_body_frame(name):
    """Pinocchio's free-flyer: v[:3] is the body origin's velocity in body axes; with no force
    its v̇[:3] is not zero but −ω × v_b (the derivative of body-frame components)."""
    import pinocchio as pin

    adapter, q = _loaded(name, "rigid_body_free", np.concatenate([[0.1, 0.2, 0.3], ROT]))
    m, d = adapter.engine.model, adapter.engine.data
    m.gravity.linear[:] = 0
    v = np.concatenate([V_LIN, OMEGA])
    pin.forwardKinematics(m, d, q, v)
    R = d.oMi[1].rotation
    assert_allclose(R, quat_to_matrix(ROT[None])[0], atol=1e-14)
    world = pin.getVelocity(m, d, 1, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    assert_allclose(world.linear, R @ V_LIN, atol=1e-14)
    assert_allclose(world.angular, R @ OMEGA, atol=1e-14)
    a = pin.aba(m, d, q, v, np.zeros(6))
    assert_allclose(a[:3], -np.cross(OMEGA, V_LIN), atol=1e-12)
    assert adapter.tree.joints[0].layout.linear_axes is Axes.LOCAL


def _loaded(name: str, case_name: str, canonical: np.ndarray):
    """An engine's loader of the case's MJCF, and the canonical configuration in the
    engine's q as its run maps it (:func:`~dyncheck.adapters.layout.engine_states`)."""
    from dyncheck.adapters.layout import engine_states

    adapter = make_implementation(name, get_case(case_name)).adapter
    zero = np.zeros((1, adapter.canon.nv))
    return adapter, engine_states(adapter.canon, adapter.tree, canonical[None], zero, zero)[1][0]


def _drake(case_name: str, canonical: np.ndarray):
    return _loaded("drake", case_name, canonical)


def test_drake_ball_joint_is_rpy_with_world_angular_velocity():
    """Drake's BallRpyJoint: q = (r, p, y) with R = R_z(y) R_y(p) R_x(r); v = ω in world
    axes. Checked on the plant Drake's parser builds from the spherical pendulum's MJCF."""
    from dyncheck.adapters.layout import canonical_states

    adapter, q = _drake("spherical_pendulum", ROT)
    plant, ctx = adapter.engine.plant, adapter.engine.context
    assert q.shape == (3,)
    plant.SetPositions(ctx, q)
    plant.SetVelocities(ctx, OMEGA)
    body = plant.GetBodyByName("bob")
    R = plant.EvalBodyPoseInWorld(ctx, body).rotation().matrix()
    assert_allclose(R, quat_to_matrix(ROT[None])[0], atol=1e-14)
    w = plant.EvalBodySpatialVelocityInWorld(ctx, body).rotational()
    assert_allclose(w, OMEGA, atol=1e-15)  # v is ω in world axes, not body axes
    back = canonical_states(adapter.canon, adapter.tree, q[None], np.zeros((1, 3)))[0][0]
    assert_allclose(quat_to_matrix(back[None])[0], quat_to_matrix(ROT[None])[0], atol=1e-14)


def test_drake_free_joint_is_quaternion_first_world_velocities():
    """Drake's QuaternionFloatingJoint: q = (w, x, y, z, p), v = (ω, v), both world axes."""
    canonical = np.concatenate([[0.1, 0.2, 0.3], ROT])
    adapter, q = _drake("rigid_body_free", canonical)
    plant, ctx = adapter.engine.plant, adapter.engine.context
    assert_allclose(q, np.concatenate([ROT, [0.1, 0.2, 0.3]]))
    plant.SetPositions(ctx, q)
    plant.SetVelocities(ctx, np.concatenate([OMEGA, V_LIN]))
    body = plant.GetBodyByName("body")
    assert_allclose(plant.EvalBodyPoseInWorld(ctx, body).translation(), [0.1, 0.2, 0.3])
    V = plant.EvalBodySpatialVelocityInWorld(ctx, body)
    assert_allclose(V.rotational(), OMEGA, atol=1e-15)
    assert_allclose(V.translational(), V_LIN, atol=1e-15)
