"""An edit of a copy of an MJCF file, in words and as a function of its (inlined) root: the
fix a hint names, applied so that the engine concerned can read the copy and the difference
be measured again (#77; :mod:`dyncheck.check.proofs`)."""

from __future__ import annotations

import contextlib
import copy
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace
from pathlib import Path
from typing import NamedTuple

from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import standalone
from dyncheck.adapters.model_tree import FixedCopy


class Edit(NamedTuple):
    """An in-place edit of an (inlined) MJCF root, and what it does in words."""

    words: str
    apply: Callable[[ET.Element], None]


def both(*edits: Edit) -> Edit:
    """The edits applied in order."""
    def edit(root: ET.Element) -> None:
        for one in edits:
            one.apply(root)
    return Edit(" and ".join(e.words for e in edits), edit)


def applied(root: ET.Element, folder: Path, edits: Sequence[Edit]) -> str:
    """The text of a copy of ``root`` (includes inlined) with ``edits`` applied, its asset
    paths absolute (``folder``: the main file's), so that it reads the same from anywhere."""
    fixed = copy.deepcopy(root)
    for edit in edits:
        edit.apply(fixed)
    return standalone(fixed, folder)


@contextlib.contextmanager
def written(source: ModelFile, text: str) -> Iterator[ModelFile]:
    """The MJCF ``source`` as the copy ``text``, written in a folder of its own for as long
    as the context lasts: what an engine reads to measure a fix."""
    with tempfile.TemporaryDirectory(prefix="dyncheck-fix-") as folder:
        path = Path(folder) / "fixed.xml"
        path.write_text(text, encoding="utf-8")
        yield replace(source, path=path, text=text, notes=())


def copied(source: ModelFile, root: ET.Element,
           edits: Sequence[Edit]) -> contextlib.AbstractContextManager[ModelFile]:
    """The MJCF ``source`` as a copy of ``root`` (its document as the engine should read it)
    with ``edits`` :func:`applied`, :func:`written` for as long as the context lasts."""
    return written(source, applied(root, source.path.resolve().parent, edits))


def fixed_copy(source: ModelFile, root: ET.Element, edits: Sequence[Edit]) -> FixedCopy | None:
    """The copy of the MJCF ``source`` (``root``: its includes inlined) with every one of
    ``edits`` applied together (:attr:`~dyncheck.adapters.model_tree.ModelTree.with_fixes`);
    None where there is none."""
    if not edits:
        return None
    return FixedCopy(fix=both(*edits).words,
                     text=applied(root, source.path.resolve().parent, edits))
