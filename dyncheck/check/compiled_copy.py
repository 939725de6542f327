"""A hint whose fix states in the file what the canonical engine compiled, measured (#77):
"give the body an ``<inertial>``" (an engine weighing the body's geoms otherwise than the
canonical engine: Pinocchio and a mesh or a visual geom; a parser ignoring ``settotalmass``)
or "state stiffness= and damping= on the joint" (a parser ignoring ``springdamper``). A copy
of the file states, on each body and joint the hints name, what the canonical engine compiled
(:attr:`~dyncheck.adapters.model_tree.ModelTree.inertials`, ``springs``), the engine
concerned reads the copy, and its reading joins the engine's fixed readings, where
:mod:`.proofs` measures the difference again. Where the copy closes it, the hint named the
cause; where it does not, the cause is unknown and the row says how much is left."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import replace
from typing import Protocol

from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.formats.bodies import keys
from dyncheck.adapters.formats.edits import Edit, both, copied
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.model_tree import FixedReading, Inertial, ModelTree, WantsCompiled
from dyncheck.adapters.registration import Format
from dyncheck.check.alignment import align_by_body


class Refused(Protocol):
    """Why an engine has no model of a copy (:class:`.engines.NotLoaded`)."""

    @property
    def message(self) -> str: ...

Start = Callable[[str, ModelFile], AbstractContextManager["ModelEngine | Refused"]]
"""An engine (by name) loaded on a copy of the model for as long as the context lasts: in a
process of its own where the check isolates engines (:func:`.engines.running`)."""


def read_tree(start: Start, engine: str, copy: ModelFile) -> tuple[ModelTree | None, str]:
    """What ``engine`` holds after reading ``copy`` (its tree is read on loading; the engine
    is closed after), or its words refusing it."""
    with start(engine, copy) as read:
        if isinstance(read, ModelEngine):
            return read.tree, ""
        return None, read.message


WORDS = "an <inertial> on {bodies} stating the mass, centre of mass and inertia {engine} compiles"
DROPPED = ", settotalmass dropped"
BOXED = ", the geoms of {bodies} replaced by one box of that inertia"
SPRING_WORDS = "stiffness= and damping= on {joints} stating what {engine} compiles"
SHOWN = 4
"""How many bodies the fix's words name (then "… (n bodies)")."""


def _named(names: list[str], what: str) -> str:
    """The first :data:`SHOWN` names, then how many in all."""
    return ", ".join(repr(n) for n in names[:SHOWN]) + (
        f" … ({len(names)} {what})" if len(names) > SHOWN else "")


def springs(stated: Mapping[str, tuple[float, float]], *, engine: str) -> Edit:
    """Write on each joint named in ``stated`` its (stiffness, damping) and
    ``springdamper="0 0"`` (which overrides a class's, so that MuJoCo too takes the values
    written: the model it compiles stays the same)."""
    def apply(root: ET.Element) -> None:
        for joint in root.iter("joint"):
            values = stated.get(joint.get("name", ""))
            if values is not None:
                joint.set("springdamper", "0 0")
                joint.set("stiffness", repr(values[0]))
                joint.set("damping", repr(values[1]))
    return Edit(SPRING_WORDS.format(joints=_named(sorted(stated), "joints"), engine=engine),
                apply)


def edit(inertials: Mapping[str, Inertial], *, engine: str, every: bool = False,
         boxed: frozenset[str] = frozenset()) -> Edit:
    """Give each body named in ``inertials`` that ``<inertial>`` (in place of its own), and
    make a compiler's ``inertiafromgeom="true"`` (which ignores every ``<inertial>``, in
    MuJoCo and Pinocchio alike) ``"auto"``; with ``every`` (every body stated, the scaled
    masses), drop the compiler's ``settotalmass``; the bodies of ``boxed`` get one box of
    that inertia in place of their geoms (:func:`_box`). The model MuJoCo compiles stays the
    same: it takes a body's mass properties from a stated ``<inertial>``."""
    shown = _named(sorted(inertials), "bodies")

    def apply(root: ET.Element) -> None:
        for compiler in root.iter("compiler"):
            if compiler.get("inertiafromgeom") == "true":
                compiler.set("inertiafromgeom", "auto")
            if every:
                compiler.attrib.pop("settotalmass", None)
        named = _referenced(root) if boxed else set()
        keyed = keys(root)
        for body in root.iter("body"):
            stated = inertials.get(keyed[id(body)])
            if stated is None:
                continue
            for old in body.findall("inertial"):
                body.remove(old)
            body.insert(0, ET.Element("inertial", {
                "pos": " ".join(repr(x) for x in stated.pos),
                "quat": " ".join(repr(x) for x in stated.quat),
                "mass": repr(stated.mass),
                "diaginertia": " ".join(repr(x) for x in stated.diaginertia)}))
            if keyed[id(body)] in boxed:
                for parent, geom in _own_geoms(body):
                    if geom.get("name") not in named:
                        parent.remove(geom)
                if stated.mass > 0:
                    body.insert(1, _box(stated))
    return Edit(WORDS.format(bodies=shown, engine=engine) + (DROPPED if every else "")
                + (BOXED.format(bodies=_named(sorted(boxed), "bodies")) if boxed else ""),
                apply)


