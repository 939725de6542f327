"""Newton's constraints (#78): the loop joints and mimic constraints its importers make of a
file's, read into neutral closures.

Newton's MJCF importer (1.8) makes a ``<connect>`` a BALL loop joint and a ``<weld>`` a FIXED
loop joint — joints outside every articulation whose child body an articulation already
moves (the rule of its own MuJoCo solver, ``SolverMuJoCo``: ``joint_articulation == -1``);
a ``<joint>`` equality and a URDF ``<mimic>`` a mimic constraint, q₀ = coef0 + coef1 · q₁ (it
warns that it keeps only these two terms of a polynomial). A loop joint's frames are its
``joint_X_p`` on the parent body and ``joint_X_c`` on the child. Its loop joints own
coordinates in its state (left out of the tree's joints: no articulation moves them).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from dyncheck.adapters.closures import Closure, ClosureKind


def loops(m: Any) -> frozenset[int]:
    """The loop joints: outside every articulation, their child moved by one."""
    articulated = m.joint_articulation.numpy()
    child = m.joint_child.numpy()
    moved = {int(child[j]) for j in range(len(child)) if articulated[j] >= 0}
    return frozenset(j for j in range(len(child))
                     if articulated[j] < 0 and int(child[j]) in moved)


def read(m: Any, joints: frozenset[int], *, kinds: dict[int, ClosureKind],
         bodies: np.ndarray, pose: Callable[[np.ndarray], np.ndarray],
         mover: Callable[[int], str | None], name: Callable[[int], str]) -> tuple[Closure, ...]:
    """Each loop joint of ``kinds`` (Newton's joint type → what it holds) as a closure (its
    frames in world axes at the body poses ``bodies``; ``mover`` the tree joint that moves a
    body, by index, −1 the world) and each enabled mimic constraint as a joint coupling."""
    types = m.joint_type.numpy()
    parent, child = m.joint_parent.numpy(), m.joint_child.numpy()
    x_p, x_c = m.joint_X_p.numpy(), m.joint_X_c.numpy()
    out = []
    for j in sorted(joints):
        kind = kinds.get(int(types[j]))
        if kind is None:
            continue
        above = np.eye(4) if parent[j] < 0 else bodies[parent[j]]
        one, two = above @ pose(x_p[j]), bodies[child[j]] @ pose(x_c[j])
        out.append(Closure(kind=kind, name=name(j), joint1=mover(int(parent[j])),
                           joint2=mover(int(child[j])), point1=one[:3, 3], point2=two[:3, 3],
                           held=one[:3, :3] @ two[:3, :3].T if kind is ClosureKind.WELD
                           else np.eye(3)))
    count = int(getattr(m, "constraint_mimic_count", 0))
    if count:
        enabled = m.constraint_mimic_enabled.numpy()
        lead = m.constraint_mimic_joint1.numpy()
        follow = m.constraint_mimic_joint0.numpy()
        coef0 = m.constraint_mimic_coef0.numpy()
        coef1 = m.constraint_mimic_coef1.numpy()
        for k in range(count):
            if enabled[k]:
                out.append(Closure(kind=ClosureKind.JOINT, name=f"mimic {name(int(follow[k]))}",
                                   first=((name(int(follow[k])), 1.0),),
                                   second=((name(int(lead[k])), 1.0),),
                                   polycoef=(float(coef0[k]), float(coef1[k]))))
    return tuple(out)
