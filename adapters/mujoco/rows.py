"""MuJoCo's equality constraint rows: how many rows an equality makes, and where its rows sit
among a step's constraint rows (``efc_*``). One home for MuJoCo C and its ports (MJX, MuJoCo
Warp), which make the same rows and order them otherwise."""

from __future__ import annotations

import mujoco
import numpy as np

EQUALITY = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
"""The ``efc_type`` of an equality's row."""


def rows_of(kind: int) -> int:
    """The rows one equality of ``kind`` (an ``mjtEq``) makes: a connect holds a point (3), a
    weld a pose (6), a joint or tendon equality a scalar (1)."""
    return {int(mujoco.mjtEq.mjEQ_CONNECT): 3, int(mujoco.mjtEq.mjEQ_WELD): 6}.get(int(kind), 1)


def equality_rows(kind: np.ndarray, ident: np.ndarray, nefc: int) -> np.ndarray:
    """The indices of the equality rows among the first ``nefc`` constraint rows (``efc_type``
    ``kind``, ``efc_id`` ``ident``), in the order of their equalities (a stable sort: an
    equality's own rows keep their order)."""
    picked = np.flatnonzero(np.asarray(kind[:nefc]) == EQUALITY)
    return picked[np.argsort(np.asarray(ident)[picked], kind="stable")]
