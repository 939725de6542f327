"""An engine-neutral description of a kinematic tree, from which every adapter builds its model.

Units: SI (kg, m, kg·m², m/s²). Frames: each body frame sits at its joints; ``joint_pos`` is that
origin in the parent's frame (world for the first body); ``com`` and ``inertia`` (about the
centre of mass, in body axes) are in the body's frame. A point mass has a zero inertia tensor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dyncheck.errors import InvalidInput, finite_array, inertia_tensor, positive
from dyncheck.vocabulary import ROTATING, JointType

Vec3 = tuple[float, float, float]
Mat3 = tuple[Vec3, Vec3, Vec3]
ZERO3: Mat3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


JOINT_TYPES = tuple(t.value for t in JointType)
"""A joint's ``type``, as text (:class:`~dyncheck.vocabulary.JointType` defines them)."""
NQ = {t.value: t.nq for t in JointType}
"""Position coordinates per joint type."""
NV = {t.value: t.nv for t in JointType}
"""Velocity coordinates per joint type."""


@dataclass(frozen=True)
class Joint:
    """``hinge`` (angle about ``axis``, rad), ``slide`` (displacement along ``axis``, m) or
    ``ball`` (a rotation about the joint's origin; ``axis`` unused); ``axis`` a unit vector
    in the body frame."""

    name: str
    type: str
    axis: Vec3 = (0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        if self.type not in JOINT_TYPES:
            raise InvalidInput(f"{self.name}.type", self.type, f"one of {JOINT_TYPES}")
        finite_array(f"{self.name}.axis", self.axis, (3,))
        if abs(float(np.linalg.norm(self.axis)) - 1.0) > 1e-12:
            raise InvalidInput(f"{self.name}.axis", self.axis, "a unit vector")


@dataclass(frozen=True)
class Body:
    """One rigid body moved relative to its parent (``None`` = the world) by its joints,
    applied in order (the first is nearest the parent), all at the body frame's origin."""

    name: str
    parent: str | None
    joint_pos: Vec3
    joints: tuple[Joint, ...]
    mass: float
    com: Vec3
    inertia: Mat3 = ZERO3

    def __post_init__(self) -> None:
        positive(f"{self.name}.mass", self.mass)
        finite_array(f"{self.name}.joint_pos", self.joint_pos, (3,))
        finite_array(f"{self.name}.com", self.com, (3,))
        inertia_tensor(f"{self.name}.inertia", np.asarray(self.inertia), allow_zero=True)
        if not self.joints:
            raise InvalidInput(f"{self.name}.joints", self.joints, "at least one joint")

    @property
    def is_point_mass(self) -> bool:
        return not np.any(np.asarray(self.inertia))


@dataclass(frozen=True)
class Coupling:
    """A linear holonomic constraint Σⱼ cⱼ qⱼ = 0 on slide or hinge joint coordinates, zero at
    the model's reference configuration (all joint coordinates 0): an inextensible cord whose
    length change is Σⱼ cⱼ qⱼ. Its multiplier f enters the joint equations as
    M v̇ + h = τ + cᵀ f; for a cord pulled taut, f = −(cord tension)."""

    name: str
    coefs: tuple[tuple[str, float], ...]
    """(joint name, coefficient) pairs."""

    def __post_init__(self) -> None:
        if not self.coefs:
            raise InvalidInput(f"{self.name}.coefs", self.coefs, "at least one joint")
        for joint, c in self.coefs:
            if not np.isfinite(c) or c == 0:
                raise InvalidInput(f"{self.name}.coefs[{joint}]", c, "a finite non-zero number")


@dataclass(frozen=True)
class Multibody:
    """A tree of bodies in parent-before-child order, under uniform gravity.

    ``mjcf_point_inertia`` is the diagonal inertia (kg·m²) written for point masses in formats
    that reject a zero body inertia: MuJoCo's compiler requires mass and inertia of moving
    bodies > mjMINVAL = 1e-15. It is a modelling choice the comparison must explain.
    """

    name: str
    bodies: tuple[Body, ...]
    gravity: Vec3
    mjcf_point_inertia: float = 1e-8
    central_mu: float = 0.0
    """μ of an inverse-square attraction F = −μ m r/|r|³ toward the world origin on every
    body's centre of mass (m³/s²), applied through each engine's external-force input."""
    couplings: tuple[Coupling, ...] = ()
    """Linear constraints between joint coordinates (cords over pulleys)."""

    def __post_init__(self) -> None:
        finite_array("gravity", self.gravity, (3,))
        positive("mjcf_point_inertia", self.mjcf_point_inertia)
        if self.central_mu:
            positive("central_mu", self.central_mu)
        seen: set[str | None] = {None}
        for body in self.bodies:
            if body.parent not in seen:
                raise ValueError(f"body {body.name!r}: parent {body.parent!r} must come first")
            seen.add(body.name)
        types = {j.name: j.type for j in self.joints}
        for coupling in self.couplings:
            for joint, _ in coupling.coefs:
                if types.get(joint) not in ("slide", "hinge"):
                    raise InvalidInput(
                        f"{coupling.name}.coefs", joint, "the name of a slide or hinge joint"
                    )

    def coupling_matrix(self, positions: bool = False) -> np.ndarray:
        """The constraint rows C: (n_couplings, nv) on velocity coordinates (C v = 0), or with
        ``positions`` (n_couplings, nq) on position coordinates (C q = 0, the violation)."""
        size = NQ if positions else NV
        index, k = {}, 0
        for j in self.joints:
            index[j.name] = k
            k += size[j.type]
        C = np.zeros((len(self.couplings), k))
        for i, coupling in enumerate(self.couplings):
            for joint, c in coupling.coefs:
                C[i, index[joint]] += c
        return C

    @property
    def joints(self) -> tuple[Joint, ...]:
        """All joints, in coordinate order."""
        return tuple(j for b in self.bodies for j in b.joints)

    def central_force(self, mass: float, position: np.ndarray) -> np.ndarray:
        """F = −μ m r/|r|³ on a body of ``mass`` at world ``position`` (zero if μ = 0)."""
        if not self.central_mu:
            return np.zeros(3)
        x, y, z = position  # one body per call, each stage of a step: scalar arithmetic
        r = math.sqrt(x * x + y * y + z * z)
        k = -self.central_mu * mass / r**3
        return np.array([k * x, k * y, k * z])

    @property
    def nq(self) -> int:
        return sum(NQ[j.type] for j in self.joints)

    @property
    def nv(self) -> int:
        return sum(NV[j.type] for j in self.joints)

    def body_inertia(self, body: Body) -> np.ndarray:
        """The inertia a model must hold for ``body``: its own, or — for a point mass on a
        ball joint, whose spin about the rod would otherwise have no inertia and make M
        singular — the isotropic floor ``mjcf_point_inertia``."""
        if body.is_point_mass and any(j.type in ROTATING for j in body.joints):
            return self.mjcf_point_inertia * np.eye(3)
        return np.asarray(body.inertia, float)
