"""PyBullet's hint of a URDF link without ``<inertial>`` proved by its fix (#77): the copy
with a massless ``<inertial>`` on each such link (what MuJoCo and Pinocchio give it), loaded
by PyBullet and read (:class:`~dyncheck.adapters.model_tree.FixedReading`)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.model_tree import FixedReading, ModelTree
from dyncheck.errors import EngineError, Unsupported

Read = Callable[[ModelFile], ModelTree]
"""PyBullet's reading of a file (its client closed after; its own fixes not measured)."""

MASSLESS = ('<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
            'izz="0"/></inertial>')


def massless(text: str, links: Sequence[str]) -> str:
    """The URDF ``text`` with a massless ``<inertial>`` on each of ``links``."""
    robot = parsing.root(text)
    wanted = set(links)
    for link in robot.findall("link"):
        if link.get("name") in wanted and link.find("inertial") is None:
            link.insert(0, ET.fromstring(MASSLESS))
    return ET.tostring(robot, encoding="unicode")


def inertial_fixed(source: ModelFile, bare: Mapping[str, list[str]],
                   read: Read) -> tuple[FixedReading, ...]:
    """PyBullet's reading of the URDF with every bare link given a massless ``<inertial>``
    (``bare``: joint → the links without one that it carries), one row of it per joint."""
    if not bare:
        return ()
    links = sorted({link for names in bare.values() for link in names})
    fix = "a massless <inertial> on " + ", ".join(repr(n) for n in links)
    try:
        tree, refused = read(replace(source, text=massless(source.text, links))), ""
    except (EngineError, Unsupported) as exc:
        tree, refused = None, str(exc)
    return tuple(FixedReading(subject=joint, fields=("mass", "com", "inertia"), fix=fix,
                              tree=tree, refused=refused) for joint in bare)
