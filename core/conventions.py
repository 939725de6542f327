"""Engine state conventions, found by experiment and written once (tests hold them).

A case's coordinate map produces a canonical engine state: unit quaternions stored
(w, x, y, z) and a ball joint's angular velocity in the body (local) frame. Each engine then
differs only in storage order — measured on the installed versions (tests/core/
test_conventions.py rotates a body by a known quaternion and reads the result back):

- MuJoCo: ball-joint qpos (w, x, y, z); qvel the angular velocity in the body frame.
- Pinocchio (``JointModelSpherical``, programmatic or from MJCF): q (x, y, z, w); v the
  angular velocity in the joint's local frame.
- Free joints (measured likewise, tests/core/test_conventions.py): MuJoCo qpos (p, w, x, y,
  z), qvel (v, ω) with the linear velocity of the body origin in the *world* frame and ω in
  the body frame; Pinocchio's free-flyer q (p, x, y, z, w), v (v, ω) *both* in the body frame.
  The canonical state is MuJoCo's; for Pinocchio the linear velocity is v_b = Rᵀ v_w, so
  velocities cross with T = diag(Rᵀ, 1) and accelerations pick up Ṫ v = (−ω × v_b, 0): the
  engine's v̇ is the derivative of body-frame components (the "spatial" acceleration
  Rᵀ p̈ − ω × v_b), not the body's acceleration.
- Drake's MJCF parser turns a ball joint into ``BallRpyJoint`` (roll-pitch-yaw angles, their
  rates as velocities) and sympy.physics.mechanics needs a chart of three angles: neither has
  a quaternion state, so dyncheck does not map ball joints for them (their rows are skipped
  with this reason).
"""

from __future__ import annotations

import numpy as np

from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.cases.multibody import NQ, NV, Multibody

QUATERNION_ORDER: dict[str, str] = {
    "mujoco": "wxyz",
    "pinocchio": "xyzw",
    "pinocchio-mjcf": "xyzw",
}
"""How each engine stores a ball joint's quaternion."""

ANGULAR_VELOCITY_FRAME: dict[str, str] = {
    "mujoco": "local",
    "pinocchio": "local",
    "pinocchio-mjcf": "local",
}
"""In which frame each engine expresses a ball or free joint's angular velocity."""

LINEAR_VELOCITY_FRAME: dict[str, str] = {
    "mujoco": "world",
    "pinocchio": "local",
    "pinocchio-mjcf": "local",
}
"""In which frame each engine expresses a free joint's linear velocity."""


def quaternion_slots(spec: Multibody) -> list[int]:
    """Index of each ball or free joint's quaternion in the position coordinates."""
    out, i = [], 0
    for joint in spec.joints:
        if joint.type == "ball":
            out.append(i)
        elif joint.type == "free":
            out.append(i + 3)
        i += NQ[joint.type]
    return out


def _free_slots(spec: Multibody) -> list[tuple[int, int]]:
    """(position index, velocity index) of each free joint."""
    out, i, k = [], 0, 0
    for joint in spec.joints:
        if joint.type == "free":
            out.append((i, k))
        i += NQ[joint.type]
        k += NV[joint.type]
    return out


def velocity_frames(engine: str, spec: Multibody, qe: np.ndarray) -> np.ndarray | None:
    """T(q) with v_native = T v_canonical (canonical states, batched (n, nv, nv)), or None
    when the engine's frames are the canonical ones."""
    slots = _free_slots(spec)
    if not slots or LINEAR_VELOCITY_FRAME.get(engine, "world") == "world":
        return None
    T = np.broadcast_to(np.eye(spec.nv), (qe.shape[0], spec.nv, spec.nv)).copy()
    for i, k in slots:
        T[:, k : k + 3, k : k + 3] = np.swapaxes(quat_to_matrix(qe[:, i + 3 : i + 7]), -1, -2)
    return T


def velocity_frame_rates(
    engine: str, spec: Multibody, qe: np.ndarray, ve: np.ndarray
) -> np.ndarray | None:
    """Ṫ v for canonical states and velocities: (−ω × Rᵀ v_w, 0) per free joint."""
    slots = _free_slots(spec)
    if not slots or LINEAR_VELOCITY_FRAME.get(engine, "world") == "world":
        return None
    out = np.zeros_like(ve)
    for i, k in slots:
        R = quat_to_matrix(qe[:, i + 3 : i + 7])
        vb = np.einsum("nji,nj->ni", R, ve[:, k : k + 3])
        out[:, k : k + 3] = -np.cross(ve[:, k + 3 : k + 6], vb)
    return out


def _perm(order: str) -> list[int]:
    return ["wxyz".index(c) for c in order]


def to_native(engine: str, spec: Multibody, qe: np.ndarray) -> np.ndarray:
    """Canonical (w, x, y, z) quaternions to the engine's storage order."""
    slots = quaternion_slots(spec)
    if not slots:
        return qe
    perm = _perm(QUATERNION_ORDER[engine])
    out = qe.copy()
    for s in slots:
        out[..., s : s + 4] = qe[..., [s + p for p in perm]]
    return out


def from_native(engine: str, spec: Multibody, qn: np.ndarray) -> np.ndarray:
    """The engine's storage order back to canonical (w, x, y, z)."""
    slots = quaternion_slots(spec)
    if not slots:
        return qn
    perm = _perm(QUATERNION_ORDER[engine])
    out = qn.copy()
    for s in slots:
        out[..., [s + p for p in perm]] = qn[..., s : s + 4]
    return out
