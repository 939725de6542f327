"""The names of the findings a trajectory study reports (each explained in
:mod:`dyncheck.explanations`)."""

from __future__ import annotations

TRUNCATION = "integrator truncation error"
PRE_ASYMPTOTIC = "pre-asymptotic step (a fast constraint mode)"
CHARTS_DIFFER = "rotating-body state stepped in different charts"
NAIVE_GROUP_RK4 = "RK4 stages summed across the rotation group's tangent spaces (order 2)"
HELD_FORCE = "state-dependent force held over RK4 stages"
GYROSCOPIC_IMPLICIT = "MuJoCo's implicitfast applies a free body's gyroscopic derivative"
