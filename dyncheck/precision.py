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


def standing(far: float, length: float) -> float:
    """The factor a model's distance from the world origin puts on a round-off bound:
    max(1, X / ℓ), X the largest distance of a joint point or centre from the origin over the
    states, ℓ the model's own length. Positions carry round-off ε X, and every lever arm an
    engine or the general method takes as a difference of positions carries ε X / ℓ
    relative; near the origin (X ≤ ℓ) the bound c ε already covers it."""
    return max(1.0, far / max(length, 1e-300))
