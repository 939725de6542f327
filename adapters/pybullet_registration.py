"""PyBullet's registration (:mod:`.pybullet_model`, which also serves ``dyncheck run``): importable
without PyBullet."""

from __future__ import annotations

from dyncheck.adapters.model_files import Format
from dyncheck.adapters.registration import A, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "pybullet": Registration(
        package="pybullet", extra="pybullet", model=A + "pybullet_model:PybulletModel",
        label="pybullet", on_request=True, run=Format.URDF, releases=("3.2.6", "3.2.7"),
        integrators=(Integrator.EULER,),
    ),
}
