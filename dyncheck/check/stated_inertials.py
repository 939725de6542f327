"""A hint whose fix is "give the body an ``<inertial>``" (an engine weighing the body's geoms
otherwise than the canonical engine: Pinocchio and a mesh or a visual geom), measured (#77):
a copy of the file states, on each body the hint names, the mass properties the canonical
engine compiled (:attr:`~dyncheck.adapters.model_tree.ModelTree.inertials`), the engine
concerned reads the copy, and its reading joins the engine's fixed readings, where
:mod:`.proofs` measures the difference again. Where the copy closes it, the geoms were the
cause; where it does not, the cause is unknown and the row says how much is left."""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path

from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.formats.edits import Edit, copied
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.model_tree import FixedReading, Inertial, ModelTree, WantsInertials
from dyncheck.adapters.registration import Format
from dyncheck.check.alignment import align_by_body
from dyncheck.check.engines import NotLoaded

Load = Callable[[str, ModelFile], "ModelEngine | NotLoaded"]
"""An engine (by name) loading a copy of the model: in a process of its own where the check
isolates engines."""

WORDS = "an <inertial> on {bodies} stating the mass, centre of mass and inertia {engine} compiles"
DROPPED = ", settotalmass dropped"
SHOWN = 4
"""How many bodies the fix's words name (then "… (n bodies)")."""


def edit(inertials: Mapping[str, Inertial], *, engine: str, every: bool = False) -> Edit:
    """Give each body named in ``inertials`` that ``<inertial>`` (in place of its own), and
    make a compiler's ``inertiafromgeom="true"`` (which ignores every ``<inertial>``, in
    MuJoCo and Pinocchio alike) ``"auto"``; with ``every`` (every body stated, the scaled
    masses), drop the compiler's ``settotalmass``: the model MuJoCo compiles stays the same."""
    names = sorted(inertials)
    shown = ", ".join(repr(n) for n in names[:SHOWN]) + (
        f" … ({len(names)} bodies)" if len(names) > SHOWN else "")

    def apply(root: ET.Element) -> None:
        for compiler in root.iter("compiler"):
            if compiler.get("inertiafromgeom") == "true":
                compiler.set("inertiafromgeom", "auto")
            if every:
                compiler.attrib.pop("settotalmass", None)
        for body in root.iter("body"):
            stated = inertials.get(body.get("name", ""))
            if stated is None:
                continue
            for old in body.findall("inertial"):
                body.remove(old)
            body.insert(0, ET.Element("inertial", {
                "pos": " ".join(repr(x) for x in stated.pos),
                "quat": " ".join(repr(x) for x in stated.quat),
                "mass": repr(stated.mass),
                "diaginertia": " ".join(repr(x) for x in stated.diaginertia)}))
    return Edit(WORDS.format(bodies=shown, engine=engine)
                + (DROPPED if every else ""), apply)


def measured(source: ModelFile, canonical: ModelTree, loaded: dict[str, ModelEngine], *,
             load: Load) -> None:
    """Each engine of ``loaded`` (but the canonical one) whose hints want bodies' inertials
    stated reads one copy with every such body given the canonical engine's; its reading
    joins its fixed readings, one per hint (a refused copy: the engine's words). Hints on a
    body the canonical engine compiled no inertial for (an unnamed one) stay unmeasured."""
    if source.format is not Format.MJCF or not canonical.inertials:
        return
    for engine, m in loaded.items():
        if m.tree is canonical:
            continue
        own = [w for w in m.tree.wants_inertials
               if all(b in canonical.inertials for b in w.bodies)]
        theirs = _canonical_hints(canonical, m.tree)
        wants = own + [w for w, _ in theirs]
        if not wants:
            continue
        fix = edit({b: canonical.inertials[b] for w in wants for b in w.bodies},
                   engine=canonical.engine, every=any(w.every for w in wants))
        with tempfile.TemporaryDirectory(prefix="dyncheck-inertials-") as folder:
            copy = copied(source, inline(source.path), (fix,), Path(folder))
            read = load(engine, copy)
        tree = None if isinstance(read, NotLoaded) else align_by_body(canonical, read.tree)[0]
        refused = read.message if isinstance(read, NotLoaded) else ""
        m.tree = replace(m.tree, hints=(*m.tree.hints, *(h for _, h in theirs)), fixed=(
            *m.tree.fixed, *(
            FixedReading(subject=w.subject, fields=w.fields, fix=fix.words, tree=tree,
                         refused=refused) for w in wants)))


def _canonical_hints(canonical: ModelTree, tree: ModelTree) -> list[
        tuple[WantsInertials, tuple[str, str, str]]]:
    """The canonical engine's hints whose fix states every body's inertial (an attribute
    only it applies, ``settotalmass``), each with the hint as ``tree``'s own (the other
    engine reads otherwise; the copy is its counterfactual): where ``tree`` gives no hint of
    its own for the field."""
    out = []
    for want in canonical.wants_inertials:
        why = canonical.hint(want.subject, want.fields[0])
        if why is None or not want.every:
            continue
        for name in want.fields:
            if tree.hint(want.subject, name) is None:
                out.append((replace(want, fields=(name,)), (want.subject, name, why)))
    return out