def _box(stated: Inertial) -> ET.Element:
    """A box (MuJoCo ignores its mass and inertia: the ``<inertial>`` beside it decides) whose
    inertia at the stated mass is the stated one: half-sizes a, b, c with I₁ = m (b² + c²) / 3
    and so on, i.e. a² = 3 (I₂ + I₃ − I₁) / (2m); placed at the centre of mass along the principal
    axes, colliding with nothing."""
    i1, i2, i3 = stated.diaginertia
    squares = [3 * (j + k - i) / (2 * stated.mass) for i, j, k in
               ((i1, i2, i3), (i2, i3, i1), (i3, i1, i2))]
    half = [max(x, 1e-12) ** 0.5 for x in squares]  # (a degenerate moment: a thin box)
    return ET.Element("geom", {
        "type": "box", "size": " ".join(repr(h) for h in half),
        "pos": " ".join(repr(x) for x in stated.pos),
        "quat": " ".join(repr(x) for x in stated.quat),
        "contype": "0", "conaffinity": "0"})


def _own_geoms(body: ET.Element) -> list[tuple[ET.Element, ET.Element]]:
    """The geoms of ``body`` itself (its children's and those of its ``<frame>``s, not those
    of the bodies it carries), each with its parent element."""
    out = []
    for child in body:
        if child.tag == "geom":
            out.append((body, child))
        elif child.tag == "frame":
            out += _own_geoms(child)
    return out


def _referenced(root: ET.Element) -> set[str]:
    """Every value an attribute other than a name holds: the geoms whose name may be
    referred to there (a contact pair, a tendon's wrap, a sensor) are kept."""
    return {v for el in root.iter() for k, v in el.attrib.items() if k != "name"}


def measured(source: ModelFile, canonical: ModelTree, loaded: dict[str, ModelEngine], *,
             start: Start) -> None:
    """Each engine of ``loaded`` (but the canonical one) whose hints want what the canonical
    engine compiled stated reads one copy stating it on every body and joint they name; its
    reading joins its fixed readings, one per hint (a refused copy: the engine's words).
    Hints on a body or joint the canonical engine compiled nothing for (an unnamed one) stay
    unmeasured."""
    if source.format is not Format.MJCF or not (canonical.inertials or canonical.springs):
        return
    for engine, m in loaded.items():
        if m.tree is canonical:
            continue
        wants, theirs = wanted(canonical, m.tree)
        if not wants:
            continue
        fix = stating(canonical, wants)
        with copied(source, inline(source.path), (fix,)) as copy:
            read, refused = read_tree(start, engine, copy)
        tree = align_by_body(canonical, read)[0] if read is not None else None
        m.tree = replace(m.tree, hints=(*m.tree.hints, *(h for _, h in theirs)), fixed=(
            *m.tree.fixed, *(
            FixedReading(subject=w.subject, fields=w.fields, fix=fix.words, tree=tree,
                         refused=refused) for w in wants)))


def wanted(canonical: ModelTree, tree: ModelTree) -> tuple[
        list[WantsCompiled], list[tuple[WantsCompiled, tuple[str, str, str]]]]:
    """What ``tree``'s engine wants stated that the canonical engine compiled (its own
    hints', and the canonical engine's hints' it takes as its own: :func:`_canonical_hints`,
    the second list with those hints)."""
    if not (canonical.inertials or canonical.springs):
        return [], []
    own = [w for w in tree.wants_compiled
           if all(b in canonical.inertials for b in w.bodies)
           and all(j in canonical.springs for j in w.joints)]
    theirs = _canonical_hints(canonical, tree)
    return own + [w for w, _ in theirs], theirs


def stating(canonical: ModelTree, wants: list[WantsCompiled]) -> Edit:
    """One edit stating, for every body and joint ``wants`` name, the canonical engine's."""
    bodies = {b: canonical.inertials[b] for w in wants for b in w.bodies}
    joints = {j: canonical.springs[j] for w in wants for j in w.joints}
    boxed = frozenset(b for w in wants if w.box for b in w.bodies)
    edits = ([edit(bodies, engine=canonical.engine, every=any(w.every for w in wants),
                   boxed=boxed)] if bodies else [])
    edits += [springs(joints, engine=canonical.engine)] if joints else []
    return both(*edits)


def _canonical_hints(canonical: ModelTree, tree: ModelTree) -> list[
        tuple[WantsCompiled, tuple[str, str, str]]]:
    """The canonical engine's hints whose fix states every body's inertial (an attribute
    only it applies, ``settotalmass``), each with the hint as ``tree``'s own (the other
    engine reads otherwise; the copy is its counterfactual): where ``tree`` gives no hint of
    its own for the field."""
    out = []
    for want in canonical.wants_compiled:
        why = canonical.hint(want.subject, want.fields[0])
        if why is None or not want.every:
            continue
        for name in want.fields:
            if tree.hint(want.subject, name) is None:
                out.append((replace(want, fields=(name,)), (want.subject, name, why)))
    return out
