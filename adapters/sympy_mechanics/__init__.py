"""sympy.physics.mechanics's registration (:mod:`.model`): importable without sympy."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "sympy-mechanics": Registration(
        module=A + "sympy_mechanics.model", cls="SympyMechanicsAdapter", package="sympy",
        integrators=(Integrator.EULER, Integrator.RK4),
    ),
}
