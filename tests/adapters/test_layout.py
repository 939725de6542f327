"""The check's map of a free joint's state into an engine's layout (frame offset, velocity
point, axes, order), against finite differences of the map itself: along a motion of the
body, the engine's velocity T v must be the time derivative of what the engine's q and point
describe, and its acceleration T v̇ + Ṫ v the derivative of that velocity (an independent
differentiation, central differences with error O(h²))."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dyncheck.adapters.layout import _free
from dyncheck.adapters.model_tree import Axes, Layout, Orientation

H = 1e-5
RNG = np.random.default_rng(7)
OFFSET = np.eye(4)
OFFSET[:3, :3] = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
OFFSET[:3, 3] = [0.1, -0.05, 0.2]
POINT = np.array([0.04, 0.12, -0.07])


def _ry(b: float) -> np.ndarray:
    return Rotation.from_rotvec([0.0, b, 0.0]).as_matrix()


def _motion(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A body's canonical state at time t — (p, quat w-x-y-z), v = (ṗ world, ω body) and v̇ —
    in closed form: p(t) quadratic, R(t) = R₀ Rz(a(t)) Ry(b(t)) with a, b quadratic, whose
    body angular velocity is ω = Ry(b)ᵀ e_z ȧ + e_y ḃ and ω̇ = Ry(b)ᵀ e_z ä − ḃ e_y ×
    (Ry(b)ᵀ e_z ȧ) + e_y b̈."""
    p0, v0, acc = np.array([0.2, -0.1, 0.4]), np.array([0.3, 0.5, -0.2]), np.array([1.0, -2.0, 0.5])
    a, a_dot, a_ddot = 0.3 + 0.9 * t + 0.35 * t * t, 0.9 + 0.7 * t, 0.7
    b, b_dot, b_ddot = -0.2 - 1.3 * t + 0.4 * t * t, -1.3 + 0.8 * t, 0.8
    e_y, e_z = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    rot = (Rotation.from_rotvec([0.4, 0.1, -0.3]) * Rotation.from_rotvec(a * e_z)
           * Rotation.from_rotvec(b * e_y))
    spin = _ry(b).T @ e_z * a_dot
    omega = spin + e_y * b_dot
    omega_dot = _ry(b).T @ e_z * a_ddot - np.cross(b_dot * e_y, spin) + e_y * b_ddot
    quat = np.roll(rot.as_quat(), 1)
    return (np.concatenate([p0 + v0 * t + 0.5 * acc * t * t, quat]),
            np.concatenate([v0 + acc * t, omega]), np.concatenate([acc, omega_dot]))


