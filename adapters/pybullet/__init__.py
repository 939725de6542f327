"""PyBullet's registration (:mod:`.model`, which also serves ``dyncheck run``): importable
without PyBullet."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "pybullet": Registration(
        package="pybullet", extra="pybullet", model=A + "pybullet.model:PybulletModel",
        label="pybullet", on_request=True, run=Format.URDF, releases=("3.2.6", "3.2.7"),
        integrators=(Integrator.EULER,),
    ),
}
