"""A PyBullet multibody's joint state, as dyncheck sets and reads it: its joints placed at
coordinates (a spherical joint's quaternion x-y-z-w) and velocities, read back, and its
motors switched off so that a step is its integrator alone. A mixin of
:class:`~.model.PybulletModel`, which holds the attributes it names."""

from __future__ import annotations

import pybullet as pb

from dyncheck.adapters.model_tree import JointType

KINDS = {pb.JOINT_REVOLUTE: JointType.HINGE, pb.JOINT_PRISMATIC: JointType.SLIDE,
          pb.JOINT_SPHERICAL: JointType.BALL}
REST = {pb.JOINT_REVOLUTE: (0.0,), pb.JOINT_PRISMATIC: (0.0,),
         pb.JOINT_SPHERICAL: (0.0, 0.0, 0.0, 1.0)}
"""A joint's coordinates at the reference configuration (a spherical joint's quaternion
x-y-z-w: the identity)."""


class PybulletState:
    """Setting and reading the joints of the multibodies :attr:`bodies` of :attr:`client`."""

    client: int
    bodies: list[int]
    _movable: dict[int, list[tuple[int, int]]]
    _damping: dict[tuple[int, int], float]
    _floating: dict[int, bool]

    def _place(self, body: int, joints: list[float], velocities: list[float] | None = None,
               ) -> None:
        """The body's joints at coordinates ``joints`` (a spherical joint's quaternion
        x-y-z-w), at rest or at ``velocities``."""
        c, at, dof = self.client, 0, 0
        for j, kind in self._movable.get(body, []):
            nq, nv = len(REST[kind]), JointType(KINDS[kind]).nv
            rate = [0.0] * nv if velocities is None else velocities[dof : dof + nv]
            if kind == pb.JOINT_SPHERICAL:
                pb.resetJointStateMultiDof(body, j, joints[at : at + nq], rate,
                                           physicsClientId=c)
            else:
                pb.resetJointState(body, j, joints[at], rate[0], physicsClientId=c)
            at, dof = at + nq, dof + nv

    def _free_motion(self, body: int, *, keep_joint_damping: bool = False) -> None:
        """Every motor of the body off and its links' damping 0 (its joints' too, unless
        ``keep_joint_damping``: the file's): what is left of a step is its semi-implicit
        Euler of its articulated-body forward dynamics."""
        c = self.client
        pb.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)
        for j, kind in self._movable.get(body, []):
            if kind == pb.JOINT_SPHERICAL:
                pb.setJointMotorControlMultiDof(body, j, pb.POSITION_CONTROL,
                                                targetPosition=list(REST[kind]),
                                                positionGain=0.0, velocityGain=0.0,
                                                force=[0.0] * 3, physicsClientId=c)
            else:
                pb.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, force=0.0,
                                         physicsClientId=c)
            damping = self._damping[(body, j)] if keep_joint_damping else 0.0
            pb.changeDynamics(body, j, linearDamping=0.0, angularDamping=0.0,
                              jointDamping=damping, physicsClientId=c)

    def _joint_states(self, body: int, which: int) -> list[float]:
        """The body's joint coordinates (``which`` 0) or velocities (1), a spherical joint's
        through its multi-DoF state."""
        out: list[float] = []
        for j, kind in self._movable.get(body, []):
            if kind == pb.JOINT_SPHERICAL:
                out += pb.getJointStateMultiDof(body, j, physicsClientId=self.client)[which]
            else:
                out.append(pb.getJointState(body, j, physicsClientId=self.client)[which])
        return out

    def _positions(self, body: int) -> list[float]:
        return self._joint_states(body, 0)

    def _velocities(self, body: int) -> list[float]:
        return self._joint_states(body, 1)

    def _size(self, body: int) -> tuple[int, int]:
        """The body's nq and nv (its moving base's included)."""
        movable = self._movable.get(body, [])
        base_q, base_v = (7, 6) if self._floating[body] else (0, 0)
        return (base_q + sum(len(REST[k]) for _, k in movable),
                base_v + sum(JointType(KINDS[k]).nv for _, k in movable))
