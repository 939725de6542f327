"""Rigid bodies (§2.2, (2.2.37)–(2.2.72)): a body turning about its fixed centre of mass.

Book coordinates: Example 9's Euler angles (φ, θ, ψ) of the body axes x̄ relative to space
axes x (x = ℓ x̄, ℓ the direction cosines (2.2.50)); rates (φ̇, θ̇, ψ̇). Engines: one ball
joint at the centre of mass, orientation ℓ as a unit quaternion, velocity the body-frame
angular velocity ω̄ of exercise 23. The body's frame is not principal (products of inertia),
so Euler's equations appear in their general form (2.2.71).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from dyncheck.cases.base import STEPS, Case, TrajectorySpec
from dyncheck.cases.coordinate_maps import EulerAngleMap, FreeBodyMap
from dyncheck.cases.multibody import Body, Joint, Multibody
from dyncheck.errors import inertia_tensor, positive
from dyncheck.vocabulary import Integrator

RIGID_STEPS = {
    **STEPS,
    Integrator.RK2: (2e-2, 1e-2, 5e-3, 2.5e-3),
    Integrator.RK3: (4e-2, 2e-2, 1e-2, 5e-3),
    Integrator.RK4: (8e-2, 4e-2, 2e-2, 1e-2),
}
"""A free rotation is smooth enough that MuJoCo's RK4 reaches the reference's accuracy below
1e-2: its study starts coarser; Drake's RK2 and RK3 likewise (Euler keeps the default)."""


