"""Joints matched across engines that name them otherwise: by their body and their place in
it, then by their place in the tree (the model check's step 1: every engine's tree aligned
with the canonical engine's before any field is compared)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from dyncheck.adapters.closures import Closure
from dyncheck.adapters.model_tree import ModelTree, TreeJoint


def _parent(joint: TreeJoint, renames: dict[str, str]) -> str | None:
    return renames.get(joint.parent, joint.parent) if joint.parent else None


def align_by_body(canonical: ModelTree, tree: ModelTree) -> tuple[ModelTree, list[str]]:
    """Joints an engine names otherwise matched to the canonical engine's by their body and
    their order in it, where the types agree: Drake names an MJCF ``<freejoint>`` after its
    body; Pinocchio's MJCF parser makes a body's several joints one composite joint whose
    components it names ``<composite>[k]``. What is left — joints and bodies without names
    in the file, which each engine names its own way — is matched by place in the tree: the
    same number, the same types in the same order, the same parents."""
    known = {j.name for j in canonical.joints}
    names = {j.name for j in tree.joints}
    renames: dict[str, str] = {}
    for body in dict.fromkeys(j.body for j in tree.joints):
        mine = [j for j in tree.joints if j.body == body]
        theirs = [j for j in canonical.joints if j.body == body]
        if (len(mine) == len(theirs) and any(j.name not in known for j in mine)
                and all(a.type is b.type for a, b in zip(mine, theirs, strict=True))
                and not any(b.name in names and b.name != a.name
                            for a, b in zip(mine, theirs, strict=True))):
            renames.update({a.name: b.name for a, b in zip(mine, theirs, strict=True)
                            if a.name != b.name})
    renamed = {renames.get(j.name, j.name) for j in tree.joints}
    mine = [j for j in tree.joints if renames.get(j.name, j.name) not in known]
    theirs = [j for j in canonical.joints if j.name not in renamed]
    by_place = {a.name: b.name for a, b in zip(mine, theirs, strict=False)}
    placed = bool(mine) and len(mine) == len(theirs) and all(  # the rest by place in the tree
        a.type is b.type and _parent(a, renames | by_place) == b.parent
        for a, b in zip(mine, theirs, strict=True))
    if placed:
        renames.update(by_place)
    if not renames:
        return tree, []
    joints = tuple(
        replace(j, name=renames.get(j.name, j.name),
                parent=renames.get(j.parent, j.parent) if j.parent else None)
        for j in tree.joints
    )
    notes = [f"{tree.engine}: joint {old!r} (body {tree.joint(old).body!r}) matched to {new!r} "
             "by its body and its place in it" for old, new in renames.items()
             if not (placed and old in by_place)]
    if placed:
        notes.append(f"{tree.engine}: {len(by_place)} joints without a common name (unnamed in "
                     "the file) matched by their place in the tree: " + ", ".join(
                         f"{old!r} = {new!r}" for old, new in by_place.items()))
    return replace(tree, joints=joints, hints=tuple(
        (renames.get(j, j), f, why) for j, f, why in tree.hints),
        closures=tuple(_renamed(c, renames) for c in tree.closures)), notes


def _renamed(closure: Closure, renames: Mapping[str, str]) -> Closure:
    """``closure`` with the joints it names renamed as its tree's are (a free joint Drake
    names after its body, held by a ``<connect>``)."""
    def name(joint: str | None) -> str | None:
        return None if joint is None else renames.get(joint, joint)
    return replace(closure, joint1=name(closure.joint1), joint2=name(closure.joint2),
                   first=tuple((renames.get(j, j), k) for j, k in closure.first),
                   second=tuple((renames.get(j, j), k) for j, k in closure.second))


def with_fixed_aligned(canonical: ModelTree, tree: ModelTree) -> ModelTree:
    """``tree`` with the reading of each fixed copy (:attr:`ModelTree.fixed`) aligned with the
    canonical engine's as the tree itself is (:func:`align_by_body`): a fix is measured on
    the joints by their canonical names (Pinocchio names a body's several joints by their
    composite, in the copy as in the file)."""
    if not tree.fixed:
        return tree
    return replace(tree, fixed=tuple(
        replace(r, tree=align_by_body(canonical, r.tree)[0]) if r.tree is not None else r
        for r in tree.fixed))
