"""What Drake's MJCF parser is known to do with a file, checked on the file before it is
said (:attr:`~dyncheck.adapters.model_tree.ModelTree.hints`): armature kept only on joints
an actuator it reads drives, joints of one body placed as if the body had no pose, classes
skipped across a gap, frames ignored — each measured on the installed Drake (the texts say
how), each with its fix."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from typing import NamedTuple

from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.formats.mjcf_copy import joints
from dyncheck.adapters.formats.mjcf_unread import springdampers
from dyncheck.adapters.model_tree import JointType, TreeJoint
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format

UNACTUATED_ARMATURE = (
    "Drake's MJCF parser keeps armature only as the reflected inertia of an actuator on the "
    "joint, and {joint!r} has none: Drake's M leaves its armature out (fix: give the joint an "
    "actuator, e.g. <motor joint=\"{joint}\"/>, or model the rotor as body inertia)"
)
UNREAD_ACTUATOR = (
    "Drake's MJCF parser keeps armature only as the reflected inertia of an actuator it "
    "reads, and {joint!r} is driven by {actuators} only, which Drake did not turn into a "
    "joint actuator (its plant holds none on the joint; Drake 1.51 ignores <general> with a "
    "warning): Drake's M leaves its armature out (fix: write the actuator as <motor> or "
    "<position>)"
)
BALL_ARMATURE = (
    "Drake's MJCF parser keeps armature only as the reflected inertia of an actuator, and "
    "only a one-degree-of-freedom joint carries one{measured}: Drake's M leaves out the "
    "armature of the {kind} joint of body {body!r} (no fix in the file keeps the same model: "
    "a rotor written as body inertia also loads the joints above it)"
)
REFUSED_ACTUATOR = " (measured: its AddJointActuator on a ball joint says \"{words}\")"


FIRST_OF_SEVERAL = (
    "{joint!r} is joint {k} of {n} in body {body!r}: Drake's MJCF parser places the frame of "
    "every joint of a body but its last as if the body had no pos or orientation (measured: "
    "joints 1 and 2 of 3 in a body at (0.3, 0, 1) turned 30° about z, anchor and axis taken in "
    "the parent's frame; joint 3 read as MuJoCo reads it), so Drake's M and h differ wherever "
    "the body is offset or rotated (fix: one joint per body, with massless bodies of your own "
    "between them)"
)


def actuators(source: ModelFile) -> dict[str, list[str]]:
    """Per joint, the file's actuators on it, as ``<tag> 'name'`` (a joint transmission:
    ``joint=``), read from the file with its includes."""
    out: dict[str, list[str]] = {}
    try:
        root = inline(source.path)
    except Exception:  # (the file loaded in Drake already: nothing more to say then)
        return out
    for block in root.iter("actuator"):
        for act in block:
            joint = act.get("joint")
            if joint:
                out.setdefault(joint, []).append(f"<{act.tag}> {act.get('name', '(unnamed)')!r}")
    return out


def armature_hint(joint: TreeJoint, actuators: list[str], refusal: str = "") -> str:
    """Why Drake holds no armature on ``joint``, from what the file says drives it (checked
    on the file, not assumed): no actuator, actuators Drake did not read, or a ball or free
    joint (``refusal``: Drake's own words refusing an actuator on one, where measured)."""
    if joint.type in (JointType.BALL, JointType.FREE):
        return BALL_ARMATURE.format(body=joint.body, kind=joint.type, measured=(
            REFUSED_ACTUATOR.format(words=refusal) if refusal else ""))
    if actuators:
        return UNREAD_ACTUATOR.format(joint=joint.name, actuators=", ".join(actuators))
    return UNACTUATED_ARMATURE.format(joint=joint.name)


def several_joints(root: ET.Element) -> list[ET.Element]:
    """The bodies of the MJCF ``root`` (includes inlined) with several ``<joint>`` elements,
    in document order: those :data:`FIRST_OF_SEVERAL` is about."""
    return [body for body in root.iter("body") if len(body.findall("joint")) > 1]


def _first_of_several(root: ET.Element) -> tuple[tuple[str, str, str], ...]:
    """Why every joint but the last of a body with several reads differently in Drake (the
    MJCF ``root``, includes inlined)."""
    out: list[tuple[str, str, str]] = []
    for body in several_joints(root):
        named = [j.get("name") for j in body.findall("joint")]
        for k, name in enumerate(named[:-1], start=1):
            if name:
                why = FIRST_OF_SEVERAL.format(joint=name, k=k, n=len(named),
                                              body=body.get("name", "(unnamed)"))
                out += [(name, field, why) for field in ("anchor", "axis")]
    return tuple(out)


SKIPPED_CLASS = (
    "{joint!r} takes its {fields} from default class {source!r} through class {gap!r}, "
    "which sets no <joint> attribute: Drake's MJCF parser passes a class's joint defaults on "
    "only through classes that have a <joint> element (measured: armature 0.01 and damping 3 "
    "read as 0, axis 1 0 0 as 0 0 1, pos 0.1 0 0 as 0 0 0, range ±10 as none), "
    "so Drake reads the element's own default instead (fix: write the attribute on class "
    "{gap!r}'s <joint>, or on the joint)"
)


LOST_ACROSS_A_GAP = {"armature": "armature", "damping": "damping", "axis": "axis",
                     "pos": "anchor", "range": "range"}
"""The joint attributes Drake loses across a class without <joint>, and the description
field each shows in."""


class Lost(NamedTuple):
    """A joint attribute Drake loses across a class gap: the joint, the attribute and the
    value the class gives it, the description field it shows in, and why."""

    joint: str
    attribute: str
    value: str
    field: str
    why: str


def _skipped_classes(root: ET.Element) -> tuple[tuple[str, str, str], ...]:
    """:func:`lost_across_gaps` as hints."""
    return tuple((lost.joint, lost.field, lost.why) for lost in lost_across_gaps(root))


def lost_across_gaps(root: ET.Element) -> list[Lost]:
    """Joint attributes Drake loses on their way down the default classes: a joint whose
    class (``class``, else the nearest ``childclass``) inherits an attribute from an
    ancestor class across a class without a ``<joint>`` element (the MJCF ``root``,
    includes inlined)."""
    chains: dict[str, list[ET.Element]] = {}  # class -> its default elements, top first

    def walk(element: ET.Element, above: list[ET.Element]) -> None:
        for child in element.findall("default"):
            chain = [*above, child]
            chains[child.get("class", "main")] = chain
            walk(child, chain)

    walk(root, [])
    out: list[Lost] = []
    for placed in joints(root):
        joint, chain = placed.element, chains.get(placed.cls, [])
        if not joint.get("name") or len(chain) < 2:
            continue
        gaps = [d for d in chain[1:] if d.find("joint") is None]
        for k, default in enumerate(chain[:-1]):
            own = default.find("joint")
            later = [d for d in chain[k + 1:] if d in gaps]
            if own is None or not later:
                continue
            below = [d.find("joint") for d in chain[k + 1:]]
            fields = [f for f in LOST_ACROSS_A_GAP if f in own.attrib
                      and f not in joint.attrib
                      and not any(e is not None and f in e.attrib for e in below)]
            for field in fields:
                out.append(Lost(joint=joint.get("name", ""), attribute=field,
                                value=own.attrib[field], field=LOST_ACROSS_A_GAP[field],
                                why=SKIPPED_CLASS.format(
                                    joint=joint.get("name"), fields=field,
                                    source=default.get("class", "main"),
                                    gap=later[0].get("class"))))
    return out


def file_hints(source: ModelFile) -> tuple[tuple[str, str, str], ...]:
    """What the MJCF itself shows Drake reads differently (read once, includes inlined)."""
    if source.format is not Format.MJCF:
        return ()
    root = inline(source.path)
    return (*_skipped_classes(root), *_first_of_several(root),
            *springdampers(root, "Drake"))


IGNORED_FRAME = (
    "Drake's MJCF parser ignores <frame> (its own warning: 'currently unsupported and will be "
    "ignored'): the bodies and joints inside a frame are not in its model (fix: move each "
    "frame's pos and orientation onto what it holds and remove the frame)"
)


def ignored_frames(notes: Sequence[str]) -> tuple[tuple[str, str, str], ...]:
    """A model-wide hint for a joint Drake lacks, where its parser said it ignored a
    <frame>: the missing joint's row then names the cause and the fix."""
    said = any("'frame'" in n and "ignored" in n for n in notes)
    return (("model", "joint", IGNORED_FRAME),) if said else ()


PROOFS = {
    "UNACTUATED_ARMATURE": Proof.FIX,
    "UNREAD_ACTUATOR": Proof.FIX,
    "BALL_ARMATURE": Proof.MEASURED,
    "FIRST_OF_SEVERAL": Proof.FIX,
    "SKIPPED_CLASS": Proof.FIX,
    "IGNORED_FRAME": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