@dataclass(frozen=True)
class RigidBodyBall(Case):
    """A rigid body with products of inertia on a ball joint at its centre of mass, no torque
    but the applied generalized forces (gravity acts at the fixed point)::

             x̄₃
              |  ╱ x̄₂      body axes, turned by (φ, θ, ψ) from space axes
           ───●───  ball joint at the centre of mass
    """

    name: ClassVar[str] = "rigid_body_ball"
    title: ClassVar[str] = "Rigid body about its centre of mass (Euler's equations)"
    book_refs: ClassVar[str] = (
        "(2.2.39)-(2.2.42), Example 9, (2.2.61)-(2.2.62), exercise 23, (2.2.70)-(2.2.71)"
    )
    coordinates: ClassVar[tuple[str, ...]] = ("φ", "θ", "ψ")
    periodic: ClassVar[tuple[bool, ...]] = (True, False, True)
    joint: ClassVar[str] = "ball"
    """The engine joint at the centre of mass (its type and name)."""

    m: float = 2.0
    """mass, kg"""
    I11: float = 0.9
    """moment of inertia about x̄₁, kg m²"""
    I22: float = 1.4
    """moment of inertia about x̄₂, kg m²"""
    I33: float = 2.0
    """moment of inertia about x̄₃, kg m²"""
    I12: float = 0.1
    """product of inertia, kg m² (I_12 of (2.2.39): −Σ m x̄₁ x̄₂)"""
    I13: float = -0.05
    """product of inertia, kg m²"""
    I23: float = 0.08
    """product of inertia, kg m²"""
    g: float = 9.81
    """gravity, m/s² (acts at the fixed centre of mass: no moment)"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(0.3, 1.4, -0.5), v0=(0.2, 0.3, 1.6), duration=2.0, steps=RIGID_STEPS
        )
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        positive("m", self.m)
        positive("g", self.g)
        inertia_tensor("inertia", self.inertia())
        self.check_state("q0", self.trajectory.q0)

    def inertia(self) -> np.ndarray:
        """Ī_ij in body axes, kg m²."""
        return np.array(
            [
                [self.I11, self.I12, self.I13],
                [self.I12, self.I22, self.I23],
                [self.I13, self.I23, self.I33],
            ]
        )

    def params(self) -> dict[str, float]:
        return {
            "m": self.m,
            "I11": self.I11,
            "I22": self.I22,
            "I33": self.I33,
            "I12": self.I12,
            "I13": self.I13,
            "I23": self.I23,
            "g": self.g,
        }

    def multibody(self) -> Multibody:
        inertia = tuple(tuple(float(x) for x in row) for row in self.inertia())
        joint = Joint(self.joint, self.joint)
        body = Body("body", None, (0, 0, 0), (joint,), self.m, (0.0, 0.0, 0.0), inertia)
        return Multibody(self.name, (body,), (0.0, 0.0, -self.g))

    def engine_map(self) -> EulerAngleMap:
        return EulerAngleMap()

    def chart_singularity(self, q: np.ndarray) -> str | None:
        theta = q[1] % (2 * np.pi)
        if min(theta, abs(theta - np.pi), 2 * np.pi - theta) < 1e-6:
            return "θ = 0 or π, gimbal lock of Example 9's angles, where φ and ψ merge"
        return None

    def rest(self) -> np.ndarray:
        return np.array([0.0, np.pi / 2, 0.0])

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """θ ∉ {0, π}: the chart is singular there."""
        return np.array([-np.pi, 0.3, -np.pi]), np.array([np.pi, np.pi - 0.3, np.pi])

    def state_scale(self) -> tuple[float, float, float]:
        return 2.0, 2.0 * self.I33, 4.0


@dataclass(frozen=True)
class TorqueFree(RigidBodyBall):
    """The same body in principal axes, I₁ < I₂ < I₃, turning freely near its intermediate
    axis (ω̄(0) ≈ (0.2, 1.5, 0.2) rad/s): Euler's equations (2.2.72) with M = 0, whose
    solution the book says is given by Jacobi elliptic functions — the closed form the
    reference's trajectory is checked against."""

    name: ClassVar[str] = "torque_free"
    title: ClassVar[str] = "Torque-free asymmetric body (Jacobi elliptic closed form)"
    book_refs: ClassVar[str] = "(2.2.72), (2.2.40), (2.2.49), exercise 23, Example 9"

    I11: float = 1.0
    """principal moment, kg m²"""
    I22: float = 2.0
    """principal moment (intermediate), kg m²"""
    I33: float = 3.0
    """principal moment, kg m²"""
    I12: float = 0.0
    """product of inertia: zero, principal axes"""
    I13: float = 0.0
    """product of inertia: zero, principal axes"""
    I23: float = 0.0
    """product of inertia: zero, principal axes"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(0.3, 1.2, -0.4), v0=(1.4, 0.77, -0.31), duration=4.0, steps=RIGID_STEPS
        )
    )


@dataclass(frozen=True)
class RigidBodyFree(RigidBodyBall):
    """The body of ``rigid_body_ball`` flying free under gravity: translation of the centre
    of mass (2.2.48) and rotation about it (2.2.70)–(2.2.71), uncoupled. Engines: a free
    joint (MuJoCo ``freejoint``: linear velocity in the world frame; Pinocchio free-flyer:
    in the body frame — the comparison layer maps both)."""

    name: ClassVar[str] = "rigid_body_free"
    title: ClassVar[str] = "Free rigid body (translation and Euler's equations)"
    book_refs: ClassVar[str] = "(2.2.44)-(2.2.49), Example 9, exercise 23, (2.2.70)-(2.2.71)"
    coordinates: ClassVar[tuple[str, ...]] = ("x1", "x2", "x3", "φ", "θ", "ψ")
    periodic: ClassVar[tuple[bool, ...]] = (False, False, False, True, False, True)
    joint: ClassVar[str] = "free"

    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(0.1, -0.2, 0.5, 0.3, 1.4, -0.5),
            v0=(0.4, 0.3, 2.0, 0.2, 0.3, 1.6),
            duration=2.0,
            steps=RIGID_STEPS,
        )
    )

    def engine_map(self) -> FreeBodyMap:
        return FreeBodyMap()

    def chart_singularity(self, q: np.ndarray) -> str | None:
        return super().chart_singularity(q[3:])

    def rest(self) -> np.ndarray:
        return np.array([0.0, 0.0, 0.0, 0.0, np.pi / 2, 0.0])

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        low, high = super().q_bounds()
        return np.concatenate([[-1.0, -1.0, -1.0], low]), np.concatenate([[1.0, 1.0, 1.0], high])

    def state_scale(self) -> tuple[float, float, float]:
        return 2.0, max(2.0 * self.I33, self.m * self.g), 10.0
