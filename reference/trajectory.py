"""Reference trajectories: the equations of motion integrated by scipy's DOP853."""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np
from scipy.integrate import solve_ivp


class Forward(Protocol):
    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray: ...


def solve(
    dynamics: Forward,
    q0: np.ndarray,
    v0: np.ndarray,
    t_eval: np.ndarray,
    *,
    rtol: float = 1e-13,
    atol: float = 1e-13,
) -> tuple[np.ndarray, np.ndarray]:
    """q(t), v(t) at ``t_eval`` (shapes (len(t_eval), N)) of M ẍ + h = 0, first-order form
    (x, ẋ)' = (ẋ, ẍ), by DOP853 (8th order) at tight tolerances."""
    q0, v0 = np.asarray(q0, float), np.asarray(v0, float)
    zero = np.zeros((1, q0.shape[0]))
    return solve_second_order(
        lambda q, v: dynamics.forward(q[None], v[None], zero)[0], q0, v0, t_eval, rtol, atol
    )


def solve_second_order(
    acceleration: Callable[[np.ndarray, np.ndarray], np.ndarray],
    q0: np.ndarray,
    v0: np.ndarray,
    t_eval: np.ndarray,
    rtol: float,
    atol: float,
) -> tuple[np.ndarray, np.ndarray]:
    """q(t), v(t) of q̈ = acceleration(q, q̇) by DOP853, first-order form (q, q̇)' = (q̇, q̈)."""
    n = q0.shape[0]

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[n:], acceleration(y[:n], y[n:])])

    sol = solve_ivp(
        rhs,
        (t_eval[0], t_eval[-1]),
        np.concatenate([q0, v0]),
        method="DOP853",
        t_eval=t_eval,
        rtol=rtol,
        atol=atol,
    )
    if not sol.success:
        raise RuntimeError(f"reference integration failed: {sol.message}")
    return sol.y[:n].T, sol.y[n:].T
