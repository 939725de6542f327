"""Unit quaternions (w, x, y, z) as rotations, and the rotation group's exponential: the
algebra an engine's stepping on a ball or free joint and the maps between layouts share (one
home; numpy only)."""

from __future__ import annotations

import math

import numpy as np


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions (w, x, y, z)."""
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ]
    )


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b of two 3-vectors (``np.cross`` costs ten times more on one pair: a stage's
    budget)."""
    a1, a2, a3 = a
    b1, b2, b3 = b
    return np.array([a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1])


def norm(x: np.ndarray) -> float:
    """|x| of a 1-D float array by numpy.linalg.norm's own formula, √(x·x) — the same
    number without its ~1.5 µs of argument handling, a stage's budget on a small model."""
    return math.sqrt(x.dot(x))


def quat_conj(quat: np.ndarray) -> np.ndarray:
    """The conjugate (w, −x, −y, −z) — a unit quaternion's inverse — components on the first
    axis, as :func:`quat_mul` takes them."""
    return np.array([quat[0], -quat[1], -quat[2], -quat[3]])


def quat_exp(theta: np.ndarray) -> np.ndarray:
    """The unit quaternion of the rotation vector θ: (cos |θ|/2, sin(|θ|/2) θ/|θ|)."""
    angle = norm(theta)
    if angle == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * theta / angle])


def dexp_inv(theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """J_r⁻¹(θ) ω: the rate θ̇ of exponential coordinates, q(t) = q₀ exp(θ(t)), whose body
    angular velocity is ω — θ̇ = ω + ½ θ × ω + (1/|θ|² − (1 + cos|θ|)/(2|θ| sin|θ|)) θ × (θ × ω)
    (the Bernoulli series ω + ½ θ × ω + θ × (θ × ω)/12 + O(|θ|⁴) below 1e-4 rad)."""
    angle = norm(theta)
    if angle < 1e-4:
        k = 1.0 / 12.0 + angle**2 / 720.0
    else:
        k = 1.0 / angle**2 - (1.0 + np.cos(angle)) / (2.0 * angle * np.sin(angle))
    t_x_w = cross(theta, omega)
    return omega + 0.5 * t_x_w + k * cross(theta, t_x_w)


def quat_order(quat: str) -> list[int]:
    """Where an engine's quaternion components come from in (w, x, y, z): q_engine =
    q_wxyz[..., quat_order(quat)], and back through its ``np.argsort`` (``quat``: an order
    such as ``"xyzw"``, an engine layout's :class:`~dyncheck.adapters.model_tree.Orientation`)."""
    return ["wxyz".index(c) for c in str(quat)]


def quat_of_rpy(rpy: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of R_z(y) R_y(p) R_x(r), batched."""
    r, p, y = (rpy[:, i] / 2 for i in range(3))
    cr, sr, cp, sp_, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.stack(
        [
            cr * cp * cy + sr * sp_ * sy,
            sr * cp * cy - cr * sp_ * sy,
            cr * sp_ * cy + sr * cp * sy,
            cr * cp * sy - sr * sp_ * cy,
        ],
        -1,
    )


UNIT_ROUNDING = 8
"""|‖q‖ − 1| of a quaternion an engine normalized in its own arithmetic is at most a few ε
(its norm's four products, three sums and square root, then the division): within this many
of its ε it is left as the engine gave it."""


def unit(quat: np.ndarray, eps: float = 0.0) -> np.ndarray:
    """Engines that integrate quaternion components (Drake) let the norm drift: renormalize
    where it drifted beyond :data:`UNIT_ROUNDING` ε of the engine's arithmetic (``eps``; 0:
    always). A quaternion the engine normalized is its own: a float32 port's, whose norm is
    1 to ε₃₂, carries its round-off into the comparison as the engine computed it."""
    norm = np.linalg.norm(quat, axis=-1, keepdims=True)
    return np.where(np.abs(norm - 1.0) <= UNIT_ROUNDING * eps, quat, quat / norm)
