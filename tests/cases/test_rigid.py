"""The rigid-body cases: the Euler-angle map (exercise 23, Example 9), bad input, and the
closed-form row of the torque-free case."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import EulerAngleMap, quat_to_matrix
from dyncheck.errors import InvalidInput

RIGID = ("rigid_body_ball", "torque_free")


@pytest.fixture
def states():
    rng = np.random.default_rng(8)
    q = np.column_stack([rng.uniform(-3, 3, 30), rng.uniform(0.3, 2.8, 30), rng.uniform(-3, 3, 30)])
    return q, rng.normal(size=(30, 3))


def test_euler_map_orientation_is_example_9(states):
    """The quaternion's rotation is ℓ = Aᵀ with A Example 9's printed matrix (written out
    here again, independently of the map's product of rotations)."""
    q, _ = states
    R = quat_to_matrix(EulerAngleMap().to_engine(q))
    for k in range(len(q)):
        f, t, p = q[k]
        cf, sf, ct, st, cp, sp_ = np.cos(f), np.sin(f), np.cos(t), np.sin(t), np.cos(p), np.sin(p)
        A = np.array(
            [
                [cp * cf - ct * sf * sp_, cp * sf + ct * cf * sp_, sp_ * st],
                [-sp_ * cf - ct * sf * cp, -sp_ * sf + ct * cf * cp, cp * st],
                [st * sf, -st * cf, ct],
            ]
        )
        assert_allclose(R[k], A.T, atol=1e-15)
    assert_allclose(EulerAngleMap().to_book(EulerAngleMap().to_engine(q)), q, atol=1e-13)


def test_euler_map_velocity_is_body_frame_angular_velocity(states):
    """J q̇ = ω̄ with ω̄̃ = Rᵀ Ṙ (body frame), Ṙ by central differences; and J̇ q̇ likewise.
    A world-frame ω = R ω̄ differs (what a wrong-frame map would feed an engine)."""
    q, v = states
    m, h = EulerAngleMap(), 1e-6
    R = m.rotation(q)
    Rd = (m.rotation(q + h * v) - m.rotation(q - h * v)) / (2 * h)
    W = np.swapaxes(R, 1, 2) @ Rd
    w_body = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], -1)
    Jv = np.einsum("nij,nj->ni", m.jacobian(q), v)
    assert_allclose(Jv, w_body, atol=1e-8)
    assert np.abs(np.einsum("nij,nj->ni", R, w_body) - Jv).max() > 0.1
    dJ = (m.jacobian(q + h * v) - m.jacobian(q - h * v)) / (2 * h)
    assert_allclose(m.hessian_term(q, v), np.einsum("nij,nj->ni", dJ, v), atol=1e-8)


@pytest.mark.parametrize("case_name", RIGID)
def test_gimbal_lock_state_is_refused(case_name):
    case = get_case(case_name)
    spec = dataclasses.replace(case.trajectory, q0=(0.3, 0.0, 0.2))
    with pytest.raises(InvalidInput, match=r"^q0 must be off the singular set.*gimbal lock"):
        dataclasses.replace(case, trajectory=spec)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"I11": -1.0}, "inertia must be positive definite"),
        ({"I11": 0.5, "I22": 0.5, "I33": 2.0}, "principal moments obey I1 \\+ I2 >= I3"),
        ({"I12": float("nan")}, "inertia must be finite"),
    ],
)
def test_bad_inertia_is_refused(change, message):
    with pytest.raises(InvalidInput, match=message):
        dataclasses.replace(get_case("rigid_body_ball"), **change)


def test_closed_form_row_passes(full_run):
    """The reference's Euler-angle trajectory reproduces the Jacobi-elliptic ω̄(t)."""
    d = full_run.discrepancies
    row = d[d.quantity == "closed_form"]
    assert list(row.case) == ["torque_free"]
    assert row.verdict.iloc[0] == "passed" and row.max_rel_err.iloc[0] < 1e-11


def test_q_and_minus_q_are_the_same_rotation(states):
    """Rotations are compared, not quaternion components: −q maps to the same angles."""
    q, _ = states
    m = EulerAngleMap()
    assert_allclose(m.to_book(-m.to_engine(q)), m.to_book(m.to_engine(q)), atol=1e-15)


@pytest.mark.parametrize(
    "quat", [(0.0, 0.0, 0.0, 0.0), (1.0, 0.1, 0.0, 0.0), (float("nan"), 0.0, 0.0, 1.0)]
)
def test_non_unit_quaternion_is_refused(quat):
    with pytest.raises(InvalidInput, match=r"^quaternion must be a unit quaternion \(w, x, y, z\)"):
        EulerAngleMap().to_book(np.array([quat]))
