"""PyBullet's spherical joint and the rotation of its link's inertial frame: a rigid body with
products of inertia on a spherical joint, stepped once from a spin, against Euler's equations
(2.2.49) about its fixed centre of mass — with the tensor the file states and with its
principal moments in the link's axes (the inertial frame's rotation dropped)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from dyncheck.explain.entry import Entry

TENSOR = ((0.9, 0.1, -0.05), (0.1, 1.4, 0.08), (-0.05, 0.08, 2.0))
"""The body's inertia about its centre of mass (kg m²), products included."""
OMEGA = (0.7, -1.3, 0.9)
"""The spin the step starts from (rad/s, the link's axes)."""


def urdf(tensor: tuple[tuple[float, ...], ...] = TENSOR) -> str:
    """A rigid body on a spherical joint at its centre of mass."""
    i = tensor
    return f"""<robot name="spinning">
  <link name="world"/>
  <link name="body"><inertial><mass value="2.0"/><inertia ixx="{i[0][0]}" ixy="{i[0][1]}"
    ixz="{i[0][2]}" iyy="{i[1][1]}" iyz="{i[1][2]}" izz="{i[2][2]}"/></inertial></link>
  <joint name="ball" type="spherical"><parent link="world"/><child link="body"/></joint>
</robot>
"""


def euler(tensor: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """ω̇ = I⁻¹ (−ω × I ω): Euler's equations with no torque (gravity acts at the fixed
    centre of mass)."""
    return np.linalg.solve(tensor, -np.cross(omega, tensor @ omega))


def pybullet_spherical_inertia() -> Entry:
    """PyBullet's ω̇ (one stepSimulation of 1e-4 s, motors and damping off) against Euler's
    equations with the stated tensor and with diag(principal moments)."""
    from dyncheck.adapters.c_output import c_output_dropped

    with c_output_dropped():  # its import prints a line of its own (on stderr)
        import pybullet as pb

    dt, omega = 1e-4, np.array(OMEGA)
    client = pb.connect(pb.DIRECT)
    try:
        with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder, \
                c_output_dropped():  # (its URDF parser's note on the joint's axis)
            path = Path(folder) / "spinning.urdf"
            path.write_text(urdf(), encoding="utf-8")
            body = pb.loadURDF(str(path), useFixedBase=True,
                               flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        pb.setTimeStep(dt, physicsClientId=client)
        pb.changeDynamics(body, 0, linearDamping=0.0, angularDamping=0.0,
                          physicsClientId=client)
        pb.setJointMotorControlMultiDof(body, 0, pb.POSITION_CONTROL,
                                        targetPosition=[0, 0, 0, 1], positionGain=0.0,
                                        velocityGain=0.0, force=[0.0] * 3,
                                        physicsClientId=client)
        pb.resetJointStateMultiDof(body, 0, [0, 0, 0, 1], list(omega), physicsClientId=client)
        pb.stepSimulation(physicsClientId=client)
        after = np.array(pb.getJointStateMultiDof(body, 0, physicsClientId=client)[1])
    finally:
        pb.disconnect(client)
    observed = (after - omega) / dt
    tensor = np.array(TENSOR)
    stated = euler(tensor, omega)
    principal = euler(np.diag(np.linalg.eigvalsh(tensor)), omega)
    scale = float(np.abs(stated).max())
    return Entry(
        "pybullet-spherical-inertia",
        "A rigid body's inertia is a tensor: with products of inertia its principal axes "
        "are not the link's, and Euler's equations (2.2.49) take the whole tensor. A body "
        "spun about its fixed centre of mass, one step.",
        "PyBullet 3.2.7's URDF importer holds the tensor as principal moments and the "
        "rotation of the inertial frame (getDynamicsInfo); on a spherical joint its "
        "dynamics — calculateMassMatrix and stepSimulation alike — take the moments in the "
        "link's own axes, dropping that rotation (a revolute joint keeps it). MuJoCo, "
        "Pinocchio and Drake take the tensor. dyncheck declares the inertia PyBullet "
        "computes with and predicts the difference (explained rows); fix: a diagonal tensor "
        "(inertial frame on the principal axes).",
        "the tensor the file states, as PyBullet holds it",
        float(np.abs(observed - stated).max()) / scale,
        float(np.abs(observed - principal).max()) / scale,
        "relative error of PyBullet's stepped ω̇ against Euler's equations",
    )
