"""sympy.physics.mechanics's registration (:mod:`.model`): importable without sympy."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "sympy-mechanics": Registration(
        model=A + "sympy_mechanics.model:SympyMechanics", run=Format.CASE, package="sympy",
        integrators=(Integrator.EULER, Integrator.RK4), checks_files=False,
    ),
}
