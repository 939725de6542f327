"""One verification run: cases × implementations → the long tables and figure data."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import pandas as pd

from dyncheck.cases import Case, get_case
from dyncheck.comparison import compare_instantaneous
from dyncheck.errors import UnknownName
from dyncheck.implementations import IMPLEMENTATIONS, Implementation, make_implementation
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

    cases = [get_case(n) for n in (case_names or list(CASES))]
    for name in impl_names:
        if name not in IMPLEMENTATIONS:
            raise UnknownName("implementation", name, IMPLEMENTATIONS)
    impls = [n for n in IMPLEMENTATIONS if n in (impl_names or IMPLEMENTATIONS)]
    return cases, impls


def run(
    cases: Sequence[Case],
    impl_names: Sequence[str],
    *,
    states: int | None = None,
    progress: Callable[[str], None] = lambda _msg: None,
) -> RunResult:
    """Evaluate, compare and study every case (``states`` sampled states each, default the
    case's own); an implementation that cannot be built (not
    installed, or raising) becomes skipped or failed rows, never an aborted run."""
    rows: list[Discrepancy] = []
    points: list[ConvergencePoint] = []
    figures: dict[str, TrajectoryFigures] = {}
    notes: dict[str, set[str]] = {}
    for case in cases:
        progress(f"{case.name}: instantaneous quantities")
        impls: dict[str, Implementation | Exception] = {}
        for name in impl_names:
            try:
                impls[name] = make_implementation(name, case)
            except Exception as exc:  # reported as a row, the run goes on
                impls[name] = exc
            warnings = getattr(getattr(impls[name], "adapter", None), "parser_warnings", [])
            notes.setdefault(name, set()).update(warnings)
        rows += compare_instantaneous(case, impls, case.iter_states(states))
        progress(f"{case.name}: trajectories and order of accuracy")
        p, r, figures[case.name] = study(case, impls)
        points += p
        rows += r
    return RunResult(
        list(cases),
        table(rows, Discrepancy, DISCREPANCY_KEY),
        table(points, ConvergencePoint, CONVERGENCE_KEY),
        figures,
        {k: sorted(v) for k, v in notes.items() if v},
    )
