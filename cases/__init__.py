"""Cases: every system defined once, in one sorted registry."""

from __future__ import annotations

from dyncheck.cases.base import INTEGRATORS, NOMINAL_ORDER, Case, StateSample, TrajectorySpec
from dyncheck.cases.particles import CylindricalCoordinates, Kepler, SphericalCoordinates
from dyncheck.cases.pendulums import CompoundPendulum, SimplePendulum, SphericalPendulum
from dyncheck.cases.pulleys import Atwood, CompoundPulley
from dyncheck.cases.rigid import RigidBodyBall, RigidBodyFree, TorqueFree
from dyncheck.errors import UnknownName

CASES: dict[str, type[Case]] = {
    "atwood": Atwood,
    "compound_pendulum": CompoundPendulum,
    "compound_pulley": CompoundPulley,
    "cylindrical_coordinates": CylindricalCoordinates,
    "kepler": Kepler,
    "rigid_body_ball": RigidBodyBall,
    "rigid_body_free": RigidBodyFree,
    "simple_pendulum": SimplePendulum,
    "spherical_coordinates": SphericalCoordinates,
    "spherical_pendulum": SphericalPendulum,
    "torque_free": TorqueFree,
}
"""Case name → case class with the book's default parameters; kept sorted by name."""


def get_case(name: str) -> Case:
    """The case ``name`` with its default parameters."""
    try:
        return CASES[name]()
    except KeyError:
        raise UnknownName("case", name, CASES) from None


__all__ = [
    "CASES",
    "INTEGRATORS",
    "NOMINAL_ORDER",
    "Case",
    "StateSample",
    "TrajectorySpec",
    "get_case",
]
