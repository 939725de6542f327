"""The referee's actuator law (reference/actuation.py) against values worked out by hand from
MuJoCo's documented general actuator, τ = g · clamp(gain · a + bias, forcerange)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from dyncheck.reference import actuation as law

INF = np.inf


def one(*, gear=1.0, gain=(1.0, 0.0, 0.0), bias=(0.0, 0.0, 0.0), ctrl=(-INF, INF),
        force=(-INF, INF), dynamics=law.NONE, tc=0.0, act=(-INF, INF)) -> law.JointActuators:
    """One actuator on velocity coordinate 0 (position coordinate 0)."""
    return law.JointActuators(
        dof=np.array([0]), q_index=np.array([0]), gear=np.array([gear]),
        gain=np.array([gain]), bias=np.array([bias]), ctrl_low=np.array([ctrl[0]]),
        ctrl_high=np.array([ctrl[1]]), force_low=np.array([force[0]]),
        force_high=np.array([force[1]]), dynamics=np.array([dynamics]),
        time_constant=np.array([tc]), act_low=np.array([act[0]]), act_high=np.array([act[1]]),
        joint_low=np.array([-INF]), joint_high=np.array([INF]))


def tau(acts: law.JointActuators, q: float, v: float, u: float, act: float | None = None):
    return float(law.generalized_force(
        acts, np.array([[q]]), np.array([[v]]), np.array([[u]]),
        act=None if act is None else np.array([[act]]))[0, 0])


# (actuator, q, v, u, τ by hand)
CASES = {
    # motor, gear 3: τ = 3 u
    "motor with gear": (one(gear=3.0), 0.2, 0.5, 0.5, 1.5),
    # ctrlrange (−1, 1): u = 5 is held at 1, τ = 3 · 1
    "ctrlrange clamping": (one(gear=3.0, ctrl=(-1.0, 1.0)), 0.2, 0.5, 5.0, 3.0),
    # forcerange (−0.5, 0.5): f = 1 is held at 0.5, τ = 3 · 0.5
    "forcerange saturation": (one(gear=3.0, force=(-0.5, 0.5)), 0.2, 0.5, 1.0, 1.5),
    # position kp 10, kv 2, gear 2: L = 0.4, L̇ = 1.2, f = 10·0.7 − 10·0.4 − 2·1.2 = 0.6
    "position servo": (one(gear=2.0, gain=(10.0, 0, 0), bias=(0, -10.0, -2.0)), 0.2, 0.6, 0.7,
                       1.2),
    # velocity kv 4: f = 4·0.3 − 4·0.6 = −1.2
    "velocity servo": (one(gain=(4.0, 0, 0), bias=(0, 0, -4.0)), 0.2, 0.6, 0.3, -1.2),
    # general affine gain (2, 0.5, 0.25), bias (1, 0, 0): gain = 2 + 0.5·0.2 + 0.25·0.6 = 2.25,
    # f = 2.25 · 0.4 + 1 = 1.9
    "general affine": (one(gain=(2.0, 0.5, 0.25), bias=(1.0, 0, 0)), 0.2, 0.6, 0.4, 1.9),
}


@pytest.mark.parametrize("name", list(CASES))
def test_force_by_hand(name):
    acts, q, v, u, expected = CASES[name]
    assert tau(acts, q, v, u) == pytest.approx(expected, rel=1e-15, abs=1e-15)


def test_a_stateful_actuator_acts_by_its_activation_not_its_control():
    """A filter's force is gain · act: act 0.25 with control 0.9 gives 2 · 0.25 = 0.5."""
    acts = one(gain=(2.0, 0, 0), dynamics=law.FILTER, tc=0.1)
    assert tau(acts, 0.0, 0.0, 0.9, act=0.25) == pytest.approx(0.5, rel=1e-15)


@pytest.mark.parametrize(("dynamics", "expected"), [
    (law.INTEGRATOR, 0.25 + 0.01 * 0.9),  # ȧ = u
    (law.FILTER, 0.25 + 0.01 * (0.9 - 0.25) / 0.1),  # ȧ = (u − a)/t
    (law.FILTER_EXACT, 0.25 + (0.9 - 0.25) * (1 - np.exp(-0.01 / 0.1))),  # exact over h
])
def test_activation_step_by_hand(dynamics, expected):
    acts = one(dynamics=dynamics, tc=0.1)
    found = law.activation_step(acts, np.array([[0.9]]), np.array([[0.25]]), 0.01)
    assert float(found[0, 0]) == pytest.approx(expected, rel=1e-14)


