"""MuJoCo Warp's registration (:mod:`.mujoco_warp_`, :mod:`.port_models`): importable without
Warp."""

from __future__ import annotations

from dyncheck.adapters.mjx_registration import PORTS
from dyncheck.adapters.mujoco_registration import MUJOCO
from dyncheck.adapters.registration import A, Registration

REGISTRATIONS: dict[str, Registration] = {
    "mujoco-warp": Registration(
        module=A + "mujoco_warp_",
        cls="MuJoCoWarpAdapter",
        package="mujoco-warp",
        extra="warp",
        ports=MUJOCO,
        float32=True,
        integrators=PORTS,
        model=A + "port_models:MujocoWarpModel", on_request=True, label="mujoco-warp",
        accelerator=True,
    ),
}
