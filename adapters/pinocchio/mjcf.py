"""What Pinocchio's MJCF parser (4.1) reads differently from MuJoCo's compiler, found in the
file itself (read as XML, includes inlined) so that a description row that finds a field
read differently names the cause and the fix. Each behaviour was measured on a file written
for it (``tests/check/test_mjcf_models.py``) and matches the parser's source
(``src/parsers/mjcf/mjcf-graph-geom.cpp``: mesh geoms get no computed inertia, visual geoms
none at all; a geom's own attributes overwrite its class's ``mass``).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from typing import NamedTuple

import numpy as np

from dyncheck.adapters.formats.bodies import keys
from dyncheck.adapters.formats.edits import Edit, both
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.mjcf_copy import (
    JOINT_KEYS,
    POSE,
    Placed,
    children,
    geoms,
    joints,
    placed,
)
from dyncheck.adapters.formats.mjcf_unread import springdampers, stated_gravity
from dyncheck.adapters.model_tree import WantsCompiled
from dyncheck.adapters.pinocchio.fixes import (
    CLASS_MASSES,
    NAME_BODIES,
    ONE_TREE,
    Fix,
    joint_pos,
)
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format

Hint = tuple[str, str, str]
"""(joint, field, why): see :attr:`dyncheck.adapters.model_tree.ModelTree.hints`."""


class Found(NamedTuple):
    """A hint and the edit of the file that its fix names (None: no file edit undoes it)."""

    subject: str
    field: str
    why: str
    edit: Edit | None = None
    bodies: tuple[str, ...] = ()
    """The bodies its fix gives an ``<inertial>`` stating what MuJoCo compiles (none: its
    fix is ``edit``, or no edit of the file)."""
    joints: tuple[str, ...] = ()
    """The joints its fix gives the stiffness and damping MuJoCo compiles."""

INCLUDES_SKIPPED = (
    "; the file has <include> elements, which Pinocchio skips: the body it keeps is the first "
    "one written in the file itself, not the first of the model with its includes"
)
FIRST_BODY_ONLY = (
    "Pinocchio's MJCF parser reads only the first body under <worldbody> ({first!r}); the "
    "other top-level bodies ({others}) and their joints are not in its model (fix: put the "
    "robot in one tree under one top-level body, or check its URDF)"
)
BARE_BODY = (
    "Pinocchio's MJCF parser skips a <body> with no attributes at all ({count} in the file): "
    "its joints are not in its model, and the bodies below it hang from its parent (measured: "
    "<body> skipped, <body pos=\"0 0 0\"> read) (fix: name every body)"
)
SLIDE_RANGE = (
    "Pinocchio's MJCF parser converts a slide joint's range from degrees to radians as if it "
    "were an angle (measured: dm_control's cartpole slider (-1.8, 1.8) m read as (-0.0314, "
    "0.0314), × π/180), under <compiler angle=\"degree\">, MJCF's default (fix: none in the "
    "file that keeps it the same model; the dynamics here leave limits out)"
)
ROOT_PLACEMENT = (
    "Pinocchio's MJCF parser puts a jointless top-level body ({body!r}, {where}) at the world "
    "origin, unrotated (measured: quat=\"0 1 0 1\" and pos read as the identity) (fix: wrap "
    "the model in a top-level body of your own without pos or orientation, or rotate "
    "gravity by the same turn)"
)
GRAVITY_FIX = "model.gravity set after loading to the gravity the file states"
GRAVITY_IGNORED = (
    "Pinocchio's MJCF parser does not read <option gravity=\"{gravity}\"> (its model keeps "
    "its default, 0 0 -9.81; measured) (fix: set model.gravity after loading)"
)
MESH_UNIT = (
    "Pinocchio's MJCF parser computes no inertia from a mesh: each mesh geom that can "
    "collide counts 1 kg with unit inertia (1 kg·m²) at the geom's origin, whatever its mass "
    "or density (measured: a 0.2 m cube stated 7 kg, or of density 500, read as 1 kg) "
    "(here: {where}) (fix: give the body an <inertial>)"
)
VISUAL_MASSLESS = (
    "Pinocchio's MJCF parser gives no mass to a geom that collides with nothing (contype=\"0\" "
    "conaffinity=\"0\"), which MuJoCo weighs like any other (measured: two 0.1 m spheres, one "
    "of them visual, 4.19 kg against MuJoCo's 8.38 kg) (here: {where}) (fix: give the body an "
    "<inertial>, or the visual geoms density=\"0\" if they should weigh nothing)"
)
DEFAULT_MASS = (
    "Pinocchio's MJCF parser ignores a geom mass set in a default class (its geom's own "
    "attributes overwrite the class's mass; measured: it computes the geom's mass from its "
    "density, 1000 unless stated) (here: {where}) (fix: write mass= on each geom, or give the "
    "body an <inertial>)"
)
DEFAULT_POS = (
    "Pinocchio's MJCF parser ignores a joint's pos set in a default class (here pos=\"{pos}\" "
    "from {cls}): it places the joint at its body's origin (measured: pos=\"0.012 0 0.01\" "
    "from a class read as 0 0 0; the same pos written on the joint read as written) (fix: "
    "write pos= on the joint)"
)
REF_RANGE = (
    "Pinocchio's MJCF parser subtracts the ref={ref} of joint {joint!r} from its range while "
    "its coordinate keeps ref (its qpos0 holds it): its limits are shifted by −ref (measured: "
    "range=\"-110 110\" ref=\"-90\" read as (-20°, 200°)) (fix: none in the file that keeps "
    "it the same model; the dynamics here leave limits out)"
)
UNLIMITED_RANGE = (
    "Pinocchio's MJCF parser reads a joint's range even where limited=\"false\" tells MuJoCo "
    "to apply none (measured) (fix: drop the range where the joint is unlimited; the dynamics "
    "here leave limits out)"
)


LATER_DEFAULTS = (
    "Pinocchio's MJCF parser reads only the first of the file's {blocks} top-level <default> "
    "blocks (measured: a class of a later block is unknown to it), and {classes} used here "
    "{are} defined in a later one: its class lookup fails (fix: put every class under one "
    "top-level <default>)"
)


CLASS_LOOKUP_FAILED = "unordered_map::at"
"""Pinocchio's MJCF parser's own words when a class it looks up is unknown to it (measured:
``std::unordered_map::at``'s exception): the one refusal :data:`LATER_DEFAULTS` explains."""


def later_defaults(root: ET.Element) -> str | None:
    """Why Pinocchio fails on a file with several top-level ``<default>`` blocks whose later
    blocks define a class the file uses (:data:`LATER_DEFAULTS`); None where that premise does
    not hold on the file."""
    blocks = root.findall("default")
    if len(blocks) < 2:
        return None
    first = {d.get("class") for d in blocks[0].iter("default")}
    later = {d.get("class") for b in blocks[1:] for d in b.iter("default")} - first - {None}
    used = {e.get("class") for e in root.iter() if e.tag != "default"} | {
        e.get("childclass") for e in root.iter()}
    missing = sorted(c for c in later & used if c)
    if not missing:
        return None
    return LATER_DEFAULTS.format(blocks=len(blocks),
                                 classes=", ".join(repr(c) for c in missing),
                                 are="is" if len(missing) == 1 else "are")


def bare_bodies(root: ET.Element) -> int:
    """How many ``<body>`` elements of the MJCF ``root`` carry no attribute (Pinocchio's
    parser skips them)."""
    return sum(1 for body in root.iter("body") if not body.attrib)


def hints(found: Sequence[Found]) -> tuple[Hint, ...]:
    """Why Pinocchio's reading of an MJCF differs, where the file shows the cause
    (``found``: :func:`found`)."""
    return tuple((f.subject, f.field, f.why) for f in found)


def fixes(found: Sequence[Found]) -> tuple[Fix, ...]:
    """The fix of each of the hints ``found`` (:func:`found`) that an edit of the file
    applies, one per hint (its fields gathered)."""
    out: dict[tuple[str, str], tuple[list[str], Edit]] = {}
    for f in found:
        if f.edit is not None:
            out.setdefault((f.subject, f.why), ([], f.edit))[0].append(f.field)
    return tuple(Fix(subject=subject, fields=tuple(fields), edit=edit)
                 for (subject, _), (fields, edit) in out.items())


def wants_compiled(found: Sequence[Found]) -> tuple[WantsCompiled, ...]:
    """The hints ``found`` (:func:`found`) whose fix states what MuJoCo compiled (the
    comparison layer writes the copy), one per hint (its fields gathered)."""
    out: dict[tuple[str, str], tuple[list[str], Found]] = {}
    for f in found:
        if f.bodies or f.joints:
            out.setdefault((f.subject, f.why), ([], f))[0].append(f.field)
    return tuple(WantsCompiled(subject=subject, fields=tuple(fields), bodies=f.bodies,
                               joints=f.joints)
                 for (subject, _), (fields, f) in out.items())


def found(source: ModelFile, root: ET.Element | None,
          held: frozenset[str] = frozenset()) -> tuple[Found, ...]:
    """Each hint of the MJCF ``source`` (``root``: its includes inlined; None for a URDF)
    with the edit its fix names: joints missing (``held``: the bodies Pinocchio's model
    holds, measured — which top-level body it kept is read from it, not assumed); slide
    ranges, gravity; each body's mass, centre of mass and inertia on the joints that carry
    it; joint positions and damping."""
    if source.format is not Format.MJCF or root is None:
        return ()
    includes = re.search(r"<include\b", source.text) is not None  # (the file's own text)
    return (*_model_hints(root, bare_bodies(root), held, includes), *_body_hints(root),
            *_joint_hints(root),
            *(Found(*h, joints=(h[0],)) for h in springdampers(root, "Pinocchio")))


def _model_hints(root: ET.Element, bare: int, held: frozenset[str],
                 includes: bool) -> Iterable[Found]:
    bodies = [b.get("name", "(unnamed)") for world in root.findall("worldbody")
              for b in world.findall("body")]
    missing = [(BARE_BODY.format(count=bare), NAME_BODIES)] if bare else []
    kept = [b for b in bodies if b in held] if held else bodies[:1]
    dropped = [b for b in bodies if b not in kept]
    if len(bodies) > 1 and len(kept) == 1 and dropped:
        others = ", ".join(repr(b) for b in dropped[:5]) + (" …" if len(dropped) > 5 else "")
        missing.append((FIRST_BODY_ONLY.format(first=kept[0], others=others)
                        + (INCLUDES_SKIPPED if includes and kept[0] != bodies[0] else ""),
                        ONE_TREE))
    if missing:
        yield Found("model", "joint", "; ".join(why for why, _ in missing),
                    both(*(edit for _, edit in missing)))
    angle = [c.get("angle") for c in root.iter("compiler") if c.get("angle")]
    if (angle[-1] if angle else "degree") == "degree" and any(
            j.get("type") == "slide" for j in root.iter("joint")):
        yield Found("model", "slide range", SLIDE_RANGE)
    tops = [b for world in root.findall("worldbody") for b in children(world, "body")]
    placed = [k for k in POSE if tops and k in tops[0].attrib]
    if placed and not (children(tops[0], "joint") or children(tops[0], "freejoint")):
        where = ", ".join(f'{k}="{tops[0].get(k)}"' for k in placed)
        yield Found("model", "placement", ROOT_PLACEMENT.format(
            body=tops[0].get("name", "(unnamed)"), where=where), ONE_TREE)
    gravity = stated_gravity(root)
    if gravity is not None:
        yield Found("model", "gravity", GRAVITY_IGNORED.format(
            gravity=" ".join(f"{g:g}" for g in gravity)))


def _weighs(geom: Placed) -> bool:
    """Whether MuJoCo's compiler gives the geom mass (mass or density nonzero)."""
    if "mass" in geom.attrs:
        return float(geom.attrs["mass"]) != 0.0
    return float(geom.attrs.get("density", "1000")) != 0.0


def _visual(geom: Placed) -> bool:
    return geom.attrs.get("contype", "1") == "0" and geom.attrs.get("conaffinity", "1") == "0"


def _body_hints(root: ET.Element) -> Iterable[Found]:
    """Mass, centre of mass and inertia: per body without ``<inertial>``, on the joints that
    carry its mass (its own, else those of the nearest moving ancestor it is welded to)."""
    counts: dict[int, dict[str, int]] = {}  # body → reason → how many of its geoms
    keyed = keys(root)  # (an unnamed body by its place: MuJoCo's body id)
    for geom in geoms(root):
        if geom.body.tag != "body" or geom.body.find("inertial") is not None:
            continue
        mesh = geom.attrs.get("type") == "mesh"
        for reason, applies in (
            (MESH_UNIT, mesh and not _visual(geom)),
            (VISUAL_MASSLESS, _visual(geom) and _weighs(geom)),
            (DEFAULT_MASS, "mass" in geom.attrs and "mass" not in geom.stated
             and not mesh and not _visual(geom)),
        ):
            if applies:
                mine = counts.setdefault(id(geom.body), {})
                mine[reason] = mine.get(reason, 0) + 1
    if not counts:
        return
    for group, names in _carriers(root):
        why, reasons = [], []
        for reason in (MESH_UNIT, VISUAL_MASSLESS, DEFAULT_MASS):
            where = [f"{keyed[id(b)]!r} {n} geom{'s' * (n > 1)}"
                     for b in group if (n := counts.get(id(b), {}).get(reason, 0))]
            if where:
                why.append(reason.format(where="body " + ", ".join(where)))
                reasons.append(reason)
        if why:  # (a mesh's or a visual geom's inertia: the canonical engine's, stated)
            edit = CLASS_MASSES if reasons == [DEFAULT_MASS] else None
            weighed = [keyed[id(b)] for b in group if counts.get(id(b))]
            bodies = tuple(weighed) if edit is None else ()
            for name in names or ("model",):
                for field in ("mass", "com", "inertia"):
                    yield Found(name, field, "; ".join(why), edit, bodies)


def _carriers(root: ET.Element) -> Iterable[tuple[list[ET.Element], tuple[str, ...]]]:
    """Each moving body with the bodies welded to it, and the names of its joints (a body
    with an unnamed joint: none, so its hints apply model-wide)."""
    out: list[tuple[list[ET.Element], tuple[str, ...]]] = []

    def own_joints(body: ET.Element) -> list[ET.Element]:
        return [*children(body, "joint"), *children(body, "freejoint")]

    def walk(body: ET.Element, group: list[ET.Element]) -> None:
        for child in children(body, "body"):
            if own_joints(child):
                start(child)
            else:
                group.append(child)
                walk(child, group)

    def start(body: ET.Element) -> None:
        group = [body]
        walk(body, group)
        names = [j.get("name") for j in own_joints(body)]
        if names:  # a body welded to the world carries no mass that moves
            out.append((group, tuple(n for n in names if n) if all(names) else ()))

    for world in root.findall("worldbody"):
        for body in children(world, "body"):
            start(body)
    return out


def predicted_ranges(root: ET.Element) -> dict[str, dict[str, tuple[float, float]]]:
    """The range hints' predictions (each hint's text → joint → the range Pinocchio holds if
    the cause is what the hint says), from the file: a slide's range × π/180 under degrees
    (:data:`SLIDE_RANGE`), a hinge's range less its ref (:data:`REF_RANGE`), the range of a
    joint that states ``limited="false"`` (:data:`UNLIMITED_RANGE`), angles in radians
    (``root``: the MJCF, its includes inlined)."""
    angle = [c.get("angle") for c in root.iter("compiler") if c.get("angle")]
    degrees = (angle[-1] if angle else "degree") == "degree"
    unit = np.pi / 180 if degrees else 1.0
    out: dict[str, dict[str, tuple[float, float]]] = {}
    for joint in placed(root, "joint", (*JOINT_KEYS, "type")):
        name, stated = joint.element.get("name"), joint.attrs.get("range")
        if not name or not stated:
            continue
        low, high = (float(x) for x in stated.split())
        kind = joint.attrs.get("type", "hinge")
        if kind == "slide" and degrees:
            out.setdefault(SLIDE_RANGE, {})[name] = (low * unit, high * unit)
        if kind != "hinge":
            continue
        ref = float(joint.attrs.get("ref", "0")) * unit
        if joint.attrs.get("limited") == "false":
            out.setdefault(UNLIMITED_RANGE, {})[name] = (low * unit, high * unit)
        elif ref:
            out.setdefault(REF_RANGE.format(ref=joint.attrs["ref"], joint=name), {})[name] = (
                low * unit - ref, high * unit - ref)
    return out


def _joint_hints(root: ET.Element) -> Iterable[Found]:
    """A joint's position from a default class; its range where it has a ``ref`` or is not
    limited."""
    for joint in joints(root):
        name = joint.element.get("name")
        if not name:  # matched by place under another name: no hint rather than a wrong one
            continue
        pos = joint.attrs.get("pos")
        if pos and "pos" not in joint.stated and any(float(x) for x in pos.split()):
            cls = joint.element.get("class")
            yield Found(name, "anchor", DEFAULT_POS.format(
                pos=pos, cls=f"class {cls!r}" if cls else "a default class"),
                joint_pos(name, pos))
        if "range" in joint.attrs:
            if joint.attrs.get("limited") == "false":
                yield Found(name, "range", UNLIMITED_RANGE)
            elif float(joint.attrs.get("ref", "0")) != 0.0:
                yield Found(name, "range", REF_RANGE.format(ref=joint.attrs["ref"], joint=name))


PROOFS = {
    "FIRST_BODY_ONLY": Proof.FIX,
    "BARE_BODY": Proof.FIX,
    "SLIDE_RANGE": Proof.PREDICTED,
    "ROOT_PLACEMENT": Proof.FIX,
    "GRAVITY_IGNORED": Proof.FIX,
    "MESH_UNIT": Proof.FIX,
    "VISUAL_MASSLESS": Proof.FIX,
    "DEFAULT_MASS": Proof.FIX,
    "DEFAULT_POS": Proof.FIX,
    "REF_RANGE": Proof.PREDICTED,
    "UNLIMITED_RANGE": Proof.PREDICTED,
    "LATER_DEFAULTS": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
