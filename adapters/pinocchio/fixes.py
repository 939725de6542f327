"""The fixes that Pinocchio's MJCF hints (:mod:`.mjcf`) name, as edits of a copy of the file:
a cause is a counterfactual, measured (#77). Each edit works on the model with its includes
inlined; the copy, with absolute asset paths, is loaded by Pinocchio again and read, and the
comparison layer then says whether the fix closes the difference the hint explains.

Every edit keeps the model MuJoCo compiles the same. It states what the class or the
compiler already gives (a joint's pos, a geom's mass), names an unnamed body, or puts the
top-level bodies under one body that has no pose and no joint.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

from dyncheck.adapters.formats.edits import Edit
from dyncheck.adapters.formats.mjcf_copy import geoms, joints

ROOT = "dyncheck_root"
"""The name of the body :data:`ONE_TREE` puts the top-level bodies under."""


@dataclass(frozen=True, kw_only=True)
class Fix:
    """One hint's fix: the (joint, fields) it explains, the fix in words, and the edit."""

    subject: str
    fields: tuple[str, ...]
    edit: Edit


def joint_pos(name: str, pos: str) -> Edit:
    """Write on joint ``name`` the ``pos`` it takes from its default class."""
    def edit(root: ET.Element) -> None:
        for joint in joints(root):
            if joint.element.get("name") == name and "pos" in joint.attrs:
                joint.element.set("pos", joint.attrs["pos"])
    return Edit(f'pos="{pos}" written on joint {name!r}', edit)


def _class_masses(root: ET.Element) -> None:
    """Write on each geom the ``mass`` it takes from a default class."""
    for geom in geoms(root):
        if "mass" in geom.attrs and "mass" not in geom.stated:
            geom.element.set("mass", geom.attrs["mass"])


def _name_bodies(root: ET.Element) -> None:
    """Name every ``<body>`` that has no attribute at all."""
    for k, body in enumerate(b for b in root.iter("body") if not b.attrib):
        body.set("name", f"dyncheck_body_{k}")


def _one_tree(root: ET.Element) -> None:
    """Put every top-level body of each ``<worldbody>`` under one body with no pose and no
    joint: MuJoCo's model is the same (a jointless body at the origin, unrotated, welds its
    children where they were)."""
    for world in root.findall("worldbody"):
        tops = world.findall("body")
        if not tops:
            continue
        wrapper = ET.Element("body", {"name": ROOT})
        at = list(world).index(tops[0])
        for body in tops:
            world.remove(body)
            wrapper.append(body)
        world.insert(at, wrapper)


def _one_defaults(root: ET.Element) -> None:
    """Move every top-level ``<default>`` block's classes under the first."""
    blocks = root.findall("default")
    for block in blocks[1:]:
        for child in list(block):
            blocks[0].append(child)
        root.remove(block)


CLASS_MASSES = Edit("the mass each geom takes from a default class written on the geom",
                    _class_masses)
NAME_BODIES = Edit("every body without attributes named", _name_bodies)
ONE_TREE = Edit("the top-level bodies put under one body without pose or joint", _one_tree)
ONE_DEFAULTS = Edit("every class put under one top-level <default>", _one_defaults)
