"""Pinocchio's hints proved by their fixes (#77): each fix of :func:`.mjcf.fixes` applied to a
copy of the file, the copy loaded by Pinocchio and read (:class:`FixedReading`), and a refusal's
cause written only where the copy with its fix loads."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.edits import copied
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.model_tree import FixedReading, ModelTree
from dyncheck.adapters.pinocchio import mjcf
from dyncheck.adapters.pinocchio.fixes import ONE_DEFAULTS, Fix
from dyncheck.adapters.pinocchio.mjcf import (
    BARE_BODY,
    CLASS_LOOKUP_FAILED,
    GRAVITY_FIX,
    bare_bodies,
    later_defaults,
    stated_gravity,
)
from dyncheck.errors import EngineError, Unsupported

Read = Callable[[ModelFile, "np.ndarray | None"], ModelTree]
"""Pinocchio's reading of a file, with the gravity given (None: its own)."""

INLINED = " (the copy's <include>s inlined)"


def fixed_readings(source: ModelFile, root: ET.Element, fixes: Sequence[Fix],
                   read: Read) -> tuple[FixedReading, ...]:
    """Pinocchio's reading of the copy of ``root`` (the file, its includes inlined) with each
    of ``fixes`` applied (one copy per fix), and of the file with the gravity it states set
    after loading (the fix its gravity hint names)."""
    out = []
    includes = "<include" in source.text
    for fix in fixes:
        words = fix.edit.words + (INLINED if includes else "")
        with copied(source, root, (fix.edit,)) as copy:
            try:
                tree = read(copy, None)
            except (EngineError, Unsupported) as exc:
                out.append(FixedReading(subject=fix.subject, fields=fix.fields, fix=words,
                                        tree=None, refused=str(exc)))
                continue
        out.append(FixedReading(subject=fix.subject, fields=fix.fields, fix=words, tree=tree))
    gravity = stated_gravity(root)
    if gravity is not None:
        out.append(FixedReading(subject="model", fields=("gravity",), fix=GRAVITY_FIX,
                                tree=read(source, gravity)))
    return tuple(out)


def predictions_met(tree: ModelTree, root: ET.Element) -> frozenset[str]:
    """The range hints whose prediction (:func:`.mjcf.predicted_ranges`; ``root``: the MJCF,
    its includes inlined) Pinocchio's reading meets on every joint it names (to 1e-9 of the
    range): their cause measured."""
    held = {**_by_place(tree, root), **{j.name: j.range for j in tree.joints}}
    return frozenset(why for why, ranges in mjcf.predicted_ranges(root).items()
                     if all(held.get(j) is not None
                            and np.allclose(held[j], r, rtol=1e-9, atol=1e-12)  # type: ignore[arg-type]
                            for j, r in ranges.items()))


def _by_place(tree: ModelTree, root: ET.Element) -> dict[str, tuple[float, float] | None]:
    """Each of the file's joints' range as Pinocchio holds it, found by its body and its
    place among that body's joints: Pinocchio holds a body's several joints as the
    components of one composite joint, named otherwise (measured: dm_control's fish)."""
    held: dict[str, list] = {}
    for joint in tree.joints:
        held.setdefault(joint.body, []).append(joint)
    out = {}
    for body in root.iter("body"):
        names = [x.get("name", "") for x in body if x.tag in ("joint", "freejoint")]
        mine = held.get(body.get("name", ""), [])
        if len(mine) == len(names):
            out.update({name: j.range for name, j in zip(names, mine, strict=True) if name})
    return out


def refusal(source: ModelFile, message: str) -> str:
    """Pinocchio's own words on refusing the MJCF ``source``, with the cause where the file
    shows it and, for the class lookup, its fix verified on a copy (#77)."""
    root = inline(source.path)
    if (count := bare_bodies(root)):
        message += f" ({BARE_BODY.format(count=count)})"
    # a cause is stated only where the engine's own words are its symptom, on the file as
    # Pinocchio reads it (its own text, no <include> followed), and its fix loads
    if CLASS_LOOKUP_FAILED in message and (why := later_defaults(parsing.root(source.text))):
        with copied(source, parsing.root(source.text), (ONE_DEFAULTS,)) as fixed:
            try:
                pin.buildModelFromMJCF(str(fixed.path))
            except Exception:  # the fix does not load: the cause is not proved, not written
                return message
        message += (f" ({why}; fix verified: with {ONE_DEFAULTS.words}, Pinocchio loads "
                    "the model)")
    return message
