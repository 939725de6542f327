"""The quaternion algebra the steppings and the layout maps share (cases/quaternions.py)."""

from __future__ import annotations

import numpy as np

from dyncheck.cases.quaternions import norm


def test_norm_is_numpys_to_the_last_bit():
    """The stages' vector norm is numpy.linalg.norm's number exactly (numpy computes √(x·x)
    for a 1-D real array; rotation vectors and quaternions of many sizes)."""
    rng = np.random.default_rng(7)
    for x in [*rng.normal(size=(200, 3)), *rng.normal(size=(200, 4)) * 1e-3, np.zeros(3)]:
        assert norm(x) == np.linalg.norm(x)
