"""Pinocchio's hints proved by their fixes (#77): each fix of :func:`.mjcf.fixes` applied to a
copy of the file, the copy loaded by Pinocchio and read (:class:`FixedReading`), and a refusal's
cause written only where the copy with its fix loads."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.edits import Edit, applied
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.model_tree import FixedReading, ModelTree
from dyncheck.adapters.pinocchio.fixes import ONE_DEFAULTS
from dyncheck.adapters.pinocchio.mjcf import (
    BARE_BODY,
    CLASS_LOOKUP_FAILED,
    GRAVITY_FIX,
    bare_bodies,
    fixes,
    later_defaults,
    stated_gravity,
)
from dyncheck.errors import EngineError, Unsupported

Read = Callable[[ModelFile, "np.ndarray | None"], ModelTree]
"""Pinocchio's reading of a file, with the gravity given (None: its own)."""

INLINED = " (the copy's <include>s inlined)"


def _copy(source: ModelFile, root_edits: tuple[Edit, ...], folder: Path, *,
          own_text: bool = False) -> ModelFile:
    """The copy of ``source`` with ``root_edits`` applied, written in ``folder``: inlined
    (or, ``own_text``, the file's own text as Pinocchio reads it, no include followed)."""
    root = parsing.root(source.text) if own_text else inline(source.path)
    text = applied(root, source.path.resolve().parent, root_edits)
    path = folder / "fixed.xml"
    path.write_text(text, encoding="utf-8")
    return replace(source, path=path, text=text, notes=())


def fixed_readings(source: ModelFile, held: frozenset[str],
                   read: Read) -> tuple[FixedReading, ...]:
    """Pinocchio's reading of the copy with each hint's fix applied (one copy per fix), and
    of the file with the gravity it states set after loading (the fix its gravity hint
    names)."""
    out = []
    includes = "<include" in source.text
    with tempfile.TemporaryDirectory(prefix="dyncheck-pinocchio-fix-") as folder:
        for fix in fixes(source, held):
            words = fix.edit.words + (INLINED if includes else "")
            try:
                tree = read(_copy(source, (fix.edit,), Path(folder)), None)
            except (EngineError, Unsupported) as exc:
                out.append(FixedReading(subject=fix.subject, fields=fix.fields, fix=words,
                                        tree=None, refused=str(exc)))
                continue
            out.append(FixedReading(subject=fix.subject, fields=fix.fields, fix=words,
                                    tree=tree))
    gravity = stated_gravity(inline(source.path)) if "gravity" in source.text else None
    if gravity is not None:
        out.append(FixedReading(subject="model", fields=("gravity",), fix=GRAVITY_FIX,
                                tree=read(source, gravity)))
    return tuple(out)


def refusal(source: ModelFile, message: str) -> str:
    """Pinocchio's own words on refusing the MJCF ``source``, with the cause where the file
    shows it and, for the class lookup, its fix verified on a copy (#77)."""
    root = inline(source.path)
    if (count := bare_bodies(root)):
        message += f" ({BARE_BODY.format(count=count)})"
    # a cause is stated only where the engine's own words are its symptom, on the file as
    # Pinocchio reads it (its own text, no <include> followed), and its fix loads
    if CLASS_LOOKUP_FAILED in message and (why := later_defaults(parsing.root(source.text))):
        with tempfile.TemporaryDirectory(prefix="dyncheck-pinocchio-fix-") as folder:
            fixed = _copy(source, (ONE_DEFAULTS,), Path(folder), own_text=True)
            try:
                pin.buildModelFromMJCF(str(fixed.path))
            except Exception:  # the fix does not load: the cause is not proved, not written
                return message
        message += (f" ({why}; fix verified: with {ONE_DEFAULTS.words}, Pinocchio loads "
                    "the model)")
    return message
