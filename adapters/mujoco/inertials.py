"""Each body's mass properties as MuJoCo compiled them, in the form an MJCF ``<inertial>``
states them: what a copy of the file gives a body so that another parser reads the mass,
centre of mass and inertia MuJoCo does (the fix of a hint that another engine weighs the
body's geoms otherwise, #77)."""

from __future__ import annotations

import mujoco

from dyncheck.adapters.model_tree import Inertial


def compiled(m: mujoco.MjModel) -> dict[str, Inertial]:
    """Body name → its compiled inertial (``body_ipos``, ``body_iquat``, ``body_mass``,
    ``body_inertia``: the body's frame, as ``<inertial>`` takes them); unnamed bodies and
    the world left out."""
    out = {}
    for b in range(1, m.nbody):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
        if name:
            out[name] = Inertial(
                pos=tuple(float(x) for x in m.body_ipos[b]),
                quat=tuple(float(x) for x in m.body_iquat[b]),
                mass=float(m.body_mass[b]),
                diaginertia=tuple(float(x) for x in m.body_inertia[b]))
    return out
