"""Trajectory studies: the observed order of accuracy of every engine × integrator, and
engine-against-engine runs of the same integrator.

Each run starts from the case's initial state (book coordinates, mapped to the engine's) and
is compared on a common grid of times against the reference trajectory of *the same model*
(the general method on the implementation's model variant, DOP853 at rtol = atol = 1e-13), so
that the study measures the integrator alone. The observed order between steps h₁ = 2h₂ is
p = ln(E₁/E₂)/ln(h₁/h₂) (Roy 2005); a step counts as asymptotic only where its error exceeds
100× the reference's own error estimate |ref(1e-13) − ref(2.5e-14)| (2.5e-14 is near the
smallest rtol DOP853 accepts).

Two engines with the same integrator and step are compared step by step: on the same model
they must agree to accumulated round-off; on models that differ by a named convention, their
difference must equal the predicted one — the reference's equations for the two model
variants stepped by the same fixed-step integrator (MuJoCo's definition), within that
round-off. A run passes when the
finest asymptotic pair shows the nominal order ± 0.1; a large error at a coarse step is the
integrator's truncation error, reported with its size, not a failure.

The study is split by what it measures: :mod:`.references` (the reference trajectories and
the general method stepped like an engine), :mod:`.order` (observed orders, figure data),
:mod:`.drift` (energy, momentum, cord drift), :mod:`.controlled` (error-controlled runs),
:mod:`.pairs` (engine against engine) and
:mod:`.study` (one case, all of them).
"""

from dyncheck.labels import (
    CHARTS_DIFFER,
    GYROSCOPIC_IMPLICIT,
    HELD_FORCE,
    NAIVE_GROUP_RK4,
    PRE_ASYMPTOTIC,
    TRUNCATION,
)
from dyncheck.studies.order import (
    CONTROLLED,
    CONTROLLED_ACCURACIES,
    TrajectoryFigures,
    finest_pair,
    observed_orders,
)
from dyncheck.studies.references import References, difference
from dyncheck.studies.study import study

__all__ = [
    "CHARTS_DIFFER",
    "CONTROLLED",
    "CONTROLLED_ACCURACIES",
    "GYROSCOPIC_IMPLICIT",
    "HELD_FORCE",
    "NAIVE_GROUP_RK4",
    "PRE_ASYMPTOTIC",
    "TRUNCATION",
    "References",
    "TrajectoryFigures",
    "difference",
    "finest_pair",
    "observed_orders",
    "study",
]
