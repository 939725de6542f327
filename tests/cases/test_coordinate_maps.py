"""Quaternion → rotation matrix, against SciPy's independent implementation, and its
one-quaternion fast path against the batched path (bit for bit: the integrators call it once
per stage, and the report check compares the runs)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.errors import InvalidInput


@pytest.fixture(scope="module")
def quats() -> np.ndarray:
    q = np.random.default_rng(7).normal(size=(2000, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_matches_scipy(quats):
    expected = Rotation.from_quat(quats, scalar_first=True).as_matrix()  # (w, x, y, z)
    assert np.abs(quat_to_matrix(quats) - expected).max() < 1e-15 * 8


def test_one_at_a_time_is_bit_identical_to_the_batch(quats):
    one = np.concatenate([quat_to_matrix(quats[i : i + 1]) for i in range(len(quats))])
    assert np.array_equal(one, quat_to_matrix(quats))


@pytest.mark.parametrize("bad", [[1.0, 0, 0, 0.1], [0.0, 0, 0, 0], [np.nan, 0, 0, 1]])
@pytest.mark.parametrize("batch", [1, 3])
def test_non_unit_quaternion_is_refused_on_both_paths(bad, batch):
    q = np.tile([1.0, 0, 0, 0], (batch, 1))
    q[-1] = bad
    with pytest.raises(InvalidInput, match="unit quaternion"):
        quat_to_matrix(q)
