"""Engine state conventions, found by experiment (tests hold them): each adapter declares its
engine's :class:`~dyncheck.adapters.base.StateLayout` (``Adapter.state_layout``); this module maps
canonical states to and from it.

A case's coordinate map produces a canonical engine state: unit quaternions stored
(w, x, y, z) and a ball joint's angular velocity in the body (local) frame. Each engine then
differs only in storage order — measured on the installed versions (tests/dyncheck/
test_conventions.py rotates a body by a known quaternion and reads the result back):

- MuJoCo: ball-joint qpos (w, x, y, z); qvel the angular velocity in the body frame.
- Pinocchio (``JointModelSpherical``, programmatic or from MJCF): q (x, y, z, w); v the
  angular velocity in the joint's local frame.
- Free joints (measured likewise, tests/dyncheck/test_conventions.py): MuJoCo qpos (p, w, x, y,
  z), qvel (v, ω) with the linear velocity of the body origin in the *world* frame and ω in
  the body frame; Pinocchio's free-flyer q (p, x, y, z, w), v (v, ω) *both* in the body frame.
  The canonical state is MuJoCo's; for Pinocchio the linear velocity is v_b = Rᵀ v_w, so
  velocities cross with T = diag(Rᵀ, 1) and accelerations pick up Ṫ v = (−ω × v_b, 0): the
  engine's v̇ is the derivative of body-frame components (the "spatial" acceleration
  Rᵀ p̈ − ω × v_b), not the body's acceleration.
- Drake (measured likewise): its MJCF parser turns a ball joint into ``BallRpyJoint``,
  q = (roll, pitch, yaw) with R = R_z(y) R_y(p) R_x(r) and v = ω in *world* axes (T = R);
  a free joint into ``QuaternionFloatingJoint``, q = (w, x, y, z, p), v = (ω, v) both in
  world axes. Drake integrates the quaternion's components, so its norm drifts: the
  comparison renormalizes.
- sympy-mechanics (dyncheck's own model): a rotating body in Example 9's angles (body Z, X,
  Z), velocities their rates, so v = J⁻¹ ω̄ (exercise 23) and v̇ picks up −J⁻¹ J̇ q̇. Where
  the book has fewer coordinates than the engine (a point mass's spin), least squares and
  least-norm forces are taken in the canonical metric W = T⁻ᵀT⁻¹, not in the angle rates'.
"""

from __future__ import annotations

import numpy as np

from dyncheck.adapters import get_adapter
from dyncheck.adapters.base import Chart, Frame, StateLayout
from dyncheck.cases.coordinate_maps import EulerAngleMap, quat_to_matrix
from dyncheck.cases.multibody import NQ, NV, ROTATING, Multibody
from dyncheck.errors import DyncheckError


def layout(engine: str) -> StateLayout:
    """The state layout the engine's adapter declares (:class:`StateLayout`)."""
    return get_adapter(engine).state_layout


def is_chart(implementation: str) -> bool:
    """Whether an implementation holds a ball joint as angles (a chart), not a quaternion."""
    try:
        adapter = get_adapter(implementation)
    except DyncheckError:  # the reference, the book, an engine that is not installed
        return False
    return adapter.state_layout.ball_chart is not Chart.QUATERNION


def _perm(order: str) -> list[int]:
    return ["wxyz".index(c) for c in order]


def _rpy_from_matrix(R: np.ndarray) -> np.ndarray:
    """(roll, pitch, yaw) with R = R_z(yaw) R_y(pitch) R_x(roll), batched."""
    return np.stack(
        [
            np.arctan2(R[:, 2, 1], R[:, 2, 2]),
            np.arcsin(np.clip(-R[:, 2, 0], -1.0, 1.0)),
            np.arctan2(R[:, 1, 0], R[:, 0, 0]),
        ],
        -1,
    )


