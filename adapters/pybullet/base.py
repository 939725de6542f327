"""A PyBullet multibody's moving base: its state in the tree's layout (q = (p, quat x-y-z-w)
of its centre-of-mass frame, v = (ω in that frame's axes, the centre of mass's velocity in
world axes)), set and read through PyBullet's base state, and its dynamics' rows mapped to that
layout. PyBullet's own conventions here were measured (see each function)."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from dyncheck.adapters.pybullet.files import rotation_of


def place_base(client: int, body: int, q: list[float], v: list[float]) -> None:
    """A moving base at (q, v) in the tree's layout; ``resetBaseVelocity`` takes both
    velocities in world axes."""
    pb.resetBasePositionAndOrientation(body, q[:3], q[3:7], physicsClientId=client)
    omega = rotation_of(tuple(q[3:7])) @ np.array(v[:3])
    pb.resetBaseVelocity(body, v[3:6], [float(x) for x in omega], physicsClientId=client)


def base_state(client: int, body: int) -> tuple[list[float], list[float]]:
    """A moving base's (q, v) in the tree's layout (:func:`place_base` inverted:
    ``getBaseVelocity`` gives both velocities in world axes)."""
    position, quat = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    linear, angular = pb.getBaseVelocity(body, physicsClientId=client)
    omega = rotation_of(tuple(quat)).T @ np.array(angular)
    return [*position, *quat], [*(float(x) for x in omega), *linear]


def world_linear(quat_xyzw: np.ndarray, mass: np.ndarray, bias: np.ndarray,
                  tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A moving base's rows in one convention, v = (ω in the centre-of-mass frame's axes,
    the centre of mass's velocity in world axes, joints) — the v ``calculateInverseDynamics``
    takes. Measured against Pinocchio (gravity off, any base orientation: agreement to
    round-off once mapped): ``calculateInverseDynamics`` takes the linear acceleration in the
    frame's axes (mapped by the caller, Rᵀ v̇) and returns (force, torque, joints) with the
    force in the frame's axes (reordered and rotated to world axes here, R F);
    ``calculateMassMatrix`` takes the linear velocity in the frame's axes (its M does not
    change with the base's orientation; mapped here by R)."""
    rot = rotation_of(tuple(quat_xyzw))
    t = np.eye(len(mass))
    t[3:6, 3:6] = rot.T
    order = np.r_[3:6, 0:3, 6:len(mass)]
    bias, tau = bias[order], tau[order]
    bias[3:6], tau[3:6] = rot @ bias[3:6], rot @ tau[3:6]
    return t.T @ mass @ t, bias, tau
