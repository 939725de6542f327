"""A book case's couplings as PyBullet's own constraints: a coupling c_a q_a + c_b q_b = 0 of
two joints is its gear constraint (``createConstraint(..., JOINT_GEAR)``,
``changeConstraint(gearRatio=c_b/c_a, erp=0)``), which holds q̇_a + r q̇_b = 0 in every
``stepSimulation``; its ``getConstraintState`` is the multiplier λ of the row (1, r), so the
coupling's f in M v̇ + h = τ + Cᵀ f is λ / c_a. Measured on PyBullet 3.2.7 (an Atwood machine,
r = 1 and 2): the step's v̇ and λ are the KKT solve's to round-off. A coupling of more than
two joints is no gear: PyBullet's limit, refused in its words."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pybullet as pb

from dyncheck.cases.multibody import Coupling
from dyncheck.errors import Unsupported

MAX_FORCE = 1e12
"""The gear's force bound: none in effect (the constraint holds whatever it takes)."""


@dataclass(frozen=True, kw_only=True)
class Gear:
    """One coupling as a gear constraint: its id, the first joint's coefficient c_a, and the
    multibody both joints belong to."""

    constraint: int
    scale: float
    body: int


GEARED = 2
"""The joints one gear constraint (``JOINT_GEAR``) ties."""


def gears(client: int, joints: dict[str, tuple[int, int]],
          couplings: Sequence[Coupling]) -> list[Gear]:
    """Each coupling as a gear constraint between its two joints (``joints``: name → (body,
    joint index)); refused where a coupling is not two joints of one multibody."""
    out = []
    for coupling in couplings:
        if len(coupling.coefs) != GEARED:
            raise Unsupported(
                f"pybullet: its gear constraint (JOINT_GEAR) couples two joints; "
                f"{coupling.name!r} couples {len(coupling.coefs)}")
        (a, c_a), (b, c_b) = coupling.coefs
        (body_a, joint_a), (body_b, joint_b) = joints[a], joints[b]
        if body_a != body_b:
            raise Unsupported(f"pybullet: {coupling.name!r} couples joints of two multibodies, "
                              "which dyncheck steps one at a time")
        gear = pb.createConstraint(body_a, joint_a, body_b, joint_b, pb.JOINT_GEAR,
                                   jointAxis=[0, 0, 1], parentFramePosition=[0, 0, 0],
                                   childFramePosition=[0, 0, 0], physicsClientId=client)
        pb.changeConstraint(gear, gearRatio=float(c_b) / float(c_a), maxForce=MAX_FORCE,
                            erp=0.0, physicsClientId=client)
        out.append(Gear(constraint=gear, scale=float(c_a), body=body_a))
    return out


def multipliers(client: int, held: Sequence[Gear]) -> list[float]:
    """Each coupling's f of the last step (λ / c_a)."""
    return [pb.getConstraintState(g.constraint, physicsClientId=client)[0] / g.scale
            for g in held]
