"""A particle carried by joints that *are* a coordinate system (Example 5; exercises 6, 7).

The engine model is one body with three joints applied in order at the origin; its position
is the coordinate map itself, so the engine's mass matrix must be M g_ij and its bias
M g_ij {j; m n} q̇ᵐ q̇ⁿ plus gravity. The joint order differs from the book's coordinate order:
a permutation, crossed like any coordinate map.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from dyncheck.cases.base import STEPS, Case, TrajectorySpec
from dyncheck.cases.coordinate_maps import LinearMap, SphericalToCartesian
from dyncheck.cases.multibody import Body, Joint, Multibody
from dyncheck.errors import positive
from dyncheck.vocabulary import Integrator

X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
COARSE_RK4 = {**STEPS, Integrator.RK4: (1e-1, 5e-2, 2.5e-2, 1.25e-2)}
"""The cylindrical particle's free fall is so smooth in (r, θ, z) that RK4 reaches the
reference's accuracy at 1e-2 already: its study starts coarser."""
PERMUTE_REVERSE = ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))


SPHERICAL_BOUNDS = (np.array([0.5, 0.3, -np.pi]), np.array([2.0, np.pi - 0.3, np.pi]))
"""Sampling box for spherical (ρ, θ, φ): ρ > 0 and θ ∉ {0, π}, off the chart's singular set."""


def spherical_singularity(q: np.ndarray) -> str | None:
    """Spherical (ρ, θ, φ): singular at ρ = 0 and on the z axis (θ = 0, π)."""
    if abs(q[0]) < 1e-9:
        return "ρ = 0, the origin"
    theta = q[1] % (2 * np.pi)
    if min(theta, abs(theta - np.pi), 2 * np.pi - theta) < 1e-6:
        return "θ = 0 or π, the z axis, where φ is undefined"
    return None


class _SphericalChart:
    """The book's spherical chart (ρ, θ, φ): datum on the equator, singular set, sampling box."""

    def rest(self) -> np.ndarray:
        return np.array([1.0, np.pi / 2, 0.0])

    def chart_singularity(self, q: np.ndarray) -> str | None:
        return spherical_singularity(q)

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return SPHERICAL_BOUNDS


@dataclass(frozen=True)
class _Particle(Case):
    M: float = 1.5
    """particle mass, kg"""
    g: float = 9.81
    """gravity along −z, m/s²"""

    def __post_init__(self) -> None:
        super().__post_init__()
        positive("M", self.M)
        positive("g", self.g)
        self.check_state("q0", self.trajectory.q0)

    def params(self) -> dict[str, float]:
        return {"M": self.M, "g": self.g}

    def state_scale(self) -> tuple[float, float, float]:
        return 2.0, 2 * self.M * self.g, 2 * self.g


@dataclass(frozen=True)
class SphericalCoordinates(_SphericalChart, _Particle):
    """Spherical coordinates (ρ, θ, φ) of Example 5 as a joint chain::

    hinge φ about z  →  hinge θ about y  →  slide ρ along z  →  ● M
    position R_z(φ) R_y(θ) (0, 0, ρ) = (ρ sin θ cos φ, ρ sin θ sin φ, ρ cos θ)
    """

    name: ClassVar[str] = "spherical_coordinates"
    title: ClassVar[str] = "Particle in spherical coordinates (Example 5)"
    book_refs: ClassVar[str] = "Example 5; (2.2.5), (2.2.21)-(2.2.23); exercise 7"
    coordinates: ClassVar[tuple[str, ...]] = ("ρ", "θ", "φ")
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(1.2, 1.2, 0.4), v0=(0.3, -0.2, 0.5), duration=1.0, steps=STEPS
        )
    )

    def multibody(self) -> Multibody:
        joints = (Joint("phi", "hinge", Z), Joint("theta", "hinge", Y), Joint("rho", "slide", Z))
        bob = Body("particle", None, (0, 0, 0), joints, self.M, (0.0, 0.0, 0.0))
        return Multibody(self.name, (bob,), (0.0, 0.0, -self.g))

    def engine_map(self) -> LinearMap:
        return LinearMap(
            PERMUTE_REVERSE, (0.0, 0.0, 0.0), "joints (φ, θ, ρ) = book (ρ, θ, φ) reversed"
        )


