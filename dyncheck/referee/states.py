"""The states a check samples (:class:`States`, drawn by
:func:`dyncheck.check.sampling.sample`) and the conditioning of M over them
(:func:`condition`, which scales the round-off bounds): held apart from the comparisons,
since every section of the check takes them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class States:
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray


def condition(mass: np.ndarray) -> float:
    """The largest condition number of M over the states (the symmetric M's eigenvalues:
    a fifth of the SVD's cost; an indefinite M from a broken model still gives |λ|
    max/min)."""
    if not mass.size:  # no coordinate: nothing to condition
        return 1.0
    with np.errstate(all="ignore"):
        symmetric = 0.5 * (mass + np.swapaxes(mass, -1, -2))
        eig = np.abs(np.linalg.eigvalsh(symmetric))
        if not np.all(np.isfinite(eig)):
            return float(np.linalg.cond(mass).max())
        ratio = eig.max(axis=-1) / eig.min(axis=-1)
        return float(np.nan_to_num(ratio, nan=np.inf).max()) if eig.size else 1.0
