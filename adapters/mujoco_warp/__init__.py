"""MuJoCo Warp's registration (:mod:`.model` on :mod:`.port`, MuJoCo's compiled model computed
in Warp): importable without Warp."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

REGISTRATIONS: dict[str, Registration] = {
    "mujoco-warp": Registration(
        package="mujoco-warp",
        run=Format.MJCF,
        extra="warp",
        ports="mujoco",
        float32=True,
        integrators=(Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4),
        model=A + "mujoco_warp.model:MujocoWarpModel", on_request=True, label="mujoco-warp",
        accelerator=True,
    ),
}
