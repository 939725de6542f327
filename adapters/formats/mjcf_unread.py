"""What MJCF parsers other than MuJoCo's compiler leave unread, found in the file (read as
XML, includes inlined): the description row that finds the field read differently names the
cause and the fix. Engine-specific readings live with their engine
(:mod:`dyncheck.adapters.pinocchio.mjcf`, :mod:`dyncheck.adapters.drake.model`)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator

import numpy as np

from dyncheck.adapters.formats.mjcf_copy import joints
from dyncheck.adapters.proof import Proof

SPRINGDAMPER = (
    "{engine}'s MJCF parser does not read springdamper=\"{value}\", from which MuJoCo derives "
    "the joint's stiffness and damping with the joint's inertia (measured: springdamper="
    "\"0.001 50\" on a 4.19 kg sphere: MuJoCo's damping 33.5, Pinocchio's 0; Drake's 0 on "
    "warp's tactile.xml) (fix: state stiffness= and damping= on the joint)"
)


def springdampers(root: ET.Element, engine: str) -> Iterator[tuple[str, str, str]]:
    """(joint, "damping", why) for every named joint of the MJCF ``root`` (includes inlined)
    whose ``springdamper`` (own or from a default class) is not zero."""
    for joint in joints(root):
        name = joint.element.get("name")
        value = joint.attrs.get("springdamper")
        if name and value and any(float(x) for x in value.split()):
            yield name, "damping", SPRINGDAMPER.format(engine=engine, value=value)


def stated_gravity(root: ET.Element) -> np.ndarray | None:
    """The gravity the MJCF ``root`` (includes inlined) states in ``<option gravity>``,
    where it is not the 0 0 −9.81 that Pinocchio and PyBullet keep when they do not read
    it (their default, and MuJoCo's)."""
    stated = [o.get("gravity", "") for o in root.iter("option") if o.get("gravity")]
    if not stated:
        return None
    gravity = np.array([float(x) for x in stated[-1].split()])
    return None if np.allclose(gravity, (0.0, 0.0, -9.81)) else gravity


PROOFS = {
    "SPRINGDAMPER": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
