"""MuJoCo Warp's registration (:mod:`.port_models` on :mod:`.mujoco_warp_`): importable
without Warp."""

from __future__ import annotations

from dyncheck.adapters.mjx_registration import PORTS
from dyncheck.adapters.model_files import Format
from dyncheck.adapters.mujoco_registration import MUJOCO
from dyncheck.adapters.registration import A, Registration

REGISTRATIONS: dict[str, Registration] = {
    "mujoco-warp": Registration(
        package="mujoco-warp",
        run=Format.MJCF,
        extra="warp",
        ports=MUJOCO,
        float32=True,
        integrators=PORTS,
        model=A + "port_models:MujocoWarpModel", on_request=True, label="mujoco-warp",
        accelerator=True,
    ),
}
