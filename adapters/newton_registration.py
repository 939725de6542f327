"""Newton's registration (:mod:`.newton_model`, which also serves ``dyncheck run``): importable
without Newton."""

from __future__ import annotations

from dyncheck.adapters.model_files import Format
from dyncheck.adapters.registration import A, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "newton": Registration(
        package="newton", extra="newton", model=A + "newton_model:NewtonModel",
        label="newton", on_request=True, float32=True, run=Format.MJCF, accelerator=True,
        integrators=(Integrator.EULER,),
        releases=("1.7.0", "1.8.0"),
    ),
}
