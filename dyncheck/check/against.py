"""``check --against OTHER``: the model's reading against another file (its previous version),
both read by the same engine. The other file is untrusted input like the model: checked up
front as the model is (:func:`~dyncheck.check.inputs.model_path`, its assets regular files,
its links massive), and compiled in an engine process of its own under the same limits, so
that a file that crashes or hangs the engine costs its one row, never dyncheck's process."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from dyncheck.adapters import REGISTRY
from dyncheck.adapters.formats.files import ModelFile, read
from dyncheck.adapters.model_tree import ModelTree
from dyncheck.check import describe, inputs
from dyncheck.check import engines as engine_processes
from dyncheck.check.engines import NotLoaded
from dyncheck.check.rows import CheckRow, Section
from dyncheck.escaping import shown
from dyncheck.vocabulary import Verdict

FLAG = "--against"


@dataclass(frozen=True, kw_only=True)
class Other:
    """The other file's reading by ``engine``: its tree, or why there is none."""

    path: Path
    engine: str
    tree: ModelTree | None
    why: str = ""


def read_other(text: str, *, engine: str, floating: bool, isolate: bool,
               limits: engine_processes.Limits | None) -> Other:
    """The file ``text`` read by ``engine`` in a process of its own (``isolate``): bad input
    (not a model file, a FIFO among its assets, massless links, refused by the engine whose
    format it is) raises :class:`~dyncheck.check.inputs.ModelFileError` before the model's
    engines start; a crash or a hang of the engine is the row's reason."""
    path = inputs.model_path(text)
    source: ModelFile = read(path, floating=floating)
    inputs.massive(path, source)
    isolate = isolate and engine_processes.can_isolate()
    started = engine_processes.start([engine], source, isolate=isolate, limits=limits)
    try:
        result = started[engine]
        if not isinstance(result, NotLoaded):
            return Other(path=path, engine=engine, tree=result.tree)
        native = REGISTRY[engine].native if engine in REGISTRY else None
        if result.refused and native is not None and native.value == source.format.value:
            raise inputs.ModelFileError(path, result.message)
        return Other(path=path, engine=engine, tree=None, why=result.message)
    finally:
        engine_processes.stop(started)


def rows(model: str, mine: ModelTree, other: Other) -> list[CheckRow]:
    """The description diff of the model's reading against the other file's, both read by
    one engine; one row where the other has no reading or another engine read the model."""
    label = f"against:{shown(other.path.name)}"
    if other.tree is not None and mine.engine == other.engine:
        return describe.diff(model, replace(other.tree, engine=label),
                             replace(mine, engine=f"{mine.engine}:{model}"))
    why = (f"{other.engine} could not read it: {other.why}" if other.tree is None else
           f"{other.engine} read it, {mine.engine} the model ({other.engine} did not load "
           "the model): two parsers, not two versions — not compared")
    return [CheckRow(model=model, section=Section.DESCRIPTION, subject="model",
                     field=FLAG, impl_a=label, impl_b=f"{mine.engine}:{model}", value_a="",
                     value_b="", error=0.0, tolerance=0.0, basis="",
                     verdict=Verdict.FAILED if other.tree is None else Verdict.SKIPPED,
                     note=why)]
