"""One verification run: cases × implementations → the long tables and figure data."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial, reduce

import pandas as pd

from dyncheck.adapters import ACCELERATORS
from dyncheck.cases import Case, get_case
from dyncheck.catalogue import DEMOS, Entry, measured_entry, not_selected
from dyncheck.closed_forms import closed_form_rows
from dyncheck.comparison import Sweep, sweep
from dyncheck.comparison import rows as rows_of
from dyncheck.errors import UnknownName
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    Implementation,
    implementations_for,
    make_implementation,
)
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
from dyncheck.skipped import once_per_case
from dyncheck.studies import TrajectoryFigures, study
from dyncheck.studies.derivatives import derivative_rows
from dyncheck.vocabulary import Verdict
from dyncheck.workers import Unit, run_units


@dataclass
class RunResult:
    cases: list[Case]
    discrepancies: pd.DataFrame
    convergence: pd.DataFrame
    figures: dict[str, TrajectoryFigures]
    parser_notes: dict[str, list[str]]
    """Per implementation, what its MJCF parser said it ignores (its own warnings)."""
    conventions: list[Entry] | None = None
    """The conventions catalogue's demonstrations, run with the cases (its report page), or
    None where the run did not include them."""
    pngs: dict[str, dict[str, bytes]] = field(default_factory=dict)
    """Per case, its figures (kind → PNG) where the run rendered them in its units of work."""
    engines: dict[str, str] = field(default_factory=dict)
    """The versions of the engines the units of work used (provenance name → version,
    :func:`dyncheck.provenance.engine_versions`)."""
    ran: tuple[str, ...] = IMPLEMENTATIONS
    """The implementations the run was asked for (the others have no rows: one line says
    which, :func:`dyncheck.roster.not_run`)."""

    @property
    def failed(self) -> bool:
        """A row failed, or a conventions demonstration raised."""
        lost = any(e.failed for e in self.conventions or ())
        return lost or bool((self.discrepancies["verdict"] == Verdict.FAILED).any())


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


STATES_PER_UNIT = 1 << 17
"""A case sweeping more states than this cuts its instantaneous comparison into slices of this
many states, each a unit of work (on another worker, its memory flat: it streams its slice in
chunks); the slices' sweeps merge in order into the same rows as one pass."""

_BUILT: dict[tuple[str, tuple[str, ...]], dict[str, Implementation | Exception]] = {}
"""Implementations built in this process, by case and names: a worker that sweeps several
slices of a case loads its engines once."""


def _release() -> None:
    """Drop the implementations built in this process, and what their engines compiled."""
    engines = {type(adapter) for built in _BUILT.values() for impl in built.values()
               if not isinstance(impl, Exception) and (adapter := impl.adapter) is not None}
    _BUILT.clear()
    for engine in engines:
        engine.release_compiled()


def _implementations(
    case: Case, impl_names: Sequence[str], notes: dict[str, set[str]] | None = None
) -> dict[str, Implementation | Exception]:
    """The case's implementations (an implementation that cannot be built is its exception,
    reported as rows); ``notes`` collects what each MJCF parser said it ignores."""
    key = (repr(case), tuple(impl_names))
    if key not in _BUILT:
        impls: dict[str, Implementation | Exception] = {}
        for name in implementations_for(case, tuple(impl_names)):
            try:
                impls[name] = make_implementation(name, case)
            except Exception as exc:  # reported as a row, the run goes on
                impls[name] = exc
        _release()  # one case's engines at a time
        _BUILT[key] = impls
    impls = _BUILT[key]
    if notes is not None:
        for name, impl in impls.items():
            adapter = impl.adapter if isinstance(impl, Implementation) else None
            if adapter is not None:
                notes.setdefault(name, set()).update(adapter.parser_warnings)
    return impls


def sweep_slice(case: Case, impl_names: Sequence[str], n: int, start: int, stop: int) -> Sweep:
    """The instantaneous comparison over states [start, stop) of ``n`` (a unit of work)."""
    impls = _implementations(case, impl_names)
    return sweep(case, impls, case.iter_states(n, start=start, stop=stop), offset=start)


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
    impls = _implementations(case, impl_names, notes)
    rows = [] if sliced else rows_of(sweep(case, impls, case.iter_states(states)))
    n = case.n_states if states is None else min(states, case.n_states)
    rows += derivative_rows(case, impl_names, n)  # at the case's own states (or fewer)
    points, trajectory_rows, figures = study(case, impls)
    pngs = {} if render is None else render(
        case, figures, table(points, ConvergencePoint, CONVERGENCE_KEY))
    used = engine_versions(impls)  # the reference and the book name no engine
    return rows + trajectory_rows + closed_form_rows(case), points, figures, notes, pngs, used


def _convention(name: str, impl_names: Sequence[str]) -> tuple[list[Entry], dict[str, str]]:
    """One demonstration of the conventions catalogue (a unit of work), with the versions of
    the engines it uses; read back from the cache when measured before with the
    same dyncheck, engines and machine (``--no-cache``: measured afresh); skipped when it needs
    an optional engine the run leaves out (:func:`~dyncheck.catalogue.not_selected`)."""
    skipped = not_selected(name, impl_names)
    if skipped is not None:
        return [skipped], {}
    entry, used, _ = measured_entry(name)
    return [entry], used


def run(
    cases: Sequence[Case],
    impl_names: Sequence[str],
    *,
    states: int | None = None,
    jobs: int = 1,
    dask: str | None = None,
    conventions: bool = False,
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
    figures in its unit of work, beside the other cases'."""
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
    if conventions:
        units += [(f"conventions: {name}", _convention, (name, list(impl_names)))
                  for name in DEMOS]
    done = run_units(units, jobs=jobs, dask=dask, progress=progress)
    rows: list[Discrepancy] = []
    points: list[ConvergencePoint] = []
    figures: dict[str, TrajectoryFigures] = {}
    pngs: dict[str, dict[str, bytes]] = {}
    notes: dict[str, set[str]] = {}
    entries: list[Entry] = []
    engines: dict[str, str] = {}
    for (what, fn, _args), out in zip(units, done, strict=True):
        if fn is _convention:
            entries += out[0]
            engines |= out[1]
        elif fn is not sweep_slice:  # a case; its slices' sweeps merged in order
            r, p, f, said, drawn, used = out
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
        entries if conventions else None,
        pngs,
        engines,
        tuple(impl_names),
    )
