"""Drake's armature hints proved by their fixes (#77): the fix each names (an actuator on the
joint; the joint's actuators written as ``<motor>``) applied to a copy of the MJCF, the copy
parsed by Drake and read (:class:`~dyncheck.adapters.model_tree.FixedReading`), so that the
comparison layer measures the armature again."""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from pathlib import Path

from dyncheck.adapters.formats.edits import Edit, copied
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.model_tree import FixedReading, ModelTree
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


def armature_fixed(source: ModelFile, root: ET.Element, *, unactuated: Sequence[str],
                   unread: Sequence[str], read: Read) -> tuple[FixedReading, ...]:
    """Drake's reading of the MJCF ``source`` (``root``: its includes inlined) with each
    armature hint's fix applied: one copy for the joints no actuator drives, one for those
    driven only by actuators Drake did not read."""
    out: list[FixedReading] = []
    for joints, edit in ((unactuated, motors(unactuated)), (unread, as_motors(unread))):
        if not joints:
            continue
        tree, refused = None, ""
        with tempfile.TemporaryDirectory(prefix="dyncheck-drake-fix-") as folder:
            try:
                tree = read(copied(source, root, (edit,), Path(folder)))
            except (EngineError, Unsupported) as exc:
                refused = str(exc)
        out += [FixedReading(subject=j, fields=("armature",), fix=edit.words, tree=tree,
                             refused=refused) for j in joints]
    return tuple(out)
