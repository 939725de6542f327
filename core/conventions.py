"""Engine state conventions, found by experiment and written once (tests hold them).

A case's coordinate map produces a canonical engine state: unit quaternions stored
(w, x, y, z) and a ball joint's angular velocity in the body (local) frame. Each engine then
differs only in storage order — measured on the installed versions (tests/core/
test_conventions.py rotates a body by a known quaternion and reads the result back):

- MuJoCo: ball-joint qpos (w, x, y, z); qvel the angular velocity in the body frame.
- Pinocchio (``JointModelSpherical``, programmatic or from MJCF): q (x, y, z, w); v the
  angular velocity in the joint's local frame.
- Drake's MJCF parser turns a ball joint into ``BallRpyJoint`` (roll-pitch-yaw angles, their
  rates as velocities) and sympy.physics.mechanics needs a chart of three angles: neither has
  a quaternion state, so dyncheck does not map ball joints for them (their rows are skipped
  with this reason).
"""

from __future__ import annotations

import numpy as np

from dyncheck.cases.multibody import NQ, Multibody

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
"""In which frame each engine expresses a ball joint's angular velocity."""


def quaternion_slots(spec: Multibody) -> list[int]:
    """Index of each ball joint's first position coordinate."""
    out, i = [], 0
    for joint in spec.joints:
        if joint.type == "ball":
            out.append(i)
        i += NQ[joint.type]
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
