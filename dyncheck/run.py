"""One verification run: cases × implementations → the long tables and figure data."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import pandas as pd

from dyncheck.cases import Case, get_case
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
from dyncheck.trajectories import TrajectoryFigures, study


@dataclass
class RunResult:
    cases: list[Case]
    discrepancies: pd.DataFrame
    convergence: pd.DataFrame
    figures: dict[str, TrajectoryFigures]
    parser_notes: dict[str, list[str]]
    """Per implementation, what its MJCF parser said it ignores (its own warnings)."""

    @property
    def failed(self) -> bool:
        return bool((self.discrepancies["verdict"] == "failed").any())


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
    progress: Callable[[str], None] = lambda _msg: None,
) -> RunResult:
    """Evaluate, compare and study every case (``states`` sampled states each, default the
    case's own), in ``jobs`` processes; results do not depend on ``jobs``. An implementation
    that cannot be built (not installed, unsupported, raising) becomes skipped or failed rows,
    never an aborted run."""
    if jobs > 1 and len(cases) > 1:
        ctx = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as pool:
            futures = [pool.submit(_run_case, c, list(impl_names), states) for c in cases]
            outputs = []
            for case, future in zip(cases, futures, strict=True):
                outputs.append(future.result())
                progress(f"{case.name}: done")
    else:
        outputs = []
        for case in cases:
            progress(f"{case.name}: running")
            outputs.append(_run_case(case, impl_names, states))
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
    )
