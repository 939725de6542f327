"""MJX's registrations (:mod:`.mjx_`, :mod:`.port_models`), float32 and float64: importable without
JAX."""

from __future__ import annotations

from dyncheck.adapters.mujoco_registration import MUJOCO
from dyncheck.adapters.registration import A, Registration
from dyncheck.vocabulary import Integrator

PORTS = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4)
"""The integrators of MuJoCo's ports (which have no external field to hold)."""

REGISTRATIONS: dict[str, Registration] = {
    "mjx-f64": Registration(
        module=A + "mjx_", cls="MJXF64Adapter", package="mujoco-mjx", extra="mjx", ports=MUJOCO,
        integrators=PORTS,
        model=A + "port_models:MjxF64Model", on_request=True, accelerator=True,
    ),
    "mjx": Registration(
        module=A + "mjx_",
        cls="MJXAdapter",
        package="mujoco-mjx",
        extra="mjx",
        ports=MUJOCO,
        float32=True,
        integrators=PORTS,
        model=A + "port_models:MjxModel", on_request=True, label="mujoco-mjx",
        accelerator=True,
    ),
}
