"""MJX's registrations (:mod:`.port_models` on :mod:`.mjx_`), float32 and float64: importable
without JAX."""

from __future__ import annotations

from dyncheck.adapters.model_files import Format
from dyncheck.adapters.mujoco_registration import MUJOCO
from dyncheck.adapters.registration import A, Registration
from dyncheck.vocabulary import Integrator

PORTS = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4)
"""The integrators of MuJoCo's ports (which have no external field to hold)."""

REGISTRATIONS: dict[str, Registration] = {
    "mjx-f64": Registration(
        package="mujoco-mjx", extra="mjx", ports=MUJOCO, integrators=PORTS, run=Format.MJCF,
        model=A + "port_models:MjxF64Model", on_request=True, accelerator=True,
    ),
    "mjx": Registration(
        package="mujoco-mjx",
        run=Format.MJCF,
        extra="mjx",
        ports=MUJOCO,
        float32=True,
        integrators=PORTS,
        model=A + "port_models:MjxModel", on_request=True, label="mujoco-mjx",
        accelerator=True,
    ),
}
