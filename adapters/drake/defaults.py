"""How Drake's MJCF parser reads an actuator's default class, measured (Drake 1.51): a
``<position>`` of class ``c`` takes its defaults from class ``c``'s own ``<position>``
element, which inherits from ``c``'s parents as MuJoCo's does; where ``c`` has no
``<position>`` element of its own, Drake takes none of its parents' either and holds its own
defaults (kp = 1). MuJoCo inherits through every class. The cause is written only with its
fix verified: the copy with an empty ``<position/>`` given to each such class, parsed by
Drake, holds the kp MuJoCo reads (#77: a cause is a counterfactual, measured)."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import standalone
from dyncheck.adapters.proof import Proof

CLASS_GAINS = (
    "Drake's MJCF parser takes a <position>'s defaults only from a class with a <position> "
    "element of its own (measured): class {cls!r} has none, so none of class {parent!r}'s "
    "(kp = {kp:g}) reach it and Drake holds kp = {held:g} (fix: give class {cls!r} an empty "
    "<position/>; fix verified: with it, Drake reads kp = {fixed:g})"
)


@dataclass(frozen=True, kw_only=True)
class Orphan:
    """A ``<position>`` whose class has no ``<position>`` of its own, and the nearest parent
    class whose ``<position>`` states the kp MuJoCo gives it."""

    actuator: str
    cls: str
    parent: str
    kp: float


def orphans(root: ET.Element) -> list[Orphan]:
    """Every named ``<position>`` of the (inlined) file that states no kp and whose class
    inherits one only through a class without a ``<position>`` element."""
    parents = {child: parent for parent in root.iter("default")
               for child in parent.findall("default")}
    classes = {d.get("class"): d for d in root.iter("default") if d.get("class")}
    out = []
    for element in (e for block in root.findall("actuator") for e in block.findall("position")):
        name, cls = element.get("name"), element.get("class")
        if not name or cls not in classes or element.get("kp") is not None \
                or classes[cls].find("position") is not None:
            continue
        above = parents.get(classes[cls])
        while above is not None:
            stated = above.find("position")
            if stated is not None and stated.get("kp") is not None:
                out.append(Orphan(actuator=name, cls=str(cls),
                                  parent=above.get("class", "main"), kp=float(stated.get(
                                      "kp", "nan"))))
                break
            above = parents.get(above)
    return out


def _fixed_gains(source: ModelFile, root: ET.Element, found: list[Orphan]) -> dict[str, float]:
    """Drake's kp of each actuator on the copy with an empty ``<position/>`` in each class
    :func:`orphans` named (its asset paths absolute, so the copy reads from anywhere)."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    fixed = copy.deepcopy(root)
    wanted = {o.cls for o in found}
    for element in fixed.iter("default"):
        if element.get("class") in wanted and element.find("position") is None:
            element.insert(0, ET.Element("position"))
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(standalone(fixed, source.path.resolve().parent), "xml")
    plant.Finalize()
    out = {}
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        if actuator.has_controller():
            out[actuator.name()] = float(actuator.get_controller_gains().p)
    return out


def class_gain_hints(plant: Any, source: ModelFile,
                     root: ET.Element) -> tuple[tuple[str, str, str], ...]:
    """(actuator, field, why) for each :func:`orphans` actuator of the MJCF ``source``
    (``root``: its includes inlined) whose kp Drake holds otherwise, where the fix, applied to
    a copy and parsed by Drake, gives MuJoCo's kp; none where the copy fails to load or the
    fix does not close the gap (cause unknown)."""
    found = orphans(root)
    held = {plant.get_joint_actuator(i).name(): plant.get_joint_actuator(i)
            for i in plant.GetJointActuatorIndices()}
    found = [o for o in found if o.actuator in held and held[o.actuator].has_controller()
             and float(held[o.actuator].get_controller_gains().p) != o.kp]
    if not found:
        return ()
    try:
        fixed = _fixed_gains(source, root, found)
    except Exception:  # a copy Drake cannot load verifies nothing: no cause written
        return ()
    out = []
    for o in found:
        if fixed.get(o.actuator) != o.kp:
            continue
        why = CLASS_GAINS.format(cls=o.cls, parent=o.parent, kp=o.kp, fixed=o.kp,
                                 held=float(held[o.actuator].get_controller_gains().p))
        out += [(o.actuator, "gain", why), (o.actuator, "bias", why)]
    return tuple(out)


PROOFS = {
    "CLASS_GAINS": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