@dataclass(frozen=True)
class CylindricalCoordinates(_Particle):
    """Cylindrical coordinates (r, θ, z) of exercise 6 as a joint chain::

    hinge θ about z  →  slide z along z  →  slide r along x  →  ● M
    position R_z(θ) (r, 0, z) = (r cos θ, r sin θ, z)
    """

    name: ClassVar[str] = "cylindrical_coordinates"
    title: ClassVar[str] = "Particle in cylindrical coordinates (exercise 6)"
    book_refs: ClassVar[str] = "(2.2.5), (2.2.21)-(2.2.23); exercise 6"
    coordinates: ClassVar[tuple[str, ...]] = ("r", "θ", "z")
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            q0=(0.6, 0.3, 0.5), v0=(-0.5, 1.5, 1.0), duration=1.0, steps=COARSE_RK4
        )
    )

    def multibody(self) -> Multibody:
        joints = (Joint("theta", "hinge", Z), Joint("z", "slide", Z), Joint("r", "slide", X))
        bob = Body("particle", None, (0, 0, 0), joints, self.M, (0.0, 0.0, 0.0))
        return Multibody(self.name, (bob,), (0.0, 0.0, -self.g))

    def engine_map(self) -> LinearMap:
        return LinearMap(
            ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)),
            (0.0, 0.0, 0.0),
            "joints (θ, z, r) = book (r, θ, z) rotated",
        )

    def rest(self) -> np.ndarray:
        return np.array([1.0, 0.0, 0.0])

    def chart_singularity(self, q: np.ndarray) -> str | None:
        """Cylindrical (r, θ, z): singular on the z axis (r = 0)."""
        return "r = 0, the z axis, where θ is undefined" if abs(q[0]) < 1e-9 else None

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """r > 0: the chart is singular on the z axis."""
        return np.array([0.5, -np.pi, -1.0]), np.array([2.0, np.pi, 1.0])


def _kepler_initial_state(mu: float, a: float, e: float, incl: float) -> tuple[tuple, tuple]:
    """Perihelion of an orbit of semi-major axis a, eccentricity e, inclined by ``incl`` about
    the x axis, in the book's spherical coordinates (ρ, θ, φ) and their rates."""
    rp = a * (1 - e)
    vp = np.sqrt(mu * (1 + e) / rp)  # vis-viva at perihelion
    rot = np.array([[1, 0, 0], [0, np.cos(incl), -np.sin(incl)], [0, np.sin(incl), np.cos(incl)]])
    yaw = np.array([[np.cos(0.4), -np.sin(0.4), 0], [np.sin(0.4), np.cos(0.4), 0], [0, 0, 1]])
    x = yaw @ rot @ np.array([rp, 0.0, 0.0])
    xd = yaw @ rot @ np.array([0.0, vp, 0.0])
    rho = np.linalg.norm(x)
    th, ph = np.arccos(x[2] / rho), np.arctan2(x[1], x[0])
    # invert (2.2.4): v_cart = J v_book
    J = SphericalToCartesian().jacobian(np.array([[rho, th, ph]]))[0]
    v = np.linalg.solve(J, xd)
    return (float(rho), float(th), float(ph)), tuple(float(c) for c in v)


@dataclass(frozen=True)
class Kepler(_SphericalChart, Case):
    """Exercise 25: a particle attracted to the origin by F = −μM r/|r|³, the force applied
    through each engine's external-force input; book coordinates spherical (ρ, θ, φ), engine
    joints three Cartesian slides::

        slide x  →  slide y  →  slide z  →  ● M        ← F = −μ M r/|r|³ (external)

    Orbit: a = 1.2, e = 0.3, inclined 30°; period 2π√(a³/μ) ≈ 8.26 s for μ = 1.
    """

    name: ClassVar[str] = "kepler"
    title: ClassVar[str] = "Kepler orbit (exercise 25)"
    book_refs: ClassVar[str] = "exercise 25; Example 5; (2.2.5), (2.2.20), (2.2.23)"
    coordinates: ClassVar[tuple[str, ...]] = ("ρ", "θ", "φ")
    periodic: ClassVar[tuple[bool, ...]] = (False, False, True)

    M: float = 1.0
    """particle mass, kg"""
    mu: float = 1.0
    """gravitational parameter G·M_sun, m³/s²"""
    trajectory: TrajectorySpec = field(
        default_factory=lambda: TrajectorySpec(
            *_kepler_initial_state(1.0, 1.2, 0.3, np.pi / 6),
            duration=4.0,
            steps={
                Integrator.EULER: (4e-3, 2e-3, 1e-3, 5e-4),
                Integrator.IMPLICITFAST: (4e-3, 2e-3, 1e-3, 5e-4),
                Integrator.RK2: (1e-2, 5e-3, 2.5e-3, 1.25e-3),
                Integrator.RK3: (1e-2, 5e-3, 2.5e-3, 1.25e-3),
                Integrator.RK4: (4e-2, 2e-2, 1e-2, 5e-3),
                Integrator.RK4_HELD_FORCE: (4e-3, 2e-3, 1e-3, 5e-4),
            },
        )
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        positive("M", self.M)
        positive("mu", self.mu)
        self.check_state("q0", self.trajectory.q0)

    def params(self) -> dict[str, float]:
        return {"M": self.M, "mu": self.mu}

    def multibody(self) -> Multibody:
        joints = (Joint("x", "slide", X), Joint("y", "slide", Y), Joint("z", "slide", Z))
        body = Body("particle", None, (0, 0, 0), joints, self.M, (0.0, 0.0, 0.0))
        return Multibody(self.name, (body,), (0.0, 0.0, 0.0), central_mu=self.mu)

    def engine_map(self) -> SphericalToCartesian:
        return SphericalToCartesian()

    def state_scale(self) -> tuple[float, float, float]:
        return 1.5, 2 * self.M * self.mu, 4 * self.mu
