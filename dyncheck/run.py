"""One verification run: cases × implementations → the long tables and figure data."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from dyncheck.cases import Case, get_case
from dyncheck.catalogue import DEMOS, Entry
from dyncheck.catalogue import explain as explain_convention
from dyncheck.closed_forms import closed_form_rows
from dyncheck.comparison import compare_instantaneous
from dyncheck.errors import UnknownName
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    Implementation,
    implementations_for,
    make_implementation,
)
from dyncheck.results import (
    CONVERGENCE_KEY,
    DISCREPANCY_KEY,
    ConvergencePoint,
    Discrepancy,
    table,
)
from dyncheck.studies import TrajectoryFigures, study
from dyncheck.workers import executor


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

    @property
    def failed(self) -> bool:
        """A row failed, or a conventions demonstration raised."""
        lost = any(e.failed for e in self.conventions or ())
        return lost or bool((self.discrepancies["verdict"] == "failed").any())


def resolve(case_names: Sequence[str], impl_names: Sequence[str]) -> tuple[list[Case], list[str]]:
    """Validate names before any work: UnknownName lists the valid ones."""
    from dyncheck.cases import CASES

    cases = [get_case(n) for n in dict.fromkeys(case_names or list(CASES))]  # once each
    for name in impl_names:
        if name not in IMPLEMENTATIONS:
            raise UnknownName("implementation", name, IMPLEMENTATIONS)
    impls = [n for n in IMPLEMENTATIONS if n in (impl_names or IMPLEMENTATIONS)]
    return cases, impls


def _run_case(
    case: Case, impl_names: Sequence[str], states: int | None
) -> tuple[list[Discrepancy], list[ConvergencePoint], TrajectoryFigures, dict[str, set[str]]]:
    """Everything for one case (a unit of work for a worker process)."""
    impls: dict[str, Implementation | Exception] = {}
    notes: dict[str, set[str]] = {}
    for name in implementations_for(case, tuple(impl_names)):
        try:
            impls[name] = make_implementation(name, case)
        except Exception as exc:  # reported as a row, the run goes on
            impls[name] = exc
        warnings = getattr(getattr(impls[name], "adapter", None), "parser_warnings", [])
        notes.setdefault(name, set()).update(warnings)
    rows = compare_instantaneous(case, impls, case.iter_states(states))
    points, trajectory_rows, figures = study(case, impls)
    return rows + trajectory_rows + closed_form_rows(case), points, figures, notes


def run(
    cases: Sequence[Case],
    impl_names: Sequence[str],
    *,
    states: int | None = None,
    jobs: int = 1,
    dask: str | None = None,
    conventions: bool = False,
    progress: Callable[[str], None] = lambda _msg: None,
) -> RunResult:
    """Evaluate, compare and study every case (``states`` sampled states each, default the
    case's own) and, with ``conventions``, run the conventions catalogue — as units of work in
    this process, ``jobs`` local processes or on a Dask cluster (``dask``:
    :func:`dyncheck.workers.executor`); results do not depend on where they ran. An
    implementation that cannot be built (not installed, unsupported, raising) becomes skipped
    or failed rows, never an aborted run."""
    units: list[tuple[str, Callable[..., Any], tuple[Any, ...]]] = [
        (case.name, _run_case, (case, list(impl_names), states)) for case in cases
    ]
    if conventions:
        units += [(f"conventions: {name}", explain_convention, (name,)) for name in DEMOS]
    with executor(jobs if len(units) > 1 else 1, dask) as pool:
        if pool is None:
            done = []
            for what, fn, args in units:
                progress(f"{what}: running")
                done.append(fn(*args))
        else:
            futures = [pool.submit(fn, *args) for _what, fn, args in units]
            done = []
            for (what, _fn, _args), future in zip(units, futures, strict=True):
                done.append(future.result())
                progress(f"{what}: done")
    outputs = done[: len(cases)]
    entries = [entry for (entry,) in done[len(cases) :]] if conventions else None
    rows: list[Discrepancy] = []
    points: list[ConvergencePoint] = []
    figures: dict[str, TrajectoryFigures] = {}
    notes: dict[str, set[str]] = {}
    for case, (r, p, f, n) in zip(cases, outputs, strict=True):
        rows += r
        points += p
        figures[case.name] = f
        for k, v in n.items():
            notes.setdefault(k, set()).update(v)
    return RunResult(
        list(cases),
        table(rows, Discrepancy, DISCREPANCY_KEY),
        table(points, ConvergencePoint, CONVERGENCE_KEY),
        figures,
        {k: sorted(v) for k, v in notes.items() if v},
        entries,
    )
