"""The generalized force of a control: a joint actuator's control law, clean-room.

Not the book's: §2.2 takes the generalized force Q (τ) as given, (2.2.23)–(2.2.24). This is
the law by which a simulator's control input makes it — the general form of an actuator on a
hinge or slide joint as MuJoCo's documentation states it (XML reference, ``<general>``;
"Computation", actuation model), written from that text alone:

    τ = g · clamp(f, f_range),   f = (g₀ + g₁ L + g₂ L̇) a + (b₀ + b₁ L + b₂ L̇),
    L = g q,   L̇ = g v,          a = clamp(u, u_range) (no activation dynamics),

and with activation dynamics a is a state, ȧ = u (integrator) or ȧ = (u − a)/t (filter).
Every function takes complex values for u and a (a complex step differentiates them): the
clamps test the real part, as the law is piecewise linear in u.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NONE, INTEGRATOR, FILTER, FILTER_EXACT = 0, 1, 2, 3
"""Activation dynamics, by number (the arrays below hold one per actuator)."""


@dataclass(frozen=True, kw_only=True)
class JointActuators:
    """k joint actuators: each acts on velocity coordinate ``dof`` (its joint's), with its
    gear, gain (k, 3), bias (k, 3), control, force and activation bounds (±inf where
    unlimited), activation dynamics (:data:`NONE` … :data:`FILTER_EXACT`) and filter time
    constants."""

    dof: np.ndarray
    q_index: np.ndarray
    gear: np.ndarray
    gain: np.ndarray
    bias: np.ndarray
    ctrl_low: np.ndarray
    ctrl_high: np.ndarray
    force_low: np.ndarray
    force_high: np.ndarray
    dynamics: np.ndarray
    time_constant: np.ndarray
    act_low: np.ndarray
    act_high: np.ndarray
    joint_low: np.ndarray
    joint_high: np.ndarray
    """Each actuator's joint's bound on the sum of its actuators' τ (±inf where none)."""

    @property
    def stateful(self) -> np.ndarray:
        """Which actuators have an activation state."""
        return self.dynamics != NONE


def clamp(x: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """x held in [low, high], tested on its real part (a complex step's imaginary part
    becomes 0 where the bound holds it, as the derivative does)."""
    x = np.asarray(x)
    return np.where(x.real < low, low, np.where(x.real > high, high, x))


def _unclamped(acts: JointActuators, q: np.ndarray, v: np.ndarray, u: np.ndarray, *,
               act: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """f = gain · a + bias before its range, and a, per actuator (n, k)."""
    length = acts.gear * q[:, acts.q_index]
    speed = acts.gear * v[:, acts.dof]
    driven = clamp(u, acts.ctrl_low, acts.ctrl_high)
    if act is not None:
        driven = np.where(acts.stateful, act, driven)
    gain = acts.gain[:, 0] + acts.gain[:, 1] * length + acts.gain[:, 2] * speed
    bias = acts.bias[:, 0] + acts.bias[:, 1] * length + acts.bias[:, 2] * speed
    return gain * driven + bias, driven


def scalar_forces(acts: JointActuators, q: np.ndarray, v: np.ndarray, u: np.ndarray, *,
                  act: np.ndarray | None = None) -> np.ndarray:
    """f clamped to its range, per actuator (n, k), at states (q, v) (n, nq), (n, nv),
    controls u (n, k) and activation states ``act`` (n, k; used where stateful)."""
    raw, _ = _unclamped(acts, q, v, u, act=act)
    return clamp(raw, acts.force_low, acts.force_high)


def generalized_force(acts: JointActuators, q: np.ndarray, v: np.ndarray, u: np.ndarray, *,
                      act: np.ndarray | None = None) -> np.ndarray:
    """τ (n, nv): every actuator's g · f on its joint's velocity coordinate, summed, and held
    in the joint's range."""
    forces = acts.gear * scalar_forces(acts, q, v, u, act=act)
    out = np.zeros((len(q), v.shape[1]), dtype=np.result_type(forces, float))
    low, high = np.full(v.shape[1], -np.inf), np.full(v.shape[1], np.inf)
    for k, dof in enumerate(acts.dof):
        out[:, dof] += forces[:, k]
        low[dof], high[dof] = acts.joint_low[k], acts.joint_high[k]
    return clamp(out, low, high)


def velocity_derivative(acts: JointActuators, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                        *, act: np.ndarray | None = None) -> np.ndarray:
    """∂τ/∂v (n, nv, nv) where no force bound holds: g² (g₂ a + b₂) on each actuator's
    joint, 0 where its forcerange holds it or where its joint's range holds the sum of the
    joint's actuators (at or beyond either bound) — the matrix an implicit-in-velocity step
    solves with, as MuJoCo 4.0's implicitfast and implicit define it (measured with
    ``mjd_transitionFD``: a position servo on a joint whose ``actuatorfrcrange`` holds meets
    the chain rule with 0 there to 6e-9, and misses by 0.13 of B with −kv)."""
    raw, driven = _unclamped(acts, q, v, u, act=act)
    free = (raw.real > acts.force_low) & (raw.real < acts.force_high)
    summed = np.zeros((len(q), v.shape[1]))
    held = acts.gear * clamp(raw.real, acts.force_low, acts.force_high)
    for k, dof in enumerate(acts.dof):
        summed[:, dof] += held[:, k]
    joint_sum = summed[:, acts.dof]
    free &= (joint_sum > acts.joint_low) & (joint_sum < acts.joint_high)
    slope = np.where(free, acts.gear**2 * (acts.gain[:, 2] * driven + acts.bias[:, 2]), 0.0)
    out = np.zeros((len(q), v.shape[1], v.shape[1]), dtype=np.result_type(slope, float))
    for k, dof in enumerate(acts.dof):
        out[:, dof, dof] += slope[:, k]
    return out


def activation_step(acts: JointActuators, u: np.ndarray, act: np.ndarray,
                    h: float) -> np.ndarray:
    """The activation states after one explicit Euler step of length h (the filter's exact
    step for :data:`FILTER_EXACT`), held in their bounds; unchanged where stateless."""
    driven = clamp(u, acts.ctrl_low, acts.ctrl_high)
    tc = np.where(acts.time_constant > 0, acts.time_constant, 1.0)
    rate = np.where(acts.dynamics == INTEGRATOR, driven, (driven - act) / tc)
    stepped = act + h * rate
    exact = act + (driven - act) * (1.0 - np.exp(-h / tc))
    stepped = np.where(acts.dynamics == FILTER_EXACT, exact, stepped)
    stepped = clamp(stepped, acts.act_low, acts.act_high)
    return np.where(acts.stateful, stepped, act)
