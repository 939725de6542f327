"""Newton's registration (:mod:`.model`, which also serves ``dyncheck run``): importable
without Newton."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "newton": Registration(
        package="newton", extra="newton", model=A + "newton.model:NewtonModel",
        label="newton", on_request=True, float32=True, run=Format.MJCF, accelerator=True,
        integrators=(Integrator.EULER,),
        releases=("1.7.0", "1.8.0"),
    ),
}
