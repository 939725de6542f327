"""Fixed-step integrators defined as MuJoCo defines them, for engines that have none.

MuJoCo (``mj_Euler``, ``mj_implicit``, ``mj_RungeKutta``; see its Computation chapter):

- ``euler``: semi-implicit Euler, v' = v + h·v̇(q, v), then q' = q + h·v' (new velocity).
- ``implicitfast``: v' = v + h·(M − h·D)⁻¹(τ − h(q, v) + f_passive) with D = ∂f/∂v of the
  passive and actuator forces only (Coriolis derivatives dropped), then q' = q + h·v'. With no
  damping and no actuators D = 0, and it is the same map as ``euler``.
- ``rk4``: the classic four-stage Runge–Kutta tableau on x = (q, v), ẋ = (v, v̇).
- ``rk4-held-force``: the same tableau with a state-dependent external force evaluated once at
  the start of the step and held over the stages — what MuJoCo does with a force written to
  ``xfrc_applied`` before ``mj_step``. The force's error over a step is O(h²), so the
  predicted order is 1.

Nominal orders: 1, 1, 4. Positions are updated by ``integrate_pos(q, v, h)``: q + h·v for
hinges and slides, and for a ball joint the quaternion times exp(h·ω/2) — MuJoCo's
``mj_integratePos``, Pinocchio's ``pin.integrate`` — so every stage and step stays on the
rotation group (the RK4 stage positions are q₀ ⊕ h·Σ aᵢⱼ kⱼ, as in ``mj_RungeKutta``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Acceleration = Callable[..., np.ndarray]
"""v̇(q, v, held) for one state, shapes (nv,) → (nv,); ``held`` is ``None`` (evaluate every
state-dependent external force now) or what ``freeze`` returned at the start of the step."""

NOMINAL_ORDER = {"euler": 1, "implicitfast": 1, "rk4": 4, "rk4-held-force": 1}


def _vector_pos(q: np.ndarray, v: np.ndarray, h: float) -> np.ndarray:
    return q + h * v


def _euler(acc: Acceleration, q: np.ndarray, v: np.ndarray, h: float, pos=_vector_pos) -> tuple:
    v_new = v + h * acc(q, v)
    return pos(q, v_new, h), v_new


def _rk4(acc: Acceleration, q: np.ndarray, v: np.ndarray, h: float, pos=_vector_pos) -> tuple:
    k1q, k1v = v, acc(q, v)
    k2q = v + 0.5 * h * k1v
    k2v = acc(pos(q, k1q, 0.5 * h), k2q)
    k3q = v + 0.5 * h * k2v
    k3v = acc(pos(q, k2q, 0.5 * h), k3q)
    k4q = v + h * k3v
    k4v = acc(pos(q, k3q, h), k4q)
    dq = (k1q + 2 * k2q + 2 * k3q + k4q) / 6
    dv = (k1v + 2 * k2v + 2 * k3v + k4v) / 6
    return pos(q, dq, h), v + h * dv


STEPPERS: dict[str, Callable[..., tuple]] = {
    "euler": _euler,
    "implicitfast": _euler,  # D = 0: no damping, no actuators (see module docstring)
    "rk4": _rk4,
    "rk4-held-force": _rk4,
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
    integrate_pos: Callable[[np.ndarray, np.ndarray, float], np.ndarray] = _vector_pos,
) -> tuple[np.ndarray, np.ndarray]:
    """States after 0..steps steps, shapes (steps + 1, nv). With ``rk4-held-force``,
    ``freeze(q, v)`` is evaluated at the start of each step and passed to every stage."""
    step = STEPPERS[integrator]
    qs = np.empty((steps + 1, q0.shape[0]))
    vs = np.empty((steps + 1, v0.shape[0]))
    q, v = np.array(q0, float), np.array(v0, float)
    qs[0], vs[0] = q, v
    held = integrator == "rk4-held-force" and freeze is not None
    for k in range(1, steps + 1):
        if held:
            frozen = freeze(q, v)

            def stage(qq: np.ndarray, vv: np.ndarray, frozen=frozen) -> np.ndarray:
                return acc(qq, vv, frozen)
        else:

            def stage(qq: np.ndarray, vv: np.ndarray) -> np.ndarray:
                return acc(qq, vv, None)

        q, v = step(stage, q, v, dt, integrate_pos)
        qs[k], vs[k] = q, v
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
            raise FloatingPointError(f"{integrator} diverged at step {k} (t = {k * dt:g})")
    return qs, vs
