"""One verification run: cases × implementations → the long tables and figure data."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial, reduce

import pandas as pd

from dyncheck.adapters import ACCELERATORS
from dyncheck.cases import Case, get_case
from dyncheck.closed_forms import closed_form_rows
from dyncheck.comparison import Sweep, sweep
from dyncheck.comparison import rows as rows_of
from dyncheck.errors import UnknownName
from dyncheck.explain.entry import Entry
from dyncheck.implementations import IMPLEMENTATIONS, engines_as_read
from dyncheck.progress import Progress
from dyncheck.provenance import engine_versions
from dyncheck.results import (
    CONVERGENCE_KEY,
    DISCREPANCY_KEY,
    ConvergencePoint,
    Discrepancy,
    table,
)
from dyncheck.roster import ON_A_CPU
from dyncheck.run_result import RunResult
from dyncheck.skipped import once_per_case
from dyncheck.slices import STATES_PER_UNIT, built, sweep_slice
from dyncheck.studies.derivatives import derivative_rows
from dyncheck.studies.order import TrajectoryFigures
from dyncheck.studies.study import study
from dyncheck.workers import Unit, run_units


def resolve(
    case_names: Sequence[str], impl_names: Sequence[str], *, accelerators: bool = False
) -> tuple[list[Case], list[str]]:
    """Validate names before any work: UnknownName lists the valid ones. No ``impl_names``:
    every implementation a CPU runs in seconds (:data:`~dyncheck.roster.ON_A_CPU`);
    ``accelerators`` adds the engines built for accelerators."""
    from dyncheck.cases import CASES

    cases = [get_case(n) for n in dict.fromkeys(case_names or list(CASES))]  # once each
    for name in impl_names:
        if name not in IMPLEMENTATIONS:
            raise UnknownName("implementation", name, IMPLEMENTATIONS)
    chosen = {*(impl_names or ON_A_CPU), *(ACCELERATORS if accelerators else ())}
    impls = [n for n in IMPLEMENTATIONS if n in chosen]
    return cases, impls


Render = Callable[[Case, TrajectoryFigures, pd.DataFrame], dict[str, bytes]]
"""Draws a case's figures from its study and its convergence table (kind → PNG)."""


def _run_case(
    case: Case, impl_names: Sequence[str], states: int | None, *, sliced: bool = False,
    render: Render | None = None,
) -> tuple[list[Discrepancy], list[ConvergencePoint], TrajectoryFigures, dict[str, set[str]],
           dict[str, bytes], dict[str, str]]:
    """Everything for one case (a unit of work for a worker process), its figures drawn by
    ``render`` where given, and the versions of the engines it used; ``sliced``: the
    instantaneous comparison is left to :func:`sweep_slice` units."""
    notes: dict[str, set[str]] = {}
    impls = built(case, impl_names, notes)
    rows = [] if sliced else rows_of(sweep(case, impls, case.iter_states(states)))
    n = case.n_states if states is None else min(states, case.n_states)
    # at the case's own states (or fewer), on the engines the run loaded (each loaded once)
    rows += derivative_rows(case, impl_names, n, reuse=engines_as_read(impls))
    points, trajectory_rows, figures = study(case, impls)
    pngs = {} if render is None else render(
        case, figures, table(points, ConvergencePoint, CONVERGENCE_KEY))
    used = engine_versions(impls)  # the reference and the book name no engine
    return rows + trajectory_rows + closed_form_rows(case), points, figures, notes, pngs, used


def run(
    cases: Sequence[Case],
    impl_names: Sequence[str],
    *,
    states: int | None = None,
    jobs: int = 1,
    dask: str | None = None,
    conventions: Sequence[Unit] | None = None,
    progress: Progress | None = None,
    states_per_unit: int = STATES_PER_UNIT,
    render: Render | None = None,
) -> RunResult:
    """Evaluate, compare and study every case (``states`` sampled states each, default the
    case's own) and, with ``conventions``, run the conventions catalogue — as units of work in
    this process, ``jobs`` local processes or on a Dask cluster (``dask``:
    :func:`dyncheck.workers.executor`); results do not depend on where they ran. An
    implementation that cannot be built (not installed, unsupported, raising) becomes skipped
    or failed rows, never an aborted run. ``render`` (the report's figures) draws each case's
    figures in its unit of work, beside the other cases'. ``conventions``: the catalogue's
    demonstrations as units of work, composed by the command that wants them
    (:func:`dyncheck.explain.catalogue.units`; each gives its entries and the engine versions it
    used), run beside the cases; None: the run leaves the catalogue out."""
    units: list[Unit] = []
    slices: dict[str, list[int]] = {}  # case → the indices of its slice units
    for case in cases:
        n = case.n_states if states is None else states
        sliced = n > states_per_unit
        whole = partial(_run_case, sliced=sliced, render=render)
        units.append((case.name, whole, (case, list(impl_names), n)))
        if sliced:
            slices[case.name] = []
            for start in range(0, n, states_per_unit):
                stop = min(n, start + states_per_unit)
                slices[case.name].append(len(units))
                units.append((f"{case.name} states {start}..{stop - 1}", sweep_slice,
                              (case, list(impl_names), n, start, stop)))
    first_convention = len(units)
    units += conventions or ()
    took: list[float] = []
    done = run_units(units, jobs=jobs, dask=dask, progress=progress, took=took)
    seconds: dict[str, float] = {}
    rows: list[Discrepancy] = []
    points: list[ConvergencePoint] = []
    figures: dict[str, TrajectoryFigures] = {}
    pngs: dict[str, dict[str, bytes]] = {}
    notes: dict[str, set[str]] = {}
    entries: list[Entry] = []
    engines: dict[str, str] = {}
    for i, ((what, fn, _args), out) in enumerate(zip(units, done, strict=True)):
        if i >= first_convention:
            entries += out[0]
            engines |= out[1]
        elif fn is not sweep_slice:  # a case; its slices' sweeps merged in order
            r, p, f, said, drawn, used = out
            seconds[what] = took[i] + sum(took[k] for k in slices.get(what, ()))
            engines |= used
            if what in slices:
                r = rows_of(reduce(Sweep.merge, (done[i] for i in slices[what]))) + r
            rows += once_per_case(r)  # an engine's limit on the case: one row
            points += p
            figures[what] = f
            if drawn:
                pngs[what] = drawn
            for k, v in said.items():
                notes.setdefault(k, set()).update(v)
    return RunResult(
        list(cases),
        table(rows, Discrepancy, DISCREPANCY_KEY),
        table(points, ConvergencePoint, CONVERGENCE_KEY),
        figures,
        {k: sorted(v) for k, v in notes.items() if v},
        entries if conventions is not None else None,
        pngs,
        engines,
        tuple(impl_names),
        seconds,
    )
