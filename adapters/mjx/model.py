"""MJX's loader of a model file (``check --impl mjx``, ``run``): MuJoCo's reading of the file,
compiled by MuJoCo (:class:`~dyncheck.adapters.mujoco.port_model.PortModel`) and computed by
:mod:`.port` in float32 (``mjx``) or float64 (``mjx-f64``)."""

from __future__ import annotations

from dyncheck.adapters.base import Offer
from dyncheck.adapters.mujoco.port_model import RUN, PortModel


class MjxModel(PortModel):
    engine = "mjx"
    package = "mujoco-mjx"
    rk4_group_order = 2  # (its RK4 sums stage velocities in one tangent space: the module's)
    gyroscopic_implicit = False  # (its implicitfast: actuator and damping derivatives only)
    euler_damps_when_disabled = True
    offers = RUN | {Offer.DERIVATIVES, Offer.ACTUATION, Offer.INPUT_JACOBIAN, Offer.CLOSURES}
    port_class = "dyncheck.adapters.mjx.port:MjxPort"


class MjxF64Model(MjxModel):
    engine = "mjx-f64"
    port_class = "dyncheck.adapters.mjx.port:MjxF64Port"
