"""Each case's system in the reference, by the case's name: its general method (Lagrange's
equations (2.2.23)–(2.2.26) from T and V) and the equations the book prints for it.

One signature for every system: ``general(params, inertia=…)`` with the case's parameters
(and, for cords, ``rest`` and ``softness``) as a mapping and the isotropic inertia each body
carries where the book has a point mass; ``printed(params)`` with the book's parameters only.
Adding a built-in case adds one entry here (after the case's module in ``cases/``); an
installed package adds its case's through :data:`ENTRY_POINTS`.
"""

from __future__ import annotations

import functools
import importlib.metadata
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from dyncheck.reference import particle, pendulum, pulley, rigid
from dyncheck.reference.coordinates import cylindrical, spherical


@dataclass(frozen=True, kw_only=True)
class System:
    """The reference's two readings of one case."""

    general: Callable[..., Any]
    """Keyword arguments: the case's parameters, ``g``, ``inertia`` (and ``rest``,
    ``softness`` with cords) → dynamics with M, h, forward, inverse, T, V."""
    printed: Callable[..., Any]
    """Keyword arguments: the case's parameters → the book's printed dynamics."""

    def general_method(self, params: Mapping[str, Any], inertia: tuple[float, ...]) -> Any:
        return self.general(**params, inertia=inertia)

    def printed_equations(self, params: Mapping[str, Any]) -> Any:
        return self.printed(**params)


_PAIRS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    "simple_pendulum": (pendulum.simple_pendulum, pendulum.simple_pendulum_printed),
    "compound_pendulum": (pendulum.compound_pendulum, pendulum.compound_pendulum_printed),
    "spherical_pendulum": (pendulum.spherical_pendulum, pendulum.spherical_pendulum_printed),
    "spherical_coordinates": (
        lambda M, g, inertia: particle.particle(spherical(), M, g, inertia=inertia),
        particle.example5_printed,
    ),
    "kepler": (
        # the engines carry the particle on three slides: its body never rotates, so a
        # point-mass inertia floor has no effect (inertia is not passed on)
        lambda M, mu, g, inertia: particle.particle(spherical(), M, g, mu=mu),
        lambda M, mu: particle.example5_printed(M, mu=mu),
    ),
    "cylindrical_coordinates": (
        lambda M, g, inertia: particle.particle(cylindrical(), M, g, inertia=inertia),
        lambda M, g: particle.lagrange_form(cylindrical(), M, g),
    ),
    # a body with its own inertia: no point-mass floor to add
    "rigid_body_ball": (
        lambda m, g, inertia, **I: rigid.rigid_ball(**I),
        lambda m, g, **I: rigid.rigid_ball_printed(**I),
    ),
    "rigid_body_free": (
        lambda m, g, inertia, **I: rigid.rigid_free(m, g, **I),
        lambda m, g, **I: rigid.rigid_free_printed(m, g, **I),
    ),
    "torque_free": (
        lambda m, g, inertia, **I: rigid.rigid_ball(**I),
        lambda m, g, **I: rigid.rigid_ball_printed(**I, principal=True),
    ),
    # the masses ride on slides and never rotate: an inertia floor has no effect
    "atwood": (
        lambda m1, m2, a, l, g, inertia, rest, softness: pulley.atwood(
            m1, m2, a, l, g, rest[0], softness=softness
        ),
        lambda m1, m2, a, l, g: pulley.atwood_printed(m1, m2, g),
    ),
    "compound_pulley": (
        lambda m1, m2, m3, a, l1, l2, g, inertia, rest, softness: pulley.compound_pulley(
            m1, m2, m3, a, l1, l2, g, rest, softness=softness
        ),
        lambda m1, m2, m3, a, l1, l2, g: pulley.compound_pulley_printed(m1, m2, m3, g),
    ),
}

ENTRY_POINTS = "dyncheck.systems"
"""The entry-point group through which an installed package gives a case it adds (the
``dyncheck.cases`` group) its system in the reference: the entry's name is the case's, its
value ``module:NAME`` a :class:`System`. A broken entry, or one whose name is taken, is left
out: that case's reference and book rows then fail, naming it."""

SYSTEMS: dict[str, System] = {
    name: System(general=general, printed=printed) for name, (general, printed) in _PAIRS.items()
}
"""Built-in case name → its system (:class:`System`). For the cylindrical particle the book
prints no equations; its "printed" form is (2.2.23) with the closed-form metric and
Christoffel symbols (exercise 6)."""


@functools.cache
def systems() -> dict[str, System]:
    """Every case's system: :data:`SYSTEMS` and those installed packages add
    (:data:`ENTRY_POINTS`), read on first use — a package's module imports this one, so
    reading them while it is imported would be circular."""
    found = dict(SYSTEMS)
    for point in importlib.metadata.entry_points(group=ENTRY_POINTS):
        try:
            system = point.load()
        except Exception:  # a broken package costs only its own case's rows
            continue
        if isinstance(system, System) and point.name not in found:
            found[point.name] = system
    return found
