"""Integrators defined as MuJoCo defines them, for engines that have none (Pinocchio,
dyncheck's own sympy-mechanics model), and error-controlled integration on the rotation group.

States are laid out as MuJoCo lays them out (:class:`Addresses`): a hinge or slide one
coordinate; a ball joint its unit quaternion (w, x, y, z) and its angular velocity ω in the
body frame; a free joint (p, quaternion) and (v, ω) with the linear velocity v in the *world*
frame. An engine whose state differs maps to this layout and back (its adapter does).

Fixed-step integrators (MuJoCo's ``mj_Euler``, ``mj_implicit``, ``mj_RungeKutta``, read in
MuJoCo's source and its 4.0.0 changelog, and checked on the installed MuJoCo to round-off in
one step of a ball and a free joint, tests/adapters/test_integrators.py):

- ``euler``: semi-implicit Euler, v' = v + h·v̇(q, v), then q' = q ⊕ h·v'.
- ``implicitfast``: v' = v + h·(M − h·D)⁻¹(τ − h(q, v) + f_passive) with D = ∂f/∂v of the
  passive and actuator forces; with no damping and no actuators D = 0 and it is ``euler``.
  (MuJoCo ≥ 3.11.0 also applies a free body's gyroscopic derivative here; dyncheck's does not.)
- ``rk4``: the classic four-stage tableau on x = (q, v) with stage positions
  q₀ ⊕ h·Σⱼ aᵢⱼ kⱼ. On a ball or free joint's rotation the stage velocities kⱼ are the
  Runge–Kutta–Munthe-Kaas ones, kⱼ = dexp⁻¹(θⱼ) ωⱼ with θⱼ the stage's own increment and
  dexp⁻¹ the exact inverse right Jacobian of SO(3) — MuJoCo ≥ 4.0.0 (commit 9a7f240f0). Up
  to MuJoCo 3.x the stage angular velocities were summed as they are (kⱼ = ωⱼ), which is
  second order on the rotation group; :func:`integrate` keeps that definition only for the
  conventions catalogue's demonstration (``naive_group=True``).
- ``rk4-held-force``: the same tableau with a state-dependent external force evaluated once at
  the start of the step and held over the stages — what MuJoCo does with a force written to
  ``xfrc_applied`` before ``mj_step``. The force's error over a step is O(h²): order 1.

Positions advance by MuJoCo's ``mj_integratePos``: q + h·v for hinges and slides (and a free
joint's position), the quaternion times exp(h·ω/2), renormalized.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property, partial

import numpy as np

from dyncheck.adapters.model_tree import StateLayout
from dyncheck.cases.quaternions import dexp_inv, norm, quat_exp, quat_mul
from dyncheck.errors import EngineError
from dyncheck.vocabulary import ROTATING, Integrator, JointType

Acceleration = Callable[..., np.ndarray]
"""v̇(q, v[, held]) for one state in the :class:`Addresses`, shapes (nq,), (nv,) → (nv,): called
with two arguments it evaluates every state-dependent external force now; with ``held``, what
``freeze`` returned at the start of the step, it uses that force instead."""


@dataclass(frozen=True, kw_only=True)
class Addresses:
    """A state laid out as MuJoCo's: per joint its type and the addresses of its positions
    (``qadr``) and velocities (``vadr``)."""

    joints: tuple[tuple[str, int, int], ...]

    @classmethod
    def of(cls, joint_types: Sequence[str]) -> Addresses:
        places = StateLayout().joints([JointType(jt) for jt in joint_types])  # MuJoCo's
        joints = [(jt, p.q_start, p.v_start) for jt, p in zip(joint_types, places, strict=True)]
        return cls(joints=tuple(joints))

    @cached_property
    def rotating(self) -> bool:
        """A ball or free joint (asked at every stage: computed once)."""
        return any(jt in ROTATING for jt, _, _ in self.joints)

    def rotations(self) -> list[tuple[int, int]]:
        """(address of the quaternion in q, of ω in v) per ball or free joint."""
        out = []
        for jt, qa, va in self.joints:
            if jt == "ball":
                out.append((qa, va))
            elif jt == "free":
                out.append((qa + 3, va + 3))
        return out

    def integrate_pos(self, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """q ⊕ dq, MuJoCo's ``mj_integratePos`` with the increment already times h."""
        if not self.rotating:
            return q + dq
        out = np.array(q, float)
        for jt, qa, va in self.joints:
            if jt == "free":
                out[qa : qa + 3] += dq[va : va + 3]
            elif jt not in ROTATING:
                out[qa] += dq[va]
        for qa, va in self.rotations():
            quat = quat_mul(out[qa : qa + 4], quat_exp(dq[va : va + 3]))
            out[qa : qa + 4] = quat / norm(quat)
        return out

    def dexp_inv(self, theta: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The velocity as the rate of the increment θ: dexp⁻¹(θ) ω on every rotation, v
        elsewhere."""
        if not self.rotating:
            return v
        out = np.array(v, float)
        for _, va in self.rotations():
            out[va : va + 3] = dexp_inv(theta[va : va + 3], v[va : va + 3])
        return out


def _vector(nq: int) -> Addresses:
    return Addresses.of(["slide"] * nq)


def _euler(acc: Acceleration, q: np.ndarray, v: np.ndarray, h: float, layout: Addresses, naive):
    v_new = v + h * acc(q, v)
    return layout.integrate_pos(q, h * v_new), v_new


RK4_A = ((0.5,), (0.0, 0.5), (0.0, 0.0, 1.0))
RK4_B = (1 / 6, 1 / 3, 1 / 3, 1 / 6)


def _rk4(acc: Acceleration, q: np.ndarray, v: np.ndarray, h: float, layout: Addresses, naive):
    """MuJoCo's ``mj_RungeKutta`` (N = 4): stage positions q₀ ⊕ h Σ aᵢⱼ kⱼ, stage velocities
    vᵢ = v₀ + h Σ aᵢⱼ v̇ⱼ, and kᵢ = dexp⁻¹(θᵢ) vᵢ on rotations (``naive``: kᵢ = vᵢ). The
    tableau's one non-zero aᵢⱼ per row is written out (a sum over its zeros adds exact zeros:
    the same numbers, without a generator per stage)."""
    (a21,), (_, a32), (_, _, a43) = RK4_A
    b1, b2, b3, b4 = RK4_B
    k1, f1 = v, acc(q, v)
    theta = h * (a21 * k1)
    v2 = v + h * (a21 * f1)
    f2 = acc(layout.integrate_pos(q, theta), v2)
    k2 = v2 if naive else layout.dexp_inv(theta, v2)
    theta = h * (a32 * k2)
    v3 = v + h * (a32 * f2)
    f3 = acc(layout.integrate_pos(q, theta), v3)
    k3 = v3 if naive else layout.dexp_inv(theta, v3)
    theta = h * (a43 * k3)
    v4 = v + h * (a43 * f3)
    f4 = acc(layout.integrate_pos(q, theta), v4)
    k4 = v4 if naive else layout.dexp_inv(theta, v4)
    dq = h * (b1 * k1 + b2 * k2 + b3 * k3 + b4 * k4)
    dv = h * (b1 * f1 + b2 * f2 + b3 * f3 + b4 * f4)
    return layout.integrate_pos(q, dq), v + dv


def _rk4_vector(acc: Acceleration, q: np.ndarray, v: np.ndarray, h: float, layout: Addresses,
                naive):
    """:func:`_rk4` on a vector state (no ball or free joint: q ⊕ dq = q + dq, dexp⁻¹ the
    identity) as one array y = (q, v) with y' = (v, v̇): element by element the same
    operations in the same order — the same numbers — in half the numpy calls (a step's
    cost on a small system is those calls, not the dynamics)."""
    (a21,), (_, a32), (_, _, a43) = RK4_A
    b1, b2, b3, b4 = RK4_B
    n = q.shape[0]
    y = np.concatenate([q, v])
    F1 = np.concatenate([v, acc(q, v)])
    y2 = y + h * (a21 * F1)
    F2 = np.concatenate([y2[n:], acc(y2[:n], y2[n:])])
    y3 = y + h * (a32 * F2)
    F3 = np.concatenate([y3[n:], acc(y3[:n], y3[n:])])
    y4 = y + h * (a43 * F3)
    F4 = np.concatenate([y4[n:], acc(y4[:n], y4[n:])])
    out = y + h * (b1 * F1 + b2 * F2 + b3 * F3 + b4 * F4)
    return out[:n], out[n:]


def _held(acc: Acceleration, held: object, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A stage's v̇ with the force frozen at the start of the step."""
    return acc(q, v, held)


