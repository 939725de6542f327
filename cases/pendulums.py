"""Examples 7 (simple pendulum) and 8 (compound pendulum) of §2.2.

Book coordinates: absolute angles θ from the downward vertical, positive when the bob moves
toward +x, bob at (ℓ sin θ, −ℓ cos θ) (2.2.28). Engines: the book's plane is the world x–z
plane (z up, gravity −z), hinges about +y with *relative* angles. A rotation α about +y takes
(0, 0, −ℓ) to (−ℓ sin α, 0, −ℓ cos α), so the engine angle is α = −θ (hinge axis sign) and,
down the chain, α₂ = −(θ₂ − θ₁) (relative angles).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from dyncheck.cases.base import STEPS, Case, TrajectorySpec
from dyncheck.cases.coordinate_maps import LinearMap, SphericalPendulumMap
from dyncheck.cases.multibody import Body, Joint, Multibody
from dyncheck.errors import positive

Y_AXIS = (0.0, 1.0, 0.0)


@dataclass(frozen=True)
class SimplePendulum(Case):
    """Example 7: a point mass m on a massless rod of length ℓ::

    O  pivot
     \\ θ
      \\  ℓ
       ●  m
    """

    name: ClassVar[str] = "simple_pendulum"
    title: ClassVar[str] = "Simple pendulum (Example 7)"
    book_refs: ClassVar[str] = "Example 7; (2.2.21), (2.2.25), (2.2.26)"
    coordinates: ClassVar[tuple[str, ...]] = ("θ",)

    m: float = 1.3
    """bob mass, kg"""
    l: float = 0.9
    """rod length, m"""
    g: float = 9.81
    """gravity, m/s²"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(q0=(1.1,), v0=(0.4,), duration=2.0, steps=STEPS)
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("m", "l", "g"):
            positive(name, getattr(self, name))

    def params(self) -> dict[str, float]:
        return {"m": self.m, "l": self.l, "g": self.g}

    def multibody(self) -> Multibody:
        bob = Body(
            "bob", None, (0, 0, 0), (Joint("hinge", "hinge", Y_AXIS),), self.m, (0.0, 0.0, -self.l)
        )
        return Multibody(self.name, (bob,), (0.0, 0.0, -self.g))

    def engine_map(self) -> LinearMap:
        return LinearMap(((-1.0,),), (0.0,), "α = −θ (hinge about +y)")

    def rest(self) -> np.ndarray:
        return np.zeros(1)

    def state_scale(self) -> tuple[float, float, float]:
        w = np.sqrt(self.g / self.l)
        return 2 * w, self.m * self.g * self.l, 2 * w * w


@dataclass(frozen=True)
class CompoundPendulum(Case):
    """Example 8: two point masses on massless rods, angles absolute (2.2.28)::

            O
             \\ θ₁  L₁
              ● m₁
              |\\
              | \\ θ₂  L₂
                 ● m₂
    """

    name: ClassVar[str] = "compound_pendulum"
    title: ClassVar[str] = "Compound pendulum (Example 8)"
    book_refs: ClassVar[str] = "Example 8; (2.2.27), (2.2.28), (2.2.29), (2.2.25), (2.2.26)"
    coordinates: ClassVar[tuple[str, ...]] = ("θ1", "θ2")

    m1: float = 1.2
    """upper mass, kg"""
    m2: float = 0.8
    """lower mass, kg"""
    L1: float = 1.1
    """upper rod, m"""
    L2: float = 0.7
    """lower rod, m"""
    g: float = 9.81
    """gravity, m/s²"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(0.7, -0.4), v0=(0.3, -0.5), duration=2.0, steps=STEPS
        )
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("m1", "m2", "L1", "L2", "g"):
            positive(name, getattr(self, name))

    def params(self) -> dict[str, float]:
        return {"m1": self.m1, "m2": self.m2, "L1": self.L1, "L2": self.L2, "g": self.g}

    def multibody(self) -> Multibody:
        upper = Body(
            "upper",
            None,
            (0, 0, 0),
            (Joint("shoulder", "hinge", Y_AXIS),),
            self.m1,
            (0.0, 0.0, -self.L1),
        )
        lower = Body(
            "lower",
            "upper",
            (0, 0, -self.L1),
            (Joint("elbow", "hinge", Y_AXIS),),
            self.m2,
            (0.0, 0.0, -self.L2),
        )
        return Multibody(self.name, (upper, lower), (0.0, 0.0, -self.g))

    def engine_map(self) -> LinearMap:
        return LinearMap(
            ((-1.0, 0.0), (1.0, -1.0)), (0.0, 0.0), "α₁ = −θ₁, α₂ = −(θ₂ − θ₁) (relative, +y)"
        )

    def rest(self) -> np.ndarray:
        return np.zeros(2)

    def state_scale(self) -> tuple[float, float, float]:
        w = np.sqrt(self.g / min(self.L1, self.L2))
        return 2 * w, (self.m1 + self.m2) * self.g * self.L1, 2 * w * w


@dataclass(frozen=True)
class SphericalPendulum(Case):
    """Exercise 28: a bob on a wire of length ℓ, free to swing in any direction; the book's z
    axis points down, φ from it, θ from the y axis. Engines: one ball joint::

                O  ball joint
               /
              /  ℓ        (φ, θ) ↔ unit quaternion, (φ̇, θ̇) ↔ angular velocity
             ● m

    A point mass on a ball joint has no inertia about the wire: every engine's model carries
    the isotropic floor ``mjcf_point_inertia`` (explained like the MJCF's)."""

    name: ClassVar[str] = "spherical_pendulum"
    title: ClassVar[str] = "Spherical pendulum (exercise 28)"
    book_refs: ClassVar[str] = "exercise 28; (2.2.21), (2.2.25), (2.2.26)"
    coordinates: ClassVar[tuple[str, ...]] = ("φ", "θ")
    periodic: ClassVar[tuple[bool, ...]] = (False, True)

    m: float = 1.3
    """bob mass, kg"""
    l: float = 1.1
    """wire length, m"""
    g: float = 9.81
    """gravity, m/s²"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(0.8, 0.3), v0=(0.2, 1.5), duration=2.0, steps=STEPS
        )
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("m", "l", "g"):
            positive(name, getattr(self, name))
        self.check_state("q0", self.trajectory.q0)

    def chart_singularity(self, q: np.ndarray) -> str | None:
        phi = q[0] % (2 * np.pi)
        if min(phi, abs(phi - np.pi), 2 * np.pi - phi) < 1e-6:
            return "φ = 0 or π, the vertical, where θ is undefined"
        return None

    def params(self) -> dict[str, float]:
        return {"m": self.m, "l": self.l, "g": self.g}

    def multibody(self) -> Multibody:
        bob = Body("bob", None, (0, 0, 0), (Joint("ball", "ball"),), self.m, (0.0, 0.0, -self.l))
        return Multibody(self.name, (bob,), (0.0, 0.0, -self.g))

    def engine_map(self) -> SphericalPendulumMap:
        return SphericalPendulumMap()

    def rest(self) -> np.ndarray:
        """A datum off the pole φ = 0 (where the chart is singular)."""
        return np.array([1.0, 0.0])

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """φ ∉ {0, π}: the chart is singular on the vertical."""
        return np.array([0.2, -np.pi]), np.array([np.pi - 0.2, np.pi])

    def state_scale(self) -> tuple[float, float, float]:
        w = np.sqrt(self.g / self.l)
        return 2 * w, self.m * self.g * self.l, 2 * w * w
