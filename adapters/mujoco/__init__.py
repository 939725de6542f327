"""MuJoCo's registrations (:mod:`.model`): the canonical engine of a
check."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

MUJOCO_C = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4, Integrator.RK4_HELD_FORCE)
"""MuJoCo's integrators, ``rk4-held-force`` being RK4 with a force held in ``xfrc_applied``;
Pinocchio is stepped by the same definitions (:mod:`.integrators`)."""

STIFF = (0.9999, 0.9999, 0.001, 0.5, 2.0)
"""``mujoco-stiff``'s solimp: its equalities' impedance at MuJoCo's ceiling mjMAXIMP = 0.9999
(dmin = dmax), the stiffest soft constraint MuJoCo offers."""

MUJOCO = "mujoco"
"""MuJoCo's implementation name, which its ports name as the engine they port."""

REGISTRATIONS: dict[str, Registration] = {
    MUJOCO: Registration(
        package="mujoco", integrators=MUJOCO_C, model=A + "mujoco.model:MujocoModel",
        label="mujoco", canonical=True, native=Format.MJCF, run=Format.MJCF,
        releases=("3.2.7", "3.3.7", "3.6.0", "3.10.0", "3.14.0", "3.17.0", "4.0.0"),
        released_with=("glfw", "pyopengl"),
    ),
    "mujoco-stiff": Registration(
        package="mujoco", integrators=MUJOCO_C, model=A + "mujoco.model:MujocoModel",
        run=Format.MJCF, checks_files=False, couplings_only=True,
        loader_options=(("solimp", STIFF),),
    ),
}
