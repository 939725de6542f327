"""The arithmetic every round-off bound is written in: ε of float64 and float32, the factor
c of the bound c ε (× depth, × conditioning where the quantity needs them), and how a basis
names ε. One home, imported by the run's tolerances and the model check alike (no engine and
no case behind it: importing it costs nothing)."""

from __future__ import annotations

import numpy as np

EPS = float(np.finfo(float).eps)
EPS32 = float(np.finfo(np.float32).eps)
ROUNDOFF_FACTOR = 64
"""c in c ε: covers the recursive algorithms' accumulation along a chain in both precisions
(measured in ``dyncheck/tolerances.py``'s derivation)."""


def eps_name(eps: float) -> str:
    """How a round-off basis names ε: "eps" (float64), "float32 eps", or its value."""
    return "eps" if eps == EPS else ("float32 eps" if eps == EPS32 else f"eps {eps:.3g}")
