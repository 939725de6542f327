"""Cases: every system defined once, in one sorted registry."""

from __future__ import annotations

import importlib.metadata

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

ENTRY_POINTS = "dyncheck.cases"
"""The entry-point group through which an installed package adds a case: each entry's name is
the case's, its value ``module:Class`` a :class:`Case` subclass of that ``name``; its system
in the reference is the same module's entry of :data:`dyncheck.reference.systems.ENTRY_POINTS`.
It joins :data:`CASES` (sorted by name) with no file of dyncheck touched."""


def _installed_cases() -> tuple[dict[str, type[Case]], dict[str, str]]:
    """The cases installed packages add (:data:`ENTRY_POINTS`), and why any could not be
    added (its name → the reason)."""
    found: dict[str, type[Case]] = {}
    broken: dict[str, str] = {}
    for point in importlib.metadata.entry_points(group=ENTRY_POINTS):
        try:
            case = point.load()
        except Exception as exc:  # a broken package costs only its own case
            broken[point.name] = f"{point.value} failed to load: {type(exc).__name__}: {exc}"
            continue
        if point.name in CASES or point.name in found:
            broken[point.name] = f"{point.value}: the name is taken by another case"
        elif not (isinstance(case, type) and issubclass(case, Case)) or case.name != point.name:
            broken[point.name] = f"{point.value} is not a Case named {point.name!r}"
        else:
            found[point.name] = case
    return found, broken


_ADDED, NOT_ADDED = _installed_cases()
CASES = dict(sorted({**CASES, **_ADDED}.items()))


def get_case(name: str) -> Case:
    """The case ``name`` with its default parameters."""
    try:
        return CASES[name]()
    except KeyError:
        raise UnknownName("case", name, CASES) from None


__all__ = [
    "CASES",
    "ENTRY_POINTS",
    "INTEGRATORS",
    "NOMINAL_ORDER",
    "NOT_ADDED",
    "Case",
    "StateSample",
    "TrajectorySpec",
    "get_case",
]