def _engine_point(lay: Layout, q_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where the engine's q puts its velocity point (world) and its frame's rotation."""
    p, quat = (q_e[3:], q_e[:4]) if lay.quat_first else (q_e[:3], q_e[3:])
    xyzw = quat if lay.quat == "xyzw" else np.roll(quat, -1)
    rot_q = Rotation.from_quat(xyzw).as_matrix()
    point = lay.offset[:3, 3] if lay.point is None else lay.point
    # the point in the q frame: offset⁻¹ · point (body frame)
    local = lay.offset[:3, :3].T @ (point - lay.offset[:3, 3])
    return p + rot_q @ local, rot_q


LAYOUTS = [
    Layout(q_start=0, v_start=0, nq=7, nv=6, quat=quat, angular_first=first,
           linear_axes=lin, angular_axes=ang, offset=offset, point=point)
    for quat, first, lin, ang, (offset, point) in itertools.product(
        (Orientation.WXYZ, Orientation.XYZW), (False, True), (Axes.WORLD, Axes.LOCAL),
        (Axes.WORLD, Axes.LOCAL),
        ((np.eye(4), None), (OFFSET, None), (np.eye(4), POINT), (OFFSET, POINT)))
]


@pytest.mark.parametrize("lay", LAYOUTS, ids=lambda lay: (
    f"{lay.quat}-{'ang' if lay.angular_first else 'lin'}first-{lay.linear_axes}-"
    f"{lay.angular_axes}-offset{int(not np.allclose(lay.offset, np.eye(4)))}-"
    f"point{int(lay.point is not None)}"))
def test_free_joint_map_matches_finite_differences_of_itself(lay):
    identity = np.array([1.0, 0.0, 0.0, 0.0])
    q_c, v_c, a_c = _motion(0.0)
    q_e, t, tdot_v = _free(lay, identity, q_c, v_c)
    v_e = t @ v_c
    lin = slice(3, 6) if lay.angular_first else slice(0, 3)
    ang = slice(0, 3) if lay.angular_first else slice(3, 6)
    (plus, rot_p), (minus, rot_m) = (_engine_point(lay, _free(lay, identity, *_motion(s)[:2])[0])
                                     for s in (H, -H))
    _, rot_0 = _engine_point(lay, q_e)
    velocity = (plus - minus) / (2 * H)  # world
    omega_hat = rot_0.T @ (rot_p - rot_m) / (2 * H)  # in the q frame's axes
    omega = np.array([omega_hat[2, 1], omega_hat[0, 2], omega_hat[1, 0]])
    expected_lin = rot_0.T @ velocity if lay.linear_axes is Axes.LOCAL else velocity
    expected_ang = omega if lay.angular_axes is Axes.LOCAL else rot_0 @ omega
    np.testing.assert_allclose(v_e[lin], expected_lin, atol=1e-8)
    np.testing.assert_allclose(v_e[ang], expected_ang, atol=1e-8)
    # the acceleration: d/dt (T v) along the motion
    v_plus = _free(lay, identity, *_motion(H)[:2])[1] @ _motion(H)[1]
    v_minus = _free(lay, identity, *_motion(-H)[:2])[1] @ _motion(-H)[1]
    np.testing.assert_allclose(t @ a_c + tdot_v, (v_plus - v_minus) / (2 * H), atol=1e-7)


PLACEMENT = np.eye(4)
PLACEMENT[:3, :3] = Rotation.from_rotvec([-0.4, 0.2, 0.1]).as_matrix()
PLACEMENT[:3, 3] = [0.3, 0.0, -0.2]


@pytest.mark.parametrize("lay", LAYOUTS, ids=lambda lay: (
    f"{lay.quat}-{'ang' if lay.angular_first else 'lin'}first-{lay.linear_axes}-"
    f"{lay.angular_axes}-offset{int(not np.allclose(lay.offset, np.eye(4)))}-"
    f"point{int(lay.point is not None)}"))
def test_the_batched_free_joint_map_is_the_one_state_map(lay):
    """The check maps a batch of real states at once (``free_batch``); expected: the
    one-state map above (itself held to finite differences), state by state, with a
    placement as well (a parser placing the model elsewhere)."""
    from dataclasses import replace

    from dyncheck.adapters.layout import free_batch
    from dyncheck.cases.coordinate_maps import quat_from_matrix

    lay = replace(lay, placement=PLACEMENT)
    place = quat_from_matrix(PLACEMENT[:3, :3].T[None])[0]
    quats = RNG.normal(size=(20, 4))
    quats /= np.linalg.norm(quats, axis=1, keepdims=True)
    q_c = np.concatenate([RNG.normal(size=(20, 3)), quats], axis=1)
    v_c = RNG.normal(size=(20, 6))
    q_e, t, tdot_v = free_batch(lay, place, q_c, v_c)
    for i in range(20):
        one = _free(lay, place, q_c[i], v_c[i])
        np.testing.assert_allclose(q_e[i], one[0], atol=1e-14)
        np.testing.assert_allclose(t[i], one[1], atol=1e-14)
        np.testing.assert_allclose(tdot_v[i], one[2], atol=1e-13)


def test_the_batched_ball_map_is_the_one_state_map():
    """A ball joint in roll-pitch-yaw with ω in the parent's axes (Drake's), batched against
    the one-state map, gimbal lock included (pitch ±π/2: roll taken 0)."""
    from dyncheck.adapters.layout import rpy_batch, rpy_from_matrix

    rot = Rotation.random(30, random_state=3).as_matrix()
    rot[0] = Rotation.from_euler("ZYX", [0.3, np.pi / 2, 0.0]).as_matrix()
    batched = rpy_batch(rot)
    for i in range(30):
        np.testing.assert_allclose(batched[i], rpy_from_matrix(rot[i]), atol=1e-12)


def _joint(name: str, kind: str, lay: Layout) -> object:
    from dyncheck.adapters.model_tree import JointType, TreeJoint

    zero3 = np.zeros(3)
    return TreeJoint(name=name, type=JointType(kind), parent=None, body=name, axis=zero3,
                     anchor=zero3, frame=np.eye(3), mass=1.0, com=zero3, inertia=np.eye(3),
                     armature=(), damping=(), range=None, layout=lay)


BALLS = [Layout.ball(quat=quat, angular_axes=axes) for quat, axes in itertools.product(
    (Orientation.WXYZ, Orientation.XYZW, Orientation.RPY), (Axes.LOCAL, Axes.PARENT))]


@pytest.mark.parametrize(("free", "ball"), list(zip(LAYOUTS, BALLS * 6, strict=False)),
                         ids=range(len(BALLS) * 6))
def test_engine_states_map_back_to_the_canonical_ones(free, ball):
    """A trajectory stepped in an engine's layout comes back (``canonical_states``, for
    Newton's and PyBullet's ball and free joints): expected, the canonical states that
    ``state_map`` (held to finite differences above) took into that layout — a hinge stored
    as (cos, sin) with a zero offset, a ball joint in each orientation and axes, a free joint
    with a placement, an offset and a velocity point, in an engine order other than the
    canonical one."""
    from dataclasses import replace

    from dyncheck.adapters.layout import canonical_states, state_map
    from dyncheck.adapters.model_tree import Canonical, JointType, ModelTree

    free = replace(free, q_start=0, v_start=0, placement=PLACEMENT)
    ball = replace(ball, q_start=free.nq, v_start=6)
    hinge = Layout(q_start=free.nq + ball.nq, v_start=9, nq=2, nv=1, cos_sin=True, zero=0.4)
    tree = ModelTree(engine="toy", joints=(_joint("base", "free", free),
                                           _joint("arm", "hinge", hinge),
                                           _joint("wrist", "ball", ball)),
                     gravity=np.zeros(3), nq=free.nq + ball.nq + 2, nv=10)
    canon = Canonical(names=("base", "arm", "wrist"),
                      types=(JointType.FREE, JointType.HINGE, JointType.BALL),
                      q_start=(0, 7, 8), v_start=(0, 6, 7), nq=12, nv=10, zeros=(0.0, 0.1, 0.0))
    quats = Rotation.random(16, random_state=5).as_quat()[:, [3, 0, 1, 2]]
    balls = Rotation.random(16, random_state=6).as_quat()[:, [3, 0, 1, 2]]
    q_c = np.concatenate([RNG.normal(size=(16, 3)), quats, RNG.uniform(-3, 3, (16, 1)), balls],
                         axis=1)
    v_c = RNG.normal(size=(16, 10))
    maps = [state_map(canon, tree, q, v) for q, v in zip(q_c, v_c, strict=True)]
    q_e = np.array([m.q for m in maps])
    v_e = np.array([m.t @ v for m, v in zip(maps, v_c, strict=True)])
    back_q, back_v = canonical_states(canon, tree, q_e, v_e)
    sign = np.sign(np.sum(back_q[:, 3:7] * quats, axis=1, keepdims=True))  # q and −q alike
    np.testing.assert_allclose(back_q[:, 3:7] * sign, quats, atol=1e-12)
    ball_sign = np.sign(np.sum(back_q[:, 8:] * balls, axis=1, keepdims=True))
    np.testing.assert_allclose(back_q[:, 8:] * ball_sign, balls, atol=1e-12)
    np.testing.assert_allclose(back_q[:, :3], q_c[:, :3], atol=1e-12)
    np.testing.assert_allclose(np.angle(np.exp(1j * (back_q[:, 7] - q_c[:, 7]))), 0, atol=1e-12)
    np.testing.assert_allclose(back_v, v_c, atol=1e-12)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_a_quaternion_normalized_by_the_engine_comes_back_as_it_gave_it(dtype):
    """A run's quaternion comes back (``canonical_positions``) as the engine computed it where
    the engine normalized it in its own arithmetic, and renormalized where its norm drifted.
    Expected values, independent of the code: a quaternion normalized in ``dtype`` has
    |‖q‖ − 1| of a few ε of ``dtype`` (its round-off, which a float32 port's rows must carry:
    the bit pattern is unchanged); one drifted by 1e-6 (Drake's components integrated) comes
    back with norm 1 to float64 round-off."""
    from dyncheck.adapters.layout import canonical_positions
    from dyncheck.adapters.model_tree import Canonical, JointType, ModelTree

    ball = Layout.ball(quat=Orientation.WXYZ, angular_axes=Axes.LOCAL)
    tree = ModelTree(engine="toy", joints=(_joint("wrist", "ball", ball),), gravity=np.zeros(3),
                     nq=4, nv=3, eps=float(np.finfo(dtype).eps))
    canon = Canonical(names=("wrist",), types=(JointType.BALL,), q_start=(0,), v_start=(0,),
                      nq=4, nv=3, zeros=(0.0,))
    raw = Rotation.random(64, random_state=7).as_quat()[:, [3, 0, 1, 2]].astype(dtype)
    normalized = (raw / np.linalg.norm(raw, axis=1, keepdims=True)).astype(float)
    assert np.abs(np.linalg.norm(normalized, axis=1) - 1).max() > 0  # not unit in float64
    np.testing.assert_array_equal(canonical_positions(canon, tree, normalized), normalized)
    drifted = normalized * (1 + 1e-6)
    back = canonical_positions(canon, tree, drifted)
    np.testing.assert_allclose(np.linalg.norm(back, axis=1), 1.0, atol=4e-16)
    np.testing.assert_allclose(back, normalized, rtol=0, atol=8 * np.finfo(dtype).eps)
