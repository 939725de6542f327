"""What MuJoCo compiled from an MJCF, in the form the file states it: each body's mass
properties as an ``<inertial>``, each joint's stiffness and damping. A copy of the file that
states them makes another parser read what MuJoCo does (the fix of a hint that another engine
weighs a body's geoms otherwise, ignores ``settotalmass`` or ``springdamper``, #77)."""

from __future__ import annotations

from dataclasses import replace

import mujoco

from dyncheck.adapters.formats.bodies import key
from dyncheck.adapters.model_tree import Inertial, ModelTree, WantsCompiled

SPRINGS = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
"""The joints whose stiffness and damping a copy states (one degree of freedom each)."""


def inertials(m: mujoco.MjModel) -> dict[str, Inertial]:
    """Body key (its name, else ``#`` its id: :mod:`~dyncheck.adapters.formats.bodies`) → its
    compiled inertial (``body_ipos``, ``body_iquat``, ``body_mass``, ``body_inertia``: the
    body's frame, as ``<inertial>`` takes them); the world left out."""
    out = {}
    for b in range(1, m.nbody):
        name = key(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or "", b)
        if name:
            out[name] = Inertial(
                pos=tuple(float(x) for x in m.body_ipos[b]),
                quat=tuple(float(x) for x in m.body_iquat[b]),
                mass=float(m.body_mass[b]),
                diaginertia=tuple(float(x) for x in m.body_inertia[b]))
    return out


def springs(m: mujoco.MjModel) -> dict[str, tuple[float, float]]:
    """Joint name → its compiled (stiffness, damping), for named hinges and slides."""
    return {name: (float(m.jnt_stiffness[j]), float(m.dof_damping[m.jnt_dofadr[j]]))
            for j in range(m.njnt) if int(m.jnt_type[j]) in SPRINGS
            and (name := mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j))}


def stated(tree: ModelTree, m: mujoco.MjModel, *, scaled: bool) -> ModelTree:
    """``tree`` with what a copy states from (:attr:`ModelTree.inertials`, ``springs``),
    and, where ``settotalmass`` rescaled the masses (``scaled``) and every body has a name,
    the wish that each other engine read the copy with every body's scaled inertial stated
    (:class:`WantsCompiled` ``every``: its :data:`TOTAL_MASS` fix)."""
    bodies = inertials(m)
    every = scaled and len(bodies) == m.nbody - 1
    return replace(tree, inertials=bodies, springs=springs(m), wants_compiled=(WantsCompiled(
        subject="model", fields=("mass", "inertia", "com"), bodies=tuple(bodies),
        every=True),) if every else ())
