"""Where an engine places a whole model (:func:`placement`): the one rigid motion that carries
one reading's joints onto another's, found so that a model placed or turned as a whole is one
row of a model check, its fields compared after undoing it (:mod:`.describe`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from dyncheck.adapters.model_tree import JointType, ModelTree, TreeJoint


@dataclass(frozen=True, kw_only=True)
class Placement:
    """The one rigid motion x_b = R x_a + t that carries every common joint of ``a`` onto
    ``b``'s (anchors and centres of mass as points, axes as directions)."""

    rotation: np.ndarray
    translation: np.ndarray

    @property
    def turned(self) -> bool:
        return bool(np.abs(self.rotation - np.eye(3)).max() > 0)

    def undo(self, joint: TreeJoint) -> TreeJoint:
        """``joint`` of ``b`` carried back into ``a``'s placement."""
        back = self.rotation.T
        return replace(joint, anchor=back @ (joint.anchor - self.translation),
                       com=back @ (joint.com - self.translation), axis=back @ joint.axis,
                       frame=back @ joint.frame, inertia=back @ joint.inertia @ self.rotation)


def placement(a: ModelTree, b: ModelTree, tol: float) -> Placement | None:
    """The rigid motion (:class:`Placement`) that carries every common joint of ``a`` onto
    ``b``'s, where there is one and it is not the identity (within ``tol``): the model placed
    elsewhere in the world, or turned (Pinocchio's MJCF parser puts a jointless top-level
    body at the world origin, unrotated — measured). The rotation from the joints' axes and
    the directions between their points (Kabsch's SVD); a translation alone where those
    directions do not fix one."""
    pairs = [(ja, b.joint(ja.name)) for ja in a.joints
             if ja.name in {j.name for j in b.joints} and b.joint(ja.name).type is ja.type]
    points = [(ja.com, jb.com) for ja, jb in pairs if ja.mass > 0 and jb.mass > 0]
    points += [(ja.anchor, jb.anchor) for ja, jb in pairs if ja.type is not JointType.SLIDE]
    if not points:
        return None
    directions = [(ja.axis, jb.axis) for ja, jb in pairs
                  if ja.type in (JointType.HINGE, JointType.SLIDE)]
    directions += [(pa - points[0][0], pb - points[0][1]) for pa, pb in points[1:]]
    if not all(np.isfinite(x).all() for pair in (*points, *directions) for x in pair):
        return None  # a tree read with NaN (a broken file): nothing to place
    rotation = np.eye(3)
    if directions:
        da = np.array([d for d, _ in directions])
        db = np.array([d for _, d in directions])
        if np.linalg.matrix_rank(da, tol=tol) >= 2:
            u, _, vt = np.linalg.svd(db.T @ da)
            rotation = u @ np.diag([1.0, 1.0, np.linalg.det(u @ vt)]) @ vt
            if np.abs(rotation - np.eye(3)).max() <= tol:
                rotation = np.eye(3)
    t = points[0][1] - rotation @ points[0][0]
    if not np.abs(rotation - np.eye(3)).max() and float(np.abs(t).max()) <= tol:
        return None
    moved = Placement(rotation=rotation, translation=t)
    for ja, jb in pairs:
        back = moved.undo(jb)
        if np.abs(ja.axis - back.axis).max() > tol:
            return None
        off = back.anchor - ja.anchor
        off = np.cross(off, ja.axis) if ja.type is JointType.HINGE else off
        if ja.type is not JointType.SLIDE and float(np.abs(off).max()) > tol:
            return None
        if ja.mass > 0 and back.mass > 0 and float(np.abs(back.com - ja.com).max()) > tol:
            return None
    return moved