STEPPERS: dict[str, Callable[..., tuple]] = {
    Integrator.EULER: _euler,
    Integrator.IMPLICITFAST: _euler,  # D = 0: no damping, no actuators (see module docstring)
    Integrator.RK4: _rk4,
    Integrator.RK4_HELD_FORCE: _rk4,
}


def integrate(
    acc: Acceleration,
    q0: np.ndarray,
    v0: np.ndarray,
    dt: float,
    steps: int,
    integrator: str,
    *,
    freeze: Callable[[np.ndarray, np.ndarray], object] | None = None,
    layout: Addresses | None = None,
    naive_group: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """States after 0..steps steps, shapes (steps + 1, nq) and (steps + 1, nv), in ``layout``
    (default: every coordinate a slide). With ``rk4-held-force``, ``freeze(q, v)`` is
    evaluated at the start of each step and passed to every stage. ``naive_group`` sums RK4's
    stage angular velocities without the Munthe-Kaas correction (MuJoCo 3.x; order 2 on the
    rotation group): for the conventions catalogue only."""
    step = STEPPERS[integrator]
    q, v = np.array(q0, float), np.array(v0, float)
    layout = layout or _vector(q.shape[0])
    if step is _rk4 and not layout.rotating:
        step = _rk4_vector
    qs = np.empty((steps + 1, q.shape[0]))
    vs = np.empty((steps + 1, v.shape[0]))
    qs[0], vs[0] = q, v
    hold = freeze if integrator == Integrator.RK4_HELD_FORCE else None
    for k in range(1, steps + 1):
        stage = acc if hold is None else partial(_held, acc, hold(q, v))
        q, v = step(stage, q, v, dt, layout, naive_group)
        qs[k], vs[k] = q, v
        # a NaN or an infinity (or |x| ~ 1e308); summed as Python floats: a small state's two
        # numpy reductions cost 2 µs, 40 % of an Euler step, its lists' sums 0.3 µs
        if not math.isfinite(sum(q.tolist()) + sum(v.tolist())):
            raise FloatingPointError(f"{integrator} diverged at step {k} (t = {k * dt:g})")
    return qs, vs


MAX_CHART_ANGLE = 0.5
"""Rotation (rad) past which a local exponential chart is re-centred: far from its singularity
at π, where dexp⁻¹ stays well conditioned."""


def solve_on_group(
    acc: Acceleration,
    q0: np.ndarray,
    v0: np.ndarray,
    t_eval: np.ndarray,
    rtol: float,
    *,
    layout: Addresses,
    label: str,
) -> tuple[np.ndarray, np.ndarray]:
    """scipy's DOP853 (rtol = atol = ``rtol``) of (q, v)' = (v, acc(q, v)). On the rotation
    group in local exponential coordinates θ about a centre q_c — θ̇ = dexp⁻¹(θ) ω,
    v̇ = acc(q_c ⊕ θ, v) — re-centred (q_c ← q_c ⊕ θ, θ ← 0) at the end of the first accepted
    step on which a rotation exceeds :data:`MAX_CHART_ANGLE`, and continued from there with the
    step size it had (never at an interpolated point: the dense output is less accurate than
    the steps). Samples at ``t_eval`` come from each step's dense output, as in ``solve_ivp``.
    Returns q, v at ``t_eval``, shapes (n, nq), (n, nv)."""
    from scipy.integrate import DOP853, solve_ivp  # 0.5 s to import: only where used

    nv = v0.shape[0]
    if not layout.rotating:  # a vector state is its own global chart: one solve
        sol = solve_ivp(
            lambda _t, y: np.concatenate([y[nv:], acc(y[:nv], y[nv:], None)]),
            (t_eval[0], t_eval[-1]),
            np.concatenate([q0, v0]),
            method="DOP853",
            t_eval=t_eval,
            rtol=rtol,
            atol=rtol,
        )
        if not sol.success:
            raise EngineError(f"{label}: solve_ivp failed: {sol.message}")
        return sol.y[:nv].T, sol.y[nv:].T

    def rhs(_t: float, y: np.ndarray, centre: np.ndarray) -> np.ndarray:
        theta, vel = y[:nv], y[nv:]
        return np.concatenate(
            [layout.dexp_inv(theta, vel), acc(layout.integrate_pos(centre, theta), vel, None)]
        )

    def start(t: float, centre: np.ndarray, v: np.ndarray,
              first_step: float | None) -> DOP853:
        return DOP853(
            lambda t, y: rhs(t, y, centre),
            t,
            np.concatenate([np.zeros(nv), v]),
            float(t_eval[-1]),
            rtol=rtol,
            atol=rtol,
            first_step=first_step,
        )

    centre = np.array(q0, float)
    solver = start(float(t_eval[0]), centre, np.asarray(v0, float), None)
    qs, vs = [centre], [np.array(v0, float)]
    k = 1
    while k < len(t_eval):
        message = solver.step()
        if solver.status == "failed":
            raise EngineError(f"{label}: DOP853 failed: {message}")
        dense = solver.dense_output()
        while k < len(t_eval) and t_eval[k] <= solver.t:
            y = dense(t_eval[k])
            qs.append(layout.integrate_pos(centre, y[:nv]))
            vs.append(y[nv:])
            k += 1
        turn = max(np.linalg.norm(solver.y[va : va + 3]) for _, va in layout.rotations())
        if turn > MAX_CHART_ANGLE and solver.status == "running":
            centre = layout.integrate_pos(centre, solver.y[:nv])
            step = min(solver.step_size, float(t_eval[-1]) - solver.t)
            solver = start(solver.t, centre, solver.y[nv:], step)
    return np.array(qs), np.array(vs)
