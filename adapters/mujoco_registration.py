"""MuJoCo's registrations (:mod:`.mujoco_`, :mod:`.mujoco_model`): the canonical engine of a
check."""

from __future__ import annotations

from dyncheck.adapters.model_files import Format
from dyncheck.adapters.registration import A, Registration
from dyncheck.vocabulary import Integrator

MUJOCO_C = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4, Integrator.RK4_HELD_FORCE)
"""MuJoCo's integrators, ``rk4-held-force`` being RK4 with a force held in ``xfrc_applied``;
Pinocchio is stepped by the same definitions (:mod:`.integrators`)."""

MUJOCO = "mujoco"
"""MuJoCo's implementation name, which its ports name as the engine they port."""

REGISTRATIONS: dict[str, Registration] = {
    MUJOCO: Registration(
        module=A + "mujoco_", cls="MuJoCoAdapter", package="mujoco", integrators=MUJOCO_C,
        model=A + "mujoco_model:MujocoModel", label="mujoco", canonical=True,
        native=Format.MJCF,
        releases=("3.2.7", "3.3.7", "3.6.0", "3.10.0", "3.14.0", "3.17.0", "4.0.0"),
        released_with=("glfw", "pyopengl"),
    ),
    "mujoco-stiff": Registration(
        module=A + "mujoco_", cls="MuJoCoStiffAdapter", package="mujoco", integrators=MUJOCO_C,
        couplings_only=True,
    ),
}
