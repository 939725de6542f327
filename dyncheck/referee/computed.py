"""A neutral tree as the book's general method takes it, and what an engine computing with
other values than it holds changes: its bodies for :class:`~dyncheck.reference.tree.
TreeDynamics` (§2.2's Lagrange equations (2.2.23)–(2.2.24) on a tree), a reading put in the
canonical layout, and the effect of a declared
:attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia` — the general method on the
inertia computed with against the general method on the inertia held."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from dyncheck.adapters.model_tree import (
    Canonical,
    Dynamics,
    JointType,
    Layout,
    ModelTree,
    StateLayout,
    TreeJoint,
    canonical,
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
    """An engine's reading in the canonical state layout (MuJoCo's), its armature in the
    canonical order: what the general method evaluates at canonical states. Its joints in
    the canonical order where each follows its parent there, else (an engine that chains a
    body's joints in another order: Newton's D6) parents first, each joint's layout still
    its canonical place (:func:`general` gathers the columns)."""
    places = StateLayout().joints(list(canon.types))
    joints = [replace(tree.joint(name), layout=place,
                      armature=canonical_armature(tree.joint(name)))
              for name, place in zip(canon.names, places, strict=True)]
    return replace(tree, joints=parents_first(joints), nq=canon.nq, nv=canon.nv)


def _key(lay: Layout) -> tuple[object, ...]:
    """What places a joint's coordinates: where they start, and their conventions."""
    return (lay.q_start, lay.v_start, lay.quat, lay.quat_first, lay.angular_first,
            lay.linear_axes, lay.angular_axes, lay.cos_sin)


def canonical_of(tree: ModelTree) -> ModelTree:
    """The first engine's reading as the canonical one: itself where it holds the canonical
    layout (MuJoCo's) parents first, else put in it (:func:`canonical_reading`: Drake's,
    where MuJoCo and Pinocchio refuse the file, lists a child before its parent and holds a
    free joint's velocities otherwise; taken as it was, the referee crashed on it, or judged
    it on the wrong columns)."""
    places = StateLayout().joints([j.type for j in tree.joints])
    if parents_first(list(tree.joints)) == tree.joints and all(
            _key(j.layout) == _key(p) for j, p in zip(tree.joints, places, strict=True)):
        return tree
    ordered = replace(tree, joints=parents_first(list(tree.joints)))
    placed = canonical_reading(canonical(ordered), ordered)
    zero = {j.name: j.layout.zero for j in tree.joints}  # (a hinge's reference angle kept)
    return replace(placed, joints=tuple(replace(j, layout=replace(j.layout, zero=zero[j.name]))
                                        for j in placed.joints))


def parents_first(joints: list[TreeJoint]) -> tuple[TreeJoint, ...]:
    """``joints`` in their order, except that a joint whose parent comes later waits for
    it (the general method takes each body after its parent)."""
    names = {j.name for j in joints}
    placed: set[str | None] = {None}
    out: list[TreeJoint] = []
    pending = list(joints)
    while pending:
        ready = next((j for j in pending if j.parent in placed or j.parent not in names),
                     pending[0])  # (a cycle cannot come from a tree: taken as it is)
        pending.remove(ready)
        placed.add(ready.name)
        out.append(ready)
    return tuple(out)


def _columns(tree: ModelTree) -> tuple[np.ndarray, np.ndarray] | None:
    """The columns of q and v that the tree's joints take, in their order (their layouts'
    places); None where that is q and v as they are."""
    qi = np.concatenate([np.arange(j.layout.q_start, j.layout.q_start + j.layout.nq)
                         for j in tree.joints]) if tree.joints else np.zeros(0, int)
    vi = np.concatenate([np.arange(j.layout.v_start, j.layout.v_start + j.layout.nv)
                         for j in tree.joints]) if tree.joints else np.zeros(0, int)
    if np.array_equal(qi, np.arange(len(qi))) and np.array_equal(vi, np.arange(len(vi))):
        return None
    return qi, vi


class Gathered:
    """One of the referee's methods on a tree whose joint order is not its layout's (a body's
    joints chained in another order than the canonical engine's: Newton's D6), at canonical
    states: the columns gathered in the tree's order, M and h put back in the layout's."""

    def __init__(self, method: Any, columns: tuple[np.ndarray, np.ndarray]) -> None:
        self.method, (self.qi, self.vi) = method, columns
        self.back = np.argsort(self.vi)

    def at_states(self, q: np.ndarray, v: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        mass, bias, kinetic, potential = self.method.at_states(q[:, self.qi], v[:, self.vi])
        return mass[:, self.back][:, :, self.back], bias[:, self.back], kinetic, potential

    def reach(self, q: np.ndarray) -> tuple[float, float]:
        out: tuple[float, float] = self.method.reach(q[:, self.qi])
        return out


def in_layout(method: Any, tree: ModelTree) -> Any:
    """``method`` (the general method or the recursive algorithm, built on ``tree``'s joints
    in their order) taking canonical states: itself where the order is the layout's, else
    :class:`Gathered`."""
    columns = _columns(tree)
    return method if columns is None else Gathered(method, columns)


def general(tree: ModelTree, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
    """The general method on ``tree`` (canonical layout) at the states: M, h, T, V, the
    forward dynamics at τ = 0 and the inverse dynamics at v̇ = a (columns gathered in the
    tree's joint order and put back, where that is another: :func:`in_layout`)."""
    solver = in_layout(TreeDynamics(bodies(tree), tree.gravity), tree)
    mass, bias, kinetic, potential = solver.at_states(q, v)
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


def computing_effect(canon: Canonical, tree: ModelTree, *, q: np.ndarray, v: np.ndarray,
                     a: np.ndarray) -> tuple[Dynamics, Dynamics] | None:
    """The general method on what the file says as ``tree``'s engine read it — its joints in
    the written order (:attr:`~dyncheck.adapters.model_tree.ModelTree.as_written`), the
    inertia it holds — and on what the engine computes with — its joints as it applies
    them, the inertia it computes with —, at canonical states; None where the two are one."""
    written = tree.as_written if tree.as_written is not None else tree
    if tree.as_written is None and all(j.computed_inertia is None for j in tree.joints):
        return None
    if not set(canon.names) <= {j.name for j in tree.joints}:
        return None
    computes = canonical_reading(canon, tree)
    computes = replace(computes, joints=tuple(
        j if j.computed_inertia is None else replace(j, inertia=j.computed_inertia)
        for j in computes.joints))
    return general(canonical_reading(canon, written), q, v, a), general(computes, q, v, a)


def depth(tree: ModelTree) -> int:
    """The number of joints on the longest chain from the world."""
    level: dict[str | None, int] = {None: 0}
    for j in tree.joints:  # parents come first in every engine's order
        level[j.name] = level.get(j.parent, 0) + 1
    return max(level.values())


def size(tree: ModelTree) -> float:
    """The model's length scale: the largest distance of a joint or centre of mass from the
    origin (at least 1 mm)."""
    points = [j.anchor for j in tree.joints] + [j.com for j in tree.joints if j.mass > 0]
    return max([1e-3, *(float(np.linalg.norm(p)) for p in points)])
