"""Drake's hints proved by their fixes (#77): the fix each names (an actuator on the joint;
the joint's actuators written as ``<motor>``; one joint per body; a class's attribute written
on the joint) applied to a copy of the MJCF, the copy parsed by Drake and read
(:class:`~dyncheck.adapters.model_tree.FixedReading`), so that the comparison layer measures
the field again."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from dyncheck.adapters.drake import actuators as drake_actuators
from dyncheck.adapters.drake.hints import Lost, lost_across_gaps, several_joints
from dyncheck.adapters.formats import frames
from dyncheck.adapters.formats.edits import Edit, copied, fixed_copy
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.mjcf_copy import POSE, placed
from dyncheck.adapters.formats.mjcf_unread import springdampers
from dyncheck.adapters.model_tree import FixedReading, JointType, ModelTree, WantsCompiled
from dyncheck.errors import EngineError, Unsupported

Read = Callable[[ModelFile], ModelTree]
"""Drake's reading of a file (its own fixes not measured again)."""

MOTOR_KEYS = frozenset({"name", "class", "joint", "gear", "ctrlrange", "ctrllimited",
                        "forcerange", "forcelimited"})
"""The attributes a ``<general>`` keeps when written as ``<motor>``."""


def motors(joints: Sequence[str]) -> Edit:
    """A ``<motor>`` added on each of ``joints`` (the fix :data:`.hints.UNACTUATED_ARMATURE`
    names)."""
    def edit(root: ET.Element) -> None:
        block = root.find("actuator")
        if block is None:
            block = ET.SubElement(root, "actuator")
        for joint in joints:
            ET.SubElement(block, "motor", {"joint": joint, "name": f"dyncheck_motor_{joint}"})
    return Edit("a <motor> on " + ", ".join(repr(j) for j in joints), edit)


def as_motors(joints: Sequence[str]) -> Edit:
    """Each actuator on ``joints`` that is neither ``<motor>`` nor ``<position>`` written as
    ``<motor>`` (the fix :data:`.hints.UNREAD_ACTUATOR` names)."""
    wanted = set(joints)

    def edit(root: ET.Element) -> None:
        for block in root.iter("actuator"):
            for act in block:
                if act.get("joint") in wanted and act.tag not in ("motor", "position"):
                    act.tag = "motor"
                    for key in set(act.attrib) - MOTOR_KEYS:
                        del act.attrib[key]
    return Edit("the actuators on " + ", ".join(repr(j) for j in joints)
                + " written as <motor>", edit)


def _split(body: ET.Element, parent: ET.Element, k: int) -> None:
    """``body``'s joints each on a body of its own, nested in the file's order: the first
    on a massless body at ``body``'s pose, the last on ``body`` itself, now unmoved within
    them (MuJoCo composes a body's joints in that order, each in the frame the ones before
    it moved: the same model)."""
    def holder(n: int) -> ET.Element:
        made = ET.Element("body", {"name": f"{body.get('name', 'body')}_dyncheck_{k}_{n}"})
        if body.get("childclass"):
            made.set("childclass", body.get("childclass", ""))
        return made

    at = list(parent).index(body)
    parent.remove(body)
    outer = inner = holder(0)
    for key in POSE:  # (the outermost of the split bodies at its pose)
        if key in body.attrib:
            outer.set(key, body.attrib.pop(key))
    joints = body.findall("joint")
    for n, joint in enumerate(joints[:-1]):
        body.remove(joint)
        inner.append(joint)
        if n < len(joints) - 2:
            inner.append(nested := holder(n + 1))
            inner = nested
    inner.append(body)
    parent.insert(at, outer)


def _split_all(root: ET.Element) -> None:
    """Split every body with several joints (:func:`_split`), in document order."""
    parent = {id(child): p for p in root.iter() for child in p}
    for k, body in enumerate(several_joints(root)):
        _split(body, parent[id(body)], k)


SPLIT = Edit("one joint per body, massless bodies between them", _split_all)
"""Every body with several joints split so that each joint has a body of its own (the fix
:data:`.hints.FIRST_OF_SEVERAL` names)."""


def written(lost: Sequence[Lost]) -> Edit:
    """Each attribute Drake loses across a class gap written on its joint, with the value the
    class gives it (the fix :data:`.hints.SKIPPED_CLASS` names)."""
    def edit(root: ET.Element) -> None:
        by_joint = {j.get("name"): j for j in root.iter("joint") if j.get("name")}
        for one in lost:
            by_joint[one.joint].set(one.attribute, one.value)
    words = [f'{x.attribute}="{x.value}" written on {x.joint!r}' for x in lost]
    return Edit(", ".join(words[:4]) + (f" … ({len(words)} attributes)" if len(words) > 4
                                        else ""), edit)


def _read(source: ModelFile, root: ET.Element, edit: Edit,
          read: Read) -> tuple[ModelTree | None, str]:
    """Drake's reading of a copy of ``root`` with ``edit`` applied, or its words refusing
    it."""
    with copied(source, root, (edit,)) as copy:
        try:
            return read(copy), ""
        except (EngineError, Unsupported) as exc:
            return None, str(exc)


