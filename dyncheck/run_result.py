"""What ``dyncheck run`` returns (:class:`RunResult`): the rows, the convergence points, the
figures' data and the catalogue's entries of one run — read by the report, which need not
import the run to know its shape."""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

from dyncheck.cases.base import Case
from dyncheck.explain.entry import Entry
from dyncheck.roster import IMPLEMENTATIONS
from dyncheck.studies.order import TrajectoryFigures
from dyncheck.vocabulary import Verdict


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
    seconds: dict[str, float] = field(default_factory=dict)
    """Per case, the seconds its units of work took where they ran (its whole unit and its
    slices of states): the JUnit's and the JSON's times."""

    @property
    def failed(self) -> bool:
        """A row failed, or a conventions demonstration raised."""
        lost = any(e.failed for e in self.conventions or ())
        return lost or bool((self.discrepancies["verdict"] == Verdict.FAILED).any())
