"""MJX's registrations (:mod:`.model` on :mod:`.port`, MuJoCo's compiled model computed in
JAX), float32 and float64: importable without JAX."""

from __future__ import annotations

from dyncheck.adapters.registration import A, Format, Registration
from dyncheck.vocabulary import Integrator

PORTS = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4)
"""The integrators of MuJoCo's ports (which have no external field to hold)."""

REGISTRATIONS: dict[str, Registration] = {
    "mjx-f64": Registration(
        package="mujoco-mjx", extra="mjx", ports="mujoco", integrators=PORTS, run=Format.MJCF,
        model=A + "mjx.model:MjxF64Model", on_request=True, accelerator=True,
    ),
    "mjx": Registration(
        package="mujoco-mjx",
        run=Format.MJCF,
        extra="mjx",
        ports="mujoco",
        float32=True,
        integrators=PORTS,
        model=A + "mjx.model:MjxModel", on_request=True, label="mujoco-mjx",
        accelerator=True,
    ),
}