def test_activation_bounds_hold_the_step():
    acts = one(dynamics=law.INTEGRATOR, act=(-0.1, 0.255))
    found = law.activation_step(acts, np.array([[0.9]]), np.array([[0.25]]), 0.01)
    assert float(found[0, 0]) == 0.255


def test_velocity_derivative_by_hand():
    """∂τ/∂v of a position servo: g² (−kv) = 4 · (−2) = −8; 0 where the force is held."""
    acts = one(gear=2.0, gain=(10.0, 0, 0), bias=(0, -10.0, -2.0))
    d = law.velocity_derivative(acts, np.array([[0.2]]), np.array([[0.6]]), np.array([[0.7]]))
    assert float(d[0, 0, 0]) == pytest.approx(-8.0, rel=1e-15)
    held = one(gear=2.0, gain=(10.0, 0, 0), bias=(0, -10.0, -2.0), force=(-0.1, 0.1))
    d = law.velocity_derivative(held, np.array([[0.2]]), np.array([[0.6]]), np.array([[0.7]]))
    assert float(d[0, 0, 0]) == 0.0


@pytest.mark.parametrize(("joint", "expected"), [((-100.0, 100.0), -8.0), ((-0.1, 0.1), 0.0)])
def test_a_joint_range_that_holds_the_sum_drops_the_velocity_derivative(joint, expected):
    """The servo above on a joint whose range holds its force (τ = 2 (10 · 0.7 − 10 · 0.2 −
    2 · 0.6) = 7.6, beyond 0.1): no −kv in the implicit step's matrix, as MuJoCo 4.0
    defines it (independent: mjd_transitionFD measured); within a wide range, g² (−kv)."""
    acts = replace(one(gear=2.0, gain=(10.0, 0, 0), bias=(0, -10.0, -2.0)),
                   joint_low=np.array([joint[0]]), joint_high=np.array([joint[1]]))
    d = law.velocity_derivative(acts, np.array([[0.2]]), np.array([[0.6]]), np.array([[0.7]]))
    assert float(d[0, 0, 0]) == pytest.approx(expected, rel=1e-15)


@pytest.mark.parametrize(("u", "slope"), [(0.7, 2.0 * 10.0), (5.0, 0.0)])
def test_a_complex_step_differentiates_through_the_clamps(u, slope):
    """∂τ/∂u = g · kp inside ctrlrange, 0 where the control is held (independent: the law's
    slope by hand)."""
    acts = one(gear=2.0, gain=(10.0, 0, 0), bias=(0, -10.0, -2.0), ctrl=(-1.0, 1.0))
    pushed = np.array([[u + 1e-30j]])
    found = law.generalized_force(acts, np.array([[0.2]]), np.array([[0.6]]), pushed)
    assert float(found[0, 0].imag / 1e-30) == pytest.approx(slope, rel=1e-15)


def test_a_joints_range_holds_the_sum_of_its_actuators():
    """Two motors on one joint, gears 1 and 2, controls 0.8 and 0.5: 0.8 + 2 · 0.5 = 1.8,
    held at the joint's 1.5 (MuJoCo's actuatorfrcrange bounds the sum, not each)."""
    two = law.JointActuators(
        dof=np.array([0, 0]), q_index=np.array([0, 0]), gear=np.array([1.0, 2.0]),
        gain=np.array([[1.0, 0, 0]] * 2), bias=np.zeros((2, 3)),
        ctrl_low=np.full(2, -INF), ctrl_high=np.full(2, INF), force_low=np.full(2, -INF),
        force_high=np.full(2, INF), dynamics=np.zeros(2, int), time_constant=np.zeros(2),
        act_low=np.full(2, -INF), act_high=np.full(2, INF), joint_low=np.full(2, -1.5),
        joint_high=np.full(2, 1.5))
    found = law.generalized_force(two, np.zeros((1, 1)), np.zeros((1, 1)), np.array([[0.8, 0.5]]))
    assert float(found[0, 0]) == 1.5
    found = law.generalized_force(two, np.zeros((1, 1)), np.zeros((1, 1)), np.array([[0.1, 0.2]]))
    assert float(found[0, 0]) == pytest.approx(0.5, rel=1e-15)
