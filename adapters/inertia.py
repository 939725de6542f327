"""Mass properties of rigidly joined bodies: what an engine's loader lumps into one body
(MuJoCo's welded children, a link's several inertials)."""

from __future__ import annotations

import numpy as np


def lump(
    masses: list[float], coms: list[np.ndarray], inertias: list[np.ndarray]
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia about it of rigidly joined bodies (world axes):
    the parallel-axis theorem, I = Σ (Iᵢ + mᵢ (|dᵢ|² 1 − dᵢ dᵢᵀ)), dᵢ = cᵢ − c."""
    mass = float(sum(masses))
    if mass <= 0.0:
        return mass, np.zeros(3), sum(inertias, np.zeros((3, 3)))
    com = sum(m * c for m, c in zip(masses, coms, strict=True)) / mass
    total = np.zeros((3, 3))
    for m, c, inertia in zip(masses, coms, inertias, strict=True):
        d = c - com
        total += inertia + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, np.asarray(com, float), total
