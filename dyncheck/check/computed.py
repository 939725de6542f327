"""A neutral tree as the book's general method takes it, and what an engine computing with
other values than it holds changes: its bodies for :class:`~dyncheck.reference.tree.
TreeDynamics` (§2.2's Lagrange equations (2.2.23)–(2.2.24) on a tree), a reading put in the
canonical layout, and the effect of a declared
:attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia` — the general method on the
inertia computed with against the general method on the inertia held."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dyncheck.adapters.layout import Canonical
from dyncheck.adapters.model_tree import (
    Dynamics,
    JointType,
    ModelTree,
    StateLayout,
    TreeJoint,
)
from dyncheck.reference.tree import Body, TreeDynamics


def bodies(tree: ModelTree) -> list[Body]:
    """The tree's joints, each with the body it alone moves, as the general method takes
    them."""
    index = {j.name: i for i, j in enumerate(tree.joints)}
    return [
        Body(
            kind=str(j.type), parent=-1 if j.parent is None else index[j.parent],
            axis=j.axis, anchor=j.anchor, frame=j.frame, zero=j.layout.zero, mass=j.mass,
            com=j.com, inertia=j.inertia, armature=j.armature,
        )
        for j in tree.joints
    ]


def canonical_armature(joint: TreeJoint) -> tuple[float, ...]:
    """A joint's armature in the canonical order of its velocities (a free joint's linear
    then angular; an engine holding the angular first declares it in its layout)."""
    arm = tuple(joint.armature)
    if joint.type is JointType.FREE and joint.layout.angular_first and len(arm) == 6:
        return arm[3:] + arm[:3]
    return arm


def canonical_reading(canon: Canonical, tree: ModelTree) -> ModelTree:
    """An engine's reading in the canonical joint order and state layout (MuJoCo's), its
    armature in the canonical order: what the general method evaluates at canonical
    states."""
    places = StateLayout().joints(list(canon.types))
    joints = tuple(replace(tree.joint(name), layout=place,
                           armature=canonical_armature(tree.joint(name)))
                   for name, place in zip(canon.names, places, strict=True))
    return replace(tree, joints=joints, nq=canon.nq, nv=canon.nv)


def general(tree: ModelTree, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
    """The general method on ``tree`` (canonical layout) at the states: M, h, T, V, the
    forward dynamics at τ = 0 and the inverse dynamics at v̇ = a."""
    mass, bias, kinetic, potential = TreeDynamics(bodies(tree), tree.gravity).at_states(q, v)
    return Dynamics(mass_matrix=mass, bias=bias,
                    forward=np.linalg.solve(mass, -bias[..., None])[..., 0],
                    inverse=np.einsum("sij,sj->si", mass, a) + bias,
                    kinetic=kinetic, potential=potential)


def computed_inertia_effect(canon: Canonical, tree: ModelTree, *, q: np.ndarray,
                            v: np.ndarray, a: np.ndarray) -> tuple[Dynamics, Dynamics] | None:
    """The general method on ``tree`` as held and on ``tree`` with the inertias its engine
    computes with (:attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia`), at
    canonical states: their difference is what computing otherwise changes; None where the
    engine computes with what it holds."""
    if all(j.computed_inertia is None for j in tree.joints) or \
            not set(canon.names) <= {j.name for j in tree.joints}:
        return None
    held = canonical_reading(canon, tree)
    computes = replace(held, joints=tuple(
        j if j.computed_inertia is None else replace(j, inertia=j.computed_inertia)
        for j in held.joints))
    return general(held, q, v, a), general(computes, q, v, a)
