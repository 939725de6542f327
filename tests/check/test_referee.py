"""The referee's two methods tied on every checked tree (dyncheck/check/referee.py): the
recursive Newton–Euler algorithm serves the states and the derivatives only where it agrees
with the book's general method; a defect inside the recursion (mutated here) fails the tie,
and the referee's derivative rows give way to that failed row — never silently trusted."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from dyncheck.check import referee as referee_module
from dyncheck.check.model_check import check_model
from dyncheck.reference.recursive import RecursiveDynamics

MODELS = Path(__file__).parent / "models"


class _Mutated(RecursiveDynamics):
    """The recursion with one joint's inertia off by 1e-6 (relative) inside it alone."""

    def __init__(self, bodies, gravity):
        heavy = max(range(len(bodies)), key=lambda i: np.abs(bodies[i].inertia).max())
        bodies = list(bodies)
        bodies[heavy] = replace(bodies[heavy], inertia=bodies[heavy].inertia * (1 + 1e-6))
        super().__init__(bodies, gravity)


@pytest.mark.parametrize("model", ["mixed.xml", "floating_arm.xml"])
def test_a_mutated_recursion_fails_the_tie(monkeypatch, model):
    monkeypatch.setattr(referee_module, "RecursiveDynamics", _Mutated)
    result = check_model(MODELS / model, states=12, impls=("reference", "mujoco"),
                         derivatives=True)
    rows = result.rows
    tie = rows[rows["subject"] == "referee"]
    assert set(tie["verdict"]) == {"failed"}, tie
    assert (tie["error"] > tie["tolerance"]).all()
    assert "general method gave every number" in tie["note"].iloc[0]
    # the general method served the dynamics: the referee still agrees with MuJoCo there
    dynamics = rows[(rows["section"] == "dynamics") & (rows["subject"] != "referee")]
    assert set(dynamics["verdict"]) == {"passed"}, dynamics
    # and its derivatives are not a side of any row
    derivative = rows[rows["section"] == "derivatives"]
    assert not ((derivative["impl_a"] == "reference") & (derivative["subject"] != "referee")
                ).any(), derivative


@pytest.mark.parametrize("model", ["mixed.xml", "floating_arm.xml"])
def test_the_unmutated_recursion_passes_the_tie(model):
    """The same models without the mutation (the test above is not failing for another
    reason): the tie passes, well inside its tolerance, and the referee's derivatives are
    compared."""
    result = check_model(MODELS / model, states=12, impls=("reference", "mujoco"),
                         derivatives=True)
    rows = result.rows
    tie = rows[rows["subject"] == "referee"]
    assert list(tie["verdict"]) == ["passed"]
    assert float(tie["error"].iloc[0]) < 0.1 * float(tie["tolerance"].iloc[0])
    derivative = rows[rows["section"] == "derivatives"]
    assert (derivative["impl_a"] == "reference").any()
