"""Coverage through the fix (#77): an engine that reads the file only in part or otherwise,
for causes whose fixes edit the file (:attr:`~dyncheck.adapters.model_tree.ModelTree.
with_fixes`, and the values the canonical engine compiled that its hints want stated,
:mod:`.compiled_copy`), is run again on the copy with every such fix applied. Does it then
read the model as the canonical engine does, and does it compute what it read — its dynamics
against the referee on the canonical reading? The rows (section "with the fix") answer the
computing question for the whole model where the file alone cannot; the engine's first line
says both (:mod:`.verdicts`)."""

from __future__ import annotations

from dataclasses import replace

from dyncheck.adapters import layout
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.edits import applied, written
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.model_tree import Canonical, Dynamics, ModelTree
from dyncheck.adapters.registration import Format
from dyncheck.check import compiled_copy, describe, predicted
from dyncheck.check.alignment import align_by_body
from dyncheck.check.dynamics import compare
from dyncheck.check.rows import COMPUTED, WITH_FIX, WITH_FIX_READING, CheckRow, Section
from dyncheck.referee.states import States
from dyncheck.referee.tree import standing_of
from dyncheck.vocabulary import REFEREE, Verdict


def _copy(source: ModelFile, canonical: ModelTree, tree: ModelTree) -> tuple[str, str] | None:
    """The text of the copy with every fix ``tree``'s engine names that edits the file, and
    the fixes in words (None where it names none): its own edits (:attr:`ModelTree.
    with_fixes`), then what the canonical engine compiled that its hints want stated."""
    wants, _ = compiled_copy.wanted(canonical, tree)
    if tree.with_fixes is None and not wants:
        return None
    base = tree.with_fixes
    root = parsing.root(base.text) if base is not None else inline(source.path)
    edits = [compiled_copy.stating(canonical, wants)] if wants else []
    text = applied(root, source.path.resolve().parent, edits)
    words = [*([base.fix] if base is not None else []), *(e.words for e in edits)]
    return text, "; ".join(words)


def _row(model: str, engine: str, verdict: Verdict, note: str, *, fix: str,
         value: str) -> CheckRow:
    """How ``engine`` reads the copy: its value ``value`` (read alike, read otherwise,
    refused, failed), the fixes in words as the other value, ``note`` why."""
    return CheckRow(model=model, section=Section.WITH_FIX, subject="model",
                    field=WITH_FIX_READING, impl_a="", impl_b=engine, value_a=fix,
                    value_b=value, error=float("nan"),
                    tolerance=float("nan"), basis="", verdict=verdict, note=note)


def rows(model: str, source: ModelFile, *, canon: Canonical, canonical_tree: ModelTree,
         batch: States, referee: Dynamics | None, loaded: dict[str, ModelEngine],
         targets: list[str], start: compiled_copy.Start) -> list[CheckRow]:
    """For each engine of ``targets`` (those reading the file in part or otherwise) that
    names a fix editing the file: a row saying how it reads the copy with every such fix
    (alike in every field the dynamics use, or the first such field still read otherwise,
    or its refusal), and where alike, its dynamics on the copy against the ``referee`` on
    the canonical reading."""
    out: list[CheckRow] = []
    if source.format is not Format.MJCF:
        return out
    for engine in targets:
        made = _copy(source, canonical_tree, loaded[engine].tree)
        if made is None:
            continue
        text, words = made
        fix = WITH_FIX.format(fix=words)
        with written(source, text) as copy, start(engine, copy) as fixed:
            if not isinstance(fixed, ModelEngine):
                out.append(_row(model, engine, Verdict.FAILED, f"{fix}: {fixed.message}",
                                fix=words, value="refused"))
                continue
            tree = align_by_body(canonical_tree, fixed.tree)[0]
            still = [r for r in describe.diff(model, canonical_tree, tree)  # (what enters
                     if r.verdict is Verdict.FAILED and r.field in describe.ENTERS]  # M, h)
            if still or [j.name for j in tree.joints] != list(canon.names):
                first = still[0] if still else None
                out.append(_row(model, engine, Verdict.FAILED, (
                    f"{fix}, {engine} still reads the {first.field} of {first.subject!r} "
                    f"otherwise ({first.error:.3g} of its scale): cause unknown (the copy "
                    "has the fixes its causes name applied)" if first else
                    f"{fix}, {engine} holds other joints than {canonical_tree.engine}"),
                    fix=words, value="read otherwise"))
                continue
            out.append(_row(model, engine, Verdict.PASSED, f"{fix}, {engine} reads the model "
                            f"as {canonical_tree.engine} does", fix=words, value="read alike"))
            if referee is not None:
                out += _computed(model, engine, fix, canon=canon, canonical_tree=canonical_tree,
                                 tree=tree, fixed=fixed, batch=batch, referee=referee)
    return out


def _computed(model: str, engine: str, fix: str, *, canon: Canonical,
              canonical_tree: ModelTree, tree: ModelTree, fixed: ModelEngine, batch: States,
              referee: Dynamics) -> list[CheckRow]:
    """The engine's dynamics on the copy against the referee on the canonical reading (it
    reads the copy alike), with the differences its computing conventions predict."""
    maps, q_e, v_e, a_e = layout.engine_states(canon, tree, batch.q, batch.v, batch.a)
    try:
        dyn = layout.to_canonical(maps, fixed.dynamics(q_e, v_e, a_e))
    except Exception as exc:  # its failure on the copy costs this row only
        return [replace(_row(model, engine, Verdict.FAILED, f"{fix}: {type(exc).__name__}: "
                             f"{exc}", fix=fix, value="computing failed"), subject="dynamics",
                        field=COMPUTED)]
    vertices = 0.0 if tree.mesh_rounding else 2 * max(canonical_tree.mesh_rounding.values(),
                                                      default=0.0)
    found = compare(model, canonical_tree, name_a=REFEREE, dyn_a=referee, name_b=engine,
                    dyn_b=dyn, explanations=predicted.differences(
                        canon, canonical_tree, canonical_tree, tree, batch, referee),
                    readings={}, states=batch, eps=max(canonical_tree.eps, tree.eps),
                    vertices=vertices, standing=standing_of(canonical_tree, batch.q))
    return [replace(r, section=Section.WITH_FIX, note=f"{fix}: {r.note}" if r.note else fix)
            for r in found]
