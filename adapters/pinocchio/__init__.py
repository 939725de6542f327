"""Pinocchio's registrations (:mod:`.model`, which also serves ``dyncheck run``):
importable without Pinocchio; stepped by MuJoCo's integrators' definitions
(:mod:`.simulation`). ``pinocchio`` reads a book case as stated (the case's gravity,
its point masses exact); ``pinocchio-mjcf`` reads the
very MJCF file MuJoCo loads as Pinocchio's MJCF parser does."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Needs, Registration
from dyncheck.vocabulary import Integrator

STEPPED = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4, Integrator.RK4_HELD_FORCE)
"""The integrators Pinocchio is stepped by: MuJoCo's definitions, written once in
:mod:`dyncheck.adapters.integrators` (:mod:`.simulation`)."""

REGISTRATIONS: dict[str, Registration] = {
    "pinocchio": Registration(
        package="pin", integrators=STEPPED, model=A + "pinocchio.model:PinocchioModel",
        label="pinocchio", run=Format.MJCF, as_stated=True,
        releases=("3.4.0", "3.7.0", "3.9.0", "4.0.0", "4.1.0"),
        released_with=("libpinocchio", "cmeel", "coal", "libcoal", "eigenpy",
                       "jrl-cmakemodules"),
        needs=(
            Needs(series="3.", unpin=("numpy",),
                  reason="Pinocchio 3.x needs cmeel-boost < 1.90, whose wheels are built "
                  "against numpy < 2.4: numpy resolves to the newest 2.3"),
            Needs(series="3.", require=("cmeel-urdfdom<5", "cmeel-tinyxml2<11"),
                  reason="Pinocchio 3.x wheels link liburdfdom 4 and libtinyxml2 10 but "
                  "do not bound cmeel-urdfdom or cmeel-tinyxml2 (the newest fail to "
                  "import: `liburdfdom_sensor.so.4.0: cannot open shared object file`)"),
        ),
    ),
    "pinocchio-mjcf": Registration(
        package="pin", integrators=STEPPED, model=A + "pinocchio.model:PinocchioModel",
        run=Format.MJCF, checks_files=False,
    ),
}
