"""Example 6 (Atwood's machine) and exercise 17 (the pulley and mass system): masses held by
cords over massless pulleys of radius a.

Book coordinates: depths below the fixed pulley's axle, positive down (Example 6's y₁; for
exercise 17, y₁ of m₁ and y₂ of m₂ below the movable pulley's axle — the geometry is stated in
:mod:`dyncheck.reference.pulley`). Engines: every mass is its own body on a slide joint along
(0, 0, −1) (down) placed at its rest depth, so a joint coordinate is a mass's displacement
from rest; the cords are couplings between the joints (a MuJoCo tendon equality, a constraint
Jacobian in Pinocchio), not a pre-reduced model. The constraint force compared is the cord
tension (N): Example 6's single cord; exercise 17's lower cord (the upper carries twice it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from dyncheck.cases.base import STEPS, Case, TrajectorySpec
from dyncheck.cases.coordinate_maps import LinearMap
from dyncheck.cases.multibody import Body, Coupling, Joint, Multibody
from dyncheck.errors import InvalidInput, positive

DOWN = (0.0, 0.0, -1.0)


def _mass(name: str, x: float, depth: float, m: float) -> Body:
    return Body(name, None, (x, 0.0, -depth), (Joint(name, "slide", DOWN),), m, (0.0, 0.0, 0.0))


@dataclass(frozen=True)
class Atwood(Case):
    """Example 6: m₁ and m₂ on one cord over a fixed pulley, y₁ + y₂ = ℓ::

        (O)      fixed pulley, radius a
       |   |
    y₁ |   | y₂ = ℓ − y₁
       ■   ■
       m₁  m₂
    """

    name: ClassVar[str] = "atwood"
    title: ClassVar[str] = "Atwood's machine (Example 6)"
    book_refs: ClassVar[str] = "Example 6; (2.2.23), (2.2.25), (2.2.26)"
    coordinates: ClassVar[tuple[str, ...]] = ("y1",)

    m1: float = 1.1
    """mass on the left, kg"""
    m2: float = 0.9
    """mass on the right, kg"""
    a: float = 0.1
    """pulley radius, m"""
    l: float = 3.0
    """the book's ℓ = y₁ + y₂, m (the cord is ℓ + πa long)"""
    g: float = 9.81
    """gravity, m/s²"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(q0=(1.0,), v0=(0.5,), duration=1.0, steps=STEPS)
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("m1", "m2", "a", "l", "g"):
            positive(name, getattr(self, name))
        self.check_state("q0", self.trajectory.q0)

    def chart_singularity(self, q: np.ndarray) -> str | None:
        if not 0 < q[0] < self.l:
            return f"y1 outside (0, ℓ = {self.l:g}): a mass would be above the pulley's axle"
        return None

    def params(self) -> dict[str, float]:
        return {"m1": self.m1, "m2": self.m2, "a": self.a, "l": self.l, "g": self.g}

    def rest(self) -> np.ndarray:
        return np.array([self.l / 2])

    def multibody(self) -> Multibody:
        y = float(self.rest()[0])
        return Multibody(
            self.name,
            (_mass("y1", -self.a, y, self.m1), _mass("y2", self.a, self.l - y, self.m2)),
            (0.0, 0.0, -self.g),
            couplings=(Coupling("cord", (("y1", 1.0), ("y2", 1.0))),),
        )

    def engine_map(self) -> LinearMap:
        y = float(self.rest()[0])
        return LinearMap(
            ((1.0,), (-1.0,)), (-y, y), "s₁ = y₁ − y₁⁰, s₂ = −(y₁ − y₁⁰) (slides down, from rest)"
        )

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([0.1 * self.l]), np.array([0.9 * self.l])

    def state_scale(self) -> tuple[float, float, float]:
        return 2.0, (self.m1 + self.m2) * self.g, 2 * self.g


@dataclass(frozen=True)
class CompoundPulley(Case):
    """Exercise 17: m₁ on the upper cord (ℓ₁) over the fixed pulley; on its other end a
    massless movable pulley whose lower cord (ℓ₂) carries m₂ and m₃::

          (O)          fixed pulley
         |   |
      y₁ |   | ℓ₁ − πa − y₁
         ■  (P)        movable pulley
         m₁ |   |
         y₂ |   | ℓ₂ − πa − y₂
            ■   ■
            m₂  m₃
    """

    name: ClassVar[str] = "compound_pulley"
    title: ClassVar[str] = "Pulley and mass system (exercise 17)"
    book_refs: ClassVar[str] = "exercise 17; Example 6; (2.2.25), (2.2.26)"
    coordinates: ClassVar[tuple[str, ...]] = ("y1", "y2")

    m1: float = 2.0
    """mass on the upper cord, kg"""
    m2: float = 0.7
    """first mass on the lower cord, kg"""
    m3: float = 1.1
    """second mass on the lower cord, kg"""
    a: float = 0.1
    """radius of each pulley, m"""
    l1: float = 3.0
    """length of the upper cord, m"""
    l2: float = 2.5
    """length of the lower cord, m"""
    g: float = 9.81
    """gravity, m/s²"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(1.0, 1.4), v0=(0.2, 0.3), duration=1.0, steps=STEPS
        )
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("m1", "m2", "m3", "a", "l1", "l2", "g"):
            positive(name, getattr(self, name))
        for name, length in (("l1", self.l1), ("l2", self.l2)):
            if length <= np.pi * self.a:
                raise InvalidInput(name, length, f"longer than the wrap πa = {np.pi * self.a:g} m")
        self.check_state("q0", self.trajectory.q0)

    def free_lengths(self) -> tuple[float, float]:
        """The cords' hanging lengths ℓ − πa, m."""
        return self.l1 - np.pi * self.a, self.l2 - np.pi * self.a

    def chart_singularity(self, q: np.ndarray) -> str | None:
        f1, f2 = self.free_lengths()
        if not (0 < q[0] < f1 and 0 < q[1] < f2):
            return (
                f"y1 outside (0, ℓ₁ − πa = {f1:g}) or y2 outside (0, ℓ₂ − πa = {f2:g}): "
                "a mass would be above its pulley's axle"
            )
        return None

    def params(self) -> dict[str, float]:
        return {
            "m1": self.m1,
            "m2": self.m2,
            "m3": self.m3,
            "a": self.a,
            "l1": self.l1,
            "l2": self.l2,
            "g": self.g,
        }

    def rest(self) -> np.ndarray:
        f1, f2 = self.free_lengths()
        return np.array([f1 / 2, f2 / 2])

    def depths(self, q: np.ndarray) -> np.ndarray:
        """Depths of m₁, m₂, m₃ below the fixed pulley's axle, shape (n, 3)."""
        f1, f2 = self.free_lengths()
        q = np.atleast_2d(q)
        yp = f1 - q[:, 0]
        return np.column_stack([q[:, 0], yp + q[:, 1], yp + f2 - q[:, 1]])

    def multibody(self) -> Multibody:
        z1, z2, z3 = self.depths(self.rest())[0]
        a = self.a
        return Multibody(
            self.name,
            (
                _mass("y1", -a, z1, self.m1),
                _mass("y2", 0.0, z2, self.m2),
                _mass("y3", 2 * a, z3, self.m3),
            ),
            (0.0, 0.0, -self.g),
            couplings=(Coupling("cords", (("y1", 2.0), ("y2", 1.0), ("y3", 1.0))),),
        )

    def engine_map(self) -> LinearMap:
        A = np.array([[1.0, 0.0], [-1.0, 1.0], [-1.0, -1.0]])
        offset = -A @ self.rest()
        return LinearMap(
            tuple(map(tuple, A)),
            tuple(map(float, offset)),
            "s₁ = Δy₁, s₂ = −Δy₁ + Δy₂, s₃ = −Δy₁ − Δy₂ (slides down, from rest)",
        )

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        f = np.array(self.free_lengths())
        return 0.1 * f, 0.9 * f

    def state_scale(self) -> tuple[float, float, float]:
        return 2.0, (self.m1 + self.m2 + self.m3) * self.g, 2 * self.g