def _quat_from_rpy(rpy: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of R_z(y) R_y(p) R_x(r), batched."""
    r, p, y = (rpy[:, i] / 2 for i in range(3))
    cr, sr, cp, sp_, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.stack(
        [
            cr * cp * cy + sr * sp_ * sy,
            sr * cp * cy - cr * sp_ * sy,
            cr * sp_ * cy + sr * cp * sy,
            cr * cp * sy - sr * sp_ * cy,
        ],
        -1,
    )


def _euler(quat: np.ndarray) -> np.ndarray:
    return EulerAngleMap().to_book(quat)


def _unit(quat: np.ndarray) -> np.ndarray:
    """Engines that integrate quaternion components (Drake) let the norm drift: renormalize."""
    return quat / np.linalg.norm(quat, axis=-1, keepdims=True)


def to_native(engine: str, spec: Multibody, qe: np.ndarray) -> np.ndarray:
    """Canonical positions (quaternions (w, x, y, z); a free joint's position first) to the
    engine's storage (quaternion order, a ball joint's chart, a free joint's layout)."""
    if not any(j.type in ROTATING for j in spec.joints):
        return qe
    lay = layout(engine)
    perm = _perm(lay.quaternion_order)
    cols, i = [], 0
    for joint in spec.joints:
        chunk = qe[:, i : i + NQ[joint.type]]
        if joint.type == "ball":
            if lay.ball_chart is Chart.RPY:
                cols.append(_rpy_from_matrix(quat_to_matrix(chunk)))
            elif lay.ball_chart is Chart.EULER:
                cols.append(_euler(chunk))
            else:
                cols.append(chunk[:, perm])
        elif joint.type == "free" and lay.ball_chart is Chart.EULER:
            cols.extend([chunk[:, :3], _euler(chunk[:, 3:])])
        elif joint.type == "free":
            quat = chunk[:, 3:][:, perm]
            parts = [quat, chunk[:, :3]] if lay.quaternion_first else [chunk[:, :3], quat]
            cols.extend(parts)
        else:
            cols.append(chunk)
        i += NQ[joint.type]
    return np.concatenate(cols, -1)


def from_native(engine: str, spec: Multibody, qn: np.ndarray) -> np.ndarray:
    """The engine's storage back to canonical positions."""
    if not any(j.type in ROTATING for j in spec.joints):
        return qn
    lay = layout(engine)
    inverse = np.argsort(_perm(lay.quaternion_order))
    cols, i = [], 0
    for joint in spec.joints:
        if joint.type == "ball" and lay.ball_chart is Chart.RPY:
            cols.append(_quat_from_rpy(qn[:, i : i + 3]))
            i += 3
            continue
        if joint.type in ROTATING and lay.ball_chart is Chart.EULER:
            if joint.type == "free":
                cols.append(qn[:, i : i + 3])
                i += 3
            cols.append(EulerAngleMap().to_engine(qn[:, i : i + 3]))
            i += 3
            continue
        chunk = qn[:, i : i + NQ[joint.type]]
        if joint.type == "ball":
            cols.append(_unit(chunk[:, inverse]))
        elif joint.type == "free":
            if lay.quaternion_first:
                quat, pos = chunk[:, :4], chunk[:, 4:]
            else:
                quat, pos = chunk[:, 3:], chunk[:, :3]
            cols.extend([pos, _unit(quat[:, inverse])])
        else:
            cols.append(chunk)
        i += NQ[joint.type]
    return np.concatenate(cols, -1)


def velocity_frames(engine: str, spec: Multibody, qe: np.ndarray) -> np.ndarray | None:
    """T(q) with v_native = T v_canonical (canonical states, batched (n, nv, nv)), or None
    when the engine's velocities are the canonical ones: a ball joint's ω in world axes
    (Drake: R ω̄), a free joint's v in body axes (Pinocchio: Rᵀ v) or (ω_world, v) (Drake)."""
    rotating = [j for j in spec.joints if j.type in ROTATING]
    if not rotating:
        return None
    lay = layout(engine)
    world_w = lay.angular_velocity_frame is Frame.WORLD
    rates = lay.angular_velocity_frame is Frame.EULER_RATES
    local_v = lay.linear_velocity_frame is Frame.LOCAL
    if not (world_w or rates or (local_v and any(j.type == "free" for j in rotating))):
        return None
    n = qe.shape[0]
    T = np.broadcast_to(np.eye(spec.nv), (n, spec.nv, spec.nv)).copy()
    i = k = 0
    for joint in spec.joints:
        if joint.type in ROTATING and rates:  # q̇ = J⁻¹ ω̄ (exercise 23 inverted)
            a, b = (i + 3, k + 3) if joint.type == "free" else (i, k)
            angles = _euler(qe[:, a : a + 4])
            T[:, b : b + 3, b : b + 3] = np.linalg.inv(EulerAngleMap().jacobian(angles))
        elif joint.type == "ball" and world_w:
            T[:, k : k + 3, k : k + 3] = quat_to_matrix(qe[:, i : i + 4])
        elif joint.type == "free":
            R = quat_to_matrix(qe[:, i + 3 : i + 7])
            lin = np.swapaxes(R, -1, -2) if local_v else np.broadcast_to(np.eye(3), R.shape)
            ang = R if world_w else np.broadcast_to(np.eye(3), R.shape)
            T[:, k : k + 6, k : k + 6] = 0.0
            if lay.angular_first:
                T[:, k : k + 3, k + 3 : k + 6] = ang
                T[:, k + 3 : k + 6, k : k + 3] = lin
            else:
                T[:, k : k + 3, k : k + 3] = lin
                T[:, k + 3 : k + 6, k + 3 : k + 6] = ang
        i += NQ[joint.type]
        k += NV[joint.type]
    return T


def velocity_frame_rates(
    engine: str, spec: Multibody, qe: np.ndarray, ve: np.ndarray, T: np.ndarray
) -> np.ndarray:
    """Ṫ v for canonical states and velocities, given T = :func:`velocity_frames` there:
    (−ω × Rᵀ v_w, 0) for a free joint whose v is in body axes; R ω̄ in world axes has
    Ṙ ω̄ = R (ω̄ × ω̄) = 0; an Euler chart's −J⁻¹ J̇ q̇."""
    out = np.zeros_like(ve)
    lay = layout(engine)
    if lay.angular_velocity_frame is Frame.EULER_RATES:
        # d/dt (J⁻¹ ω̄) = −J⁻¹ J̇ q̇ with q̇ = J⁻¹ ω̄ (the Euler chart's own (2.2.5) term)
        i = k = 0
        for joint in spec.joints:
            if joint.type in ROTATING:
                a, b = (i + 3, k + 3) if joint.type == "free" else (i, k)
                angles = _euler(qe[:, a : a + 4])
                Tb = T[:, b : b + 3, b : b + 3]
                qdot = np.einsum("nij,nj->ni", Tb, ve[:, b : b + 3])
                out[:, b : b + 3] = -np.einsum(
                    "nij,nj->ni", Tb, EulerAngleMap().hessian_term(angles, qdot)
                )
            i += NQ[joint.type]
            k += NV[joint.type]
        return out
    if lay.linear_velocity_frame is not Frame.LOCAL:
        return out
    i = k = 0
    for joint in spec.joints:
        if joint.type == "free":
            R = quat_to_matrix(qe[:, i + 3 : i + 7])
            vb = np.einsum("nji,nj->ni", R, ve[:, k : k + 3])
            out[:, k : k + 3] = -np.cross(ve[:, k + 3 : k + 6], vb)
        i += NQ[joint.type]
        k += NV[joint.type]
    return out
