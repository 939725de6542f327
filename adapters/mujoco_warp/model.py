"""MuJoCo Warp's loader of a model file (``check --impl mujoco-warp``, ``run``): MuJoCo's reading
of the file, compiled by MuJoCo (:class:`~dyncheck.adapters.mujoco.port_model.PortModel`) and
computed by :mod:`.port` in float32."""

from __future__ import annotations

from dyncheck.adapters.mujoco.port_model import PortModel


class MujocoWarpModel(PortModel):
    engine = "mujoco-warp"
    package = "mujoco-warp"
    rk4_group_order = 4  # (MuJoCo C 4.0's RK4 on the group, read in mujoco_warp/_src)
    gyroscopic_implicit = True  # (implicit_free_body)
    batches_steps = True
    port_class = "dyncheck.adapters.mujoco_warp.port:MujocoWarpPort"