def armature_fixed(source: ModelFile, root: ET.Element, *, unactuated: Sequence[str],
                   unread: Sequence[str], read: Read) -> tuple[FixedReading, ...]:
    """Drake's reading of the MJCF ``source`` (``root``: its includes inlined) with each
    armature hint's fix applied: one copy for the joints no actuator drives, one for those
    driven only by actuators Drake did not read."""
    out: list[FixedReading] = []
    for joints, edit in ((unactuated, motors(unactuated)), (unread, as_motors(unread))):
        if joints:
            tree, refused = _read(source, root, edit, read)
            out += [FixedReading(subject=j, fields=("armature",), fix=edit.words, tree=tree,
                                 refused=refused) for j in joints]
    return tuple(out)


def file_fixed(source: ModelFile, root: ET.Element, *, read: Read) -> tuple[FixedReading, ...]:
    """Drake's reading of the MJCF ``source`` (``root``: its includes inlined) with the
    fixes of the hints the file shows: every body of several joints split (each named joint
    but the last: its anchor and axis), and each attribute lost across a class gap written
    on its joint (its field); one copy each."""
    split = [(name, ("anchor", "axis")) for body in several_joints(root)
             for name in [j.get("name") for j in body.findall("joint")][:-1] if name]
    lost = lost_across_gaps(root)
    out: list[FixedReading] = []
    for edit, subjects in ((SPLIT, split), (written(lost), [(x.joint, (x.field,))
                                                             for x in lost])):
        if subjects:
            tree, refused = _read(source, root, edit, read)
            out += [FixedReading(subject=joint, fields=fields, fix=edit.words, tree=tree,
                                 refused=refused) for joint, fields in subjects]
    return tuple(out)


def measured(source: ModelFile, root: ET.Element, plant: Any, tree: ModelTree, *,
             reflected: Mapping[str, float], driven: Mapping[str, list[str]],
             read: Read | None) -> ModelTree:
    """``tree`` (Drake's reading of the MJCF ``source``, ``root`` its includes inlined) with
    its hints' fixes measured (#77): the servos' kv set and the controls scaled by the gear
    on the plant; where ``read`` reads a copy, each armature hint's fix and each of the
    file's hints' applied to a copy and read; and the springdamper hints the comparison
    layer measures (their copy states what MuJoCo compiled: :attr:`ModelTree.
    wants_compiled`). ``reflected``: the joints whose armature Drake holds; ``driven``: the
    file's actuators per joint."""
    tree = replace(tree, wants_compiled=tuple(
        WantsCompiled(subject=j, fields=(f,), joints=(j,))
        for j, f, _ in springdampers(root, "Drake")))
    fixed = drake_actuators.damping_fixed(plant, root, tree) + \
        drake_actuators.gear_fixed(plant, tree) + drake_actuators.effort_fixed(plant, root, tree)
    if read is not None:
        armed = {p.element.get("name") for p in placed(root, "joint", ("armature",))
                 if float(p.attrs.get("armature", "0") or 0) != 0.0}
        bare = [j for j in tree.joints if j.name not in reflected and j.name in armed
                and j.type not in (JointType.BALL, JointType.FREE)]
        unactuated = [j.name for j in bare if not driven.get(j.name)]
        unread = [j.name for j in bare if driven.get(j.name)]
        fixed += armature_fixed(source, root, unactuated=unactuated, unread=unread, read=read)
        fixed += file_fixed(source, root, read=read)
        fixed += ignored_fixed(source, root, driven=driven, read=read)
        framed = root.find(".//frame") is not None
        if framed:  # (the fix IGNORED_FRAME names: the frames undone, each joint held again)
            held, refused = _read(source, root, frames.FLATTEN, read)
            fixed += (FixedReading(subject="model", fields=("joint",), fix=frames.FLATTEN.words,
                                   tree=held, refused=refused),)
        lost, rewritten = lost_across_gaps(root), sorted({*unread, *_ignored(driven)})
        tree = replace(tree, with_fixes=fixed_copy(source, root, [edit for edit, wanted in (
            (frames.FLATTEN, framed),
            (motors(unactuated), unactuated), (as_motors(rewritten), rewritten),
            (SPLIT, several_joints(root)), (written(lost), lost)) if wanted]))
    return replace(tree, fixed=fixed)


def _ignored(driven: Mapping[str, list[str]]) -> list[str]:
    """The joints driven by an actuator Drake's MJCF parser ignores (``driven``: the file's
    actuators per joint)."""
    return sorted(j for j, tags in driven.items()
                  if any(not t.startswith(drake_actuators.READ_TAGS) for t in tags))


def ignored_fixed(source: ModelFile, root: ET.Element, *, driven: Mapping[str, list[str]],
                  read: Read) -> tuple[FixedReading, ...]:
    """Drake's reading of the MJCF ``source`` with every actuator it ignores (neither
    ``<motor>`` nor ``<position>``: ``driven``, the file's actuators per joint) written as
    ``<motor>``, the fix :data:`.actuators.IGNORED` names (the model's actuator hint)."""
    joints = _ignored(driven)
    if not joints:
        return ()
    edit = as_motors(joints)
    tree, refused = _read(source, root, edit, read)
    return (FixedReading(subject="model", fields=("actuator",), fix=edit.words, tree=tree,
                         refused=refused),)
