"""Newton's D6 joint read as the chain of joints it applies.

Newton 1.8's MJCF importer fuses the joints of one body into one D6 joint, whose transform
translates along its linear axes first and then rotates about its angular axes composed
intrinsically (``jcalc_transform``, ``compute_2d_rotational_dofs`` and
``compute_3d_rotational_dofs`` in its source), whatever order the file writes them in: a
chain of slides, then hinges, each group in the written order. That chain is what Newton
holds and computes with; the file's order is kept beside it (:attr:`~.model_tree.ModelTree.
as_written`), so that the referee on both measures what the order changes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from dyncheck.adapters.model_tree import JointType, Layout, ModelTree, TreeJoint
from dyncheck.adapters.proof import Proof

D6_ORDER = (
    "Newton fused the joints of body {body!r} ({written}, as written) into one D6 joint, "
    "which applies its slides first, then its hinges: {applied} (its jcalc_transform; "
    "measured by the referee on both orders; fix: one joint per body, with massless bodies "
    "between; dyncheck explain newton-several-joints-on-a-body)"
)


def d6_chain(fused: Sequence[tuple[str, JointType]], *, frame: np.ndarray, axes: np.ndarray,
             parent: str | None, body: str, starts: tuple[int, int],
             lumped: tuple[float, np.ndarray, np.ndarray]) -> list[TreeJoint]:
    """The D6 joint's coordinates as a chain of one-coordinate joints at its frame (``frame``,
    4×4 at the reference configuration; ``axes`` in it; ``starts`` its first q and v), in the
    order Newton applies them, the body's mass (``lumped``: mass, centre, inertia) on the
    last."""
    q_start, v_start = starts
    out = []
    for k, (name, kind) in enumerate(fused):
        end = k == len(fused) - 1
        mass, com, inertia = lumped if end else (0.0, np.zeros(3), np.zeros((3, 3)))
        out.append(TreeJoint(
            name=name, type=kind, parent=parent if k == 0 else fused[k - 1][0], body=body,
            axis=frame[:3, :3] @ np.asarray(axes[k], float), anchor=frame[:3, 3],
            frame=frame[:3, :3], mass=float(mass), com=com, inertia=inertia, armature=(0.0,),
            damping=(0.0,), range=None,
            layout=Layout(q_start=q_start + k, v_start=v_start + k, nq=1, nv=1)))
    return out


def written_order(tree: ModelTree, written: Sequence[Sequence[str]]) -> ModelTree:
    """``tree`` with each fused chain (its joints' names in the file's order, ``written``)
    re-chained in that order: the first takes the chain's parent, each the one before, the
    last the body's mass; the joints below keep their parent, the chain's last."""
    joints = list(tree.joints)
    for names in written:
        chain = [tree.joint(n) for n in names]
        applied = sorted(chain, key=lambda j: j.layout.q_start)
        top, carrier = applied[0].parent, applied[-1]
        at = min(joints.index(j) for j in chain)
        rechained = [replace(j, parent=top if k == 0 else names[k - 1],
                             mass=carrier.mass if k == len(names) - 1 else 0.0,
                             com=carrier.com if k == len(names) - 1 else np.zeros(3),
                             inertia=carrier.inertia if k == len(names) - 1 else
                             np.zeros((3, 3)))
                     for k, j in enumerate(chain)]
        joints = [replace(j, parent=names[-1]) if j.parent == carrier.name else j
                  for j in joints if j.name not in names]
        joints[at:at] = rechained
    return replace(tree, joints=tuple(joints), as_written=None)


PROOFS = {
    "D6_ORDER": Proof.MEASURED,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
