"""Drake's registration (:mod:`.model`, which also serves ``dyncheck run``): importable
without pydrake."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "drake": Registration(
        package="drake",
        extra="drake",
        integrators=(Integrator.EULER, Integrator.RK2, Integrator.RK3),
        model=A + "drake.model:DrakeModel",
        label="drake",
        run=Format.MJCF,
        releases=("1.40.0", "1.45.0", "1.51.1"),
        released_with=("mosek",),
    ),
}
