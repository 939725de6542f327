"""The observed order of accuracy between steps h₁ = 2h₂, p = ln(E₁/E₂)/ln(h₁/h₂)
(Roy 2005), and the data the report plots."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CONTROLLED = "rk3-controlled"
"""The integrator column of an engine's error-controlled runs (Drake's runge_kutta3)."""
CONTROLLED_ACCURACIES = (1e-7, 1e-8, 1e-9, 1e-10)
"""Target accuracies ε of an engine's error-controlled integrator, a decade apart."""


def observed_orders(dts: list[float], errors: list[float]) -> list[float]:
    """p between consecutive steps; NaN for the first."""
    out = [float("nan")]
    for i in range(1, len(dts)):
        out.append(float(np.log(errors[i - 1] / errors[i]) / np.log(dts[i - 1] / dts[i])))
    return out


def finest_pair(asymptotic: list[bool]) -> int | None:
    """The index i of the finest pair of consecutive steps (i − 1, i) both in the asymptotic
    range, or None: where an observed order is read."""
    pairs = [i for i in range(1, len(asymptotic)) if asymptotic[i] and asymptotic[i - 1]]
    return pairs[-1] if pairs else None


@dataclass
class TrajectoryFigures:
    """What the report plots: the book model's reference on the grid, and per engine ×
    integrator the finest run's configuration and its error against its own reference."""

    t: np.ndarray
    reference: np.ndarray
    runs: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    errors: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    steps: dict[tuple[str, str], float] = field(default_factory=dict)
    energy: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    momentum: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    """|H(t) − H(0)| / |H(0)| of the finest run, H = ℓ Ī ω̄ the angular momentum in space
    axes ((2.2.42), (2.2.50)), for rigid bodies under no moment about the centre of mass."""
    """|E(t) − E(0)| / max|E| of the finest run, E = T + V (+ the field's V) of its own model."""
