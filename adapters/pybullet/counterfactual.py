"""PyBullet's hints proved by their fix (#77), read by PyBullet
(:class:`~dyncheck.adapters.model_tree.FixedReading`): a URDF link without ``<inertial>``
(the copy with a massless one on each such link, what MuJoCo and Pinocchio give it) and
the MJCF's gravity it ignores (``setGravity`` with the stated one)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Protocol

import numpy as np

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.formats.mjcf_unread import stated_gravity
from dyncheck.adapters.model_tree import FixedReading, ModelTree
from dyncheck.adapters.pybullet.files import GRAVITY_FIX
from dyncheck.adapters.registration import Format
from dyncheck.errors import EngineError, Unsupported


class Read(Protocol):
    """PyBullet's reading of a file (its client closed after; its own fixes not measured),
    under its gravity or ``gravity``."""

    def __call__(self, copy: ModelFile, *, gravity: np.ndarray | None = None) -> ModelTree: ...

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


def gravity_fixed(source: ModelFile, gravity: np.ndarray, read: Read) -> tuple[FixedReading, ...]:
    """The fix :data:`~.files.GRAVITY_HINT` names, measured: the MJCF read again with
    ``setGravity`` given the gravity the file states (where it states one other than
    ``gravity``, PyBullet's)."""
    stated = stated_gravity(inline(source.path)) if source.format is Format.MJCF else None
    if stated is None or np.allclose(stated, gravity):
        return ()
    return (FixedReading(subject="model", fields=("gravity",), fix=GRAVITY_FIX.format(
        gravity=" ".join(f"{g:g}" for g in stated)), tree=read(source, gravity=stated)),)
