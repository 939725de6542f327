"""Forces on a PyBullet multibody's links (a book case's external field, :data:`~.base.
Field`), through PyBullet's own means: ``applyExternalForce`` at a link's centre of mass
before each ``stepSimulation`` (cleared by it), and the generalized force Jᵀ F of its
``calculateJacobian`` at that centre (``localPosition`` is relative to the link's centre of
mass frame: zero)."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from dyncheck.adapters.base import Field
from dyncheck.errors import Unsupported


def named_links(client: int, bodies: list[int]) -> dict[str, tuple[int, int]]:
    """Every link by its name (a base by its body's name): (body, link index, −1 the
    base)."""
    out = {}
    for body in bodies:
        out[pb.getBodyInfo(body, physicsClientId=client)[0].decode()] = (body, -1)
        for j in range(pb.getNumJoints(body, physicsClientId=client)):
            out[pb.getJointInfo(body, j, physicsClientId=client)[12].decode()] = (body, j)
    return out


def centre(client: int, body: int, link: int) -> np.ndarray:
    """A link's centre of mass in world axes, as PyBullet's state holds it."""
    if link < 0:
        return np.array(pb.getBasePositionAndOrientation(body, physicsClientId=client)[0])
    return np.array(pb.getLinkState(body, link, computeForwardKinematics=True,
                                    physicsClientId=client)[0])


def _forces(client: int, links: dict[str, tuple[int, int]],
            field: Field) -> dict[str, np.ndarray]:
    return field({name: centre(client, *at) for name, at in links.items()})


def apply_field(client: int, links: dict[str, tuple[int, int]], field: Field) -> None:
    """``field`` at the links' centres of mass now, for the next ``stepSimulation``."""
    for name, force in _forces(client, links, field).items():
        body, link = links[name]
        pb.applyExternalForce(body, link, [float(x) for x in force],
                              [float(x) for x in centre(client, body, link)], pb.WORLD_FRAME,
                              physicsClientId=client)


def field_force(client: int, body: int, *, joints: list[float],
                links: dict[str, tuple[int, int]], field: Field) -> np.ndarray:
    """Jᵀ F over the links of ``body`` the field pushes, its joints at ``joints`` (placed by
    the caller), by ``calculateJacobian`` at each link's centre of mass."""
    out = np.zeros(len(joints))
    zero = [0.0] * len(joints)
    for name, force in _forces(client, links, field).items():
        owner, link = links[name]
        if owner != body or not np.any(force):
            continue
        if link < 0:
            raise Unsupported("pybullet: a force on a moving base is not mapped by dyncheck")
        linear, _ = pb.calculateJacobian(body, link, [0.0, 0.0, 0.0], joints, zero, zero,
                                         physicsClientId=client)
        out += np.asarray(linear, float).T @ np.asarray(force, float)
    return out
