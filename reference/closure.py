"""The constraints that close a tree (#78): C(q) = 0 on its configurations, their rows J of
velocity (J v = 0) and their accelerations at v̇ = 0 (J̇ v), for the constrained forward
dynamics of :mod:`.constrained` (Lagrange's equations with constraints, (2.2.23)–(2.2.26)).

Three kinds, each as a mechanism's file states it (points and rotations in world axes at the
tree's reference configuration, the point of view of :class:`~.tree.Body`):

- :class:`Connect` — a point of one body held at a point of another (or of the world): three
  rows, C = x₁ − x₂, J = J_x₁ − J_x₂;
- :class:`Weld` — a relative pose held: the connect's rows at the anchor and three of
  rotation, C = the rotation vector of A₁ E A₂ᵀ (A_b the body's rotation from the reference
  configuration, E the held A₁ᵀ A₂), J = J_ω₁ − J_ω₂ (C's derivative where C = 0);
- :class:`Coupling` — one length a polynomial in another, L₁ − L₁⁰ = Σₖ aₖ (L₂ − L₂⁰)ᵏ, each
  length a linear form in the hinge and slide coordinates (a joint: one term; a fixed
  tendon: its joints' coefficients; a URDF mimic joint: a₀ the offset, a₁ the multiplier).

A row's J̇ v is exact (:meth:`~.tree.TreeDynamics.point_motion`: the complex step along
q ⊕ s v); where C ≠ 0 the weld's rotation rows are C's derivative only to first order in C
(they are exact on the constraint set, where the dynamics are evaluated).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from dyncheck.reference.constrained import Closed
from dyncheck.reference.tree import TreeDynamics


@dataclass(frozen=True, kw_only=True)
class Connect:
    """``point1`` on joint ``body1``'s body held at ``point2`` on ``body2``'s (−1: the
    world), both in world axes at the reference configuration."""

    body1: int
    body2: int
    point1: np.ndarray
    point2: np.ndarray


@dataclass(frozen=True, kw_only=True)
class Weld:
    """A :class:`Connect` and the relative rotation ``held`` = A₁ᵀ A₂ (identity where the
    reference configuration satisfies the weld)."""

    body1: int
    body2: int
    point1: np.ndarray
    point2: np.ndarray
    held: np.ndarray


@dataclass(frozen=True, kw_only=True)
class Coupling:
    """L₁ − ``reference1`` = Σₖ ``polycoef``[k] (L₂ − ``reference2``)ᵏ, each length Σ c q_j
    over (tree joint j, c) terms of hinges and slides (``second`` empty: L₁ held at
    ``reference1`` + a₀)."""

    first: tuple[tuple[int, float], ...]
    second: tuple[tuple[int, float], ...]
    reference1: float
    reference2: float
    polycoef: tuple[float, ...]


Closure = Connect | Weld | Coupling
Way = Callable[..., Closed]


@dataclass(frozen=True, kw_only=True)
class Rows:
    """The closures' rows at S states, in the closures' order: C (S, m), J (S, m, nv),
    J̇ v (S, m); ``sizes`` each closure's number of rows."""

    value: np.ndarray
    jacobian: np.ndarray
    bias: np.ndarray
    sizes: tuple[int, ...]


def _rotation_vector(r: np.ndarray) -> np.ndarray:
    """log(R)^∨ of rotations (S, 3, 3) (angle < π)."""
    cos = np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1.0, 1.0)
    angle = np.arccos(cos)
    skew = np.stack([r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0],
                     r[:, 1, 0] - r[:, 0, 1]], -1) / 2
    sin = np.sin(angle)
    scale = np.where(sin > 1e-8, angle / np.where(sin > 1e-8, sin, 1.0), 1 + angle**2 / 6)
    return skew * scale[:, None]


def _length(terms: tuple[tuple[int, float], ...], tree: TreeDynamics, q: np.ndarray, *,
            nv: int) -> tuple[np.ndarray, np.ndarray]:
    """A linear form's value (S,) and row (nv,) over hinge and slide coordinates."""
    value, row = np.zeros(len(q)), np.zeros(nv)
    for joint, c in terms:
        value = value + c * q[:, int(tree.q_start[joint])]
        row[int(tree.v_start[joint])] += c
    return value, row


def _coupling(c: Coupling, tree: TreeDynamics, q: np.ndarray,
              v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C, J, J̇ v of a coupling: with x = L₂ − L₂⁰, C = L₁ − L₁⁰ − p(x), J = ℓ₁ − p'(x) ℓ₂,
    J̇ v = −p''(x) (ℓ₂·v)²."""
    l1, row1 = _length(c.first, tree, q, nv=tree.nv)
    l2, row2 = _length(c.second, tree, q, nv=tree.nv)
    x = l2 - c.reference2
    poly = np.polynomial.Polynomial(c.polycoef or (0.0,))
    slope, curve = poly.deriv(1), poly.deriv(2)
    value = l1 - c.reference1 - (poly(x) if c.second else poly.coef[0])
    if not c.second:
        slope = curve = np.polynomial.Polynomial((0.0,))
    jac = row1[None] - slope(x)[:, None] * row2[None]
    bias = -curve(x) * (v @ row2) ** 2
    return value[:, None], jac[:, None], bias[:, None]


def rows(tree: TreeDynamics, closures: list[Closure] | tuple[Closure, ...], q: np.ndarray,
         v: np.ndarray) -> Rows:
    """Every closure's rows at S states (q (S, nq), v (S, nv), the tree's layout)."""
    q, v = np.atleast_2d(np.asarray(q, float)), np.atleast_2d(np.asarray(v, float))
    parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    posed = [c for c in closures if not isinstance(c, Coupling)]
    motions = iter(tree.points_motion(q, v, [x for c in posed for x in (
        (c.body1, c.point1), (c.body2, c.point2))]))
    for c in closures:
        if isinstance(c, Coupling):
            parts.append(_coupling(c, tree, q, v))
            continue
        one, two = next(motions), next(motions)
        value = one.position - two.position
        jac = one.linear - two.linear
        bias = one.linear_bias - two.linear_bias
        if isinstance(c, Weld):
            turn = one.rotation @ c.held @ np.swapaxes(two.rotation, 1, 2)
            value = np.concatenate([value, _rotation_vector(turn)], 1)
            jac = np.concatenate([jac, one.angular - two.angular], 1)
            bias = np.concatenate([bias, one.angular_bias - two.angular_bias], 1)
        parts.append((value, jac, bias))
    s, nv = len(q), tree.nv
    if not parts:
        return Rows(value=np.zeros((s, 0)), jacobian=np.zeros((s, 0, nv)),
                    bias=np.zeros((s, 0)), sizes=())
    value, jac, bias = (np.concatenate(x, 1) for x in zip(*parts, strict=True))
    return Rows(value=value, jacobian=jac, bias=bias,
                sizes=tuple(p[0].shape[1] for p in parts))


def forward(tree: TreeDynamics, closures: list[Closure] | tuple[Closure, ...], q: np.ndarray,
            v: np.ndarray, *, tau: np.ndarray, way: Way) -> list[Closed]:
    """The closed tree's forward dynamics at S states, one :class:`~.constrained.Closed` per
    state, by ``way`` (:func:`~.constrained.reduced` or :func:`~.constrained.multipliers`)."""
    q, v = np.atleast_2d(np.asarray(q, float)), np.atleast_2d(np.asarray(v, float))
    tau = np.broadcast_to(np.asarray(tau, float), v.shape)
    mass, bias, _, _ = tree.at_states(q, v)
    held = rows(tree, closures, q, v)
    return [way(mass[s], bias[s], tau[s], J=held.jacobian[s], jdot_v=held.bias[s])
            for s in range(len(q))]


def _quat_step(quat: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """quat ⊗ exp(ξ/2) (w, x, y, z; S rows): the rotation R exp(ξ̂), ξ in the body's axes."""
    angle = np.linalg.norm(xi, axis=-1, keepdims=True)
    half = np.concatenate([np.cos(angle / 2),
                           xi * (np.sinc(angle / (2 * np.pi)) / 2)], -1)  # sin(θ/2)/θ · ξ
    w1, v1, w2, v2 = quat[..., :1], quat[..., 1:], half[..., :1], half[..., 1:]
    out = np.concatenate([w1 * w2 - np.sum(v1 * v2, -1, keepdims=True),
                          w1 * v2 + w2 * v1 + np.cross(v1, v2)], -1)
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def retract(tree: TreeDynamics, q: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """q ⊕ dv on the tree's charts, S states at once: hinges and slides add, a ball turns
    by exp(dξ) in its axes, a free body moves by its world displacement and turns likewise
    (MuJoCo's layout)."""
    out = np.array(q, float)
    for j, body in enumerate(tree.bodies):
        qs, vs = int(tree.q_start[j]), int(tree.v_start[j])
        if body.kind in ("hinge", "slide"):
            out[..., qs] += dv[..., vs]
        elif body.kind == "ball":
            out[..., qs : qs + 4] = _quat_step(out[..., qs : qs + 4], dv[..., vs : vs + 3])
        else:
            out[..., qs : qs + 3] += dv[..., vs : vs + 3]
            out[..., qs + 3 : qs + 7] = _quat_step(out[..., qs + 3 : qs + 7],
                                                   dv[..., vs + 3 : vs + 6])
    return out


@dataclass(frozen=True, kw_only=True)
class Projected:
    """S states moved onto the constraints: q with C(q) = 0 and v in J's null space, how far
    each is from them (|C|, |J v|, largest entries), and whether Newton's method converged."""

    q: np.ndarray
    v: np.ndarray
    residual: np.ndarray
    rate: np.ndarray
    converged: np.ndarray


PROJECTION_STEPS = 50
"""Newton's iterations before a draw is dropped (quadratic convergence: a draw that takes
more is near a singular configuration, or off every solution)."""


def _least_norm(jac: np.ndarray, value: np.ndarray) -> np.ndarray:
    """J⁺ C of each state (S, m, nv), (S, m): the least-norm step (rank-deficient rows
    allowed)."""
    return np.einsum("sij,sj->si", np.linalg.pinv(jac, rcond=1e-12), value)


def project(tree: TreeDynamics, closures: list[Closure] | tuple[Closure, ...], q: np.ndarray,
            v: np.ndarray, *, tol: float) -> Projected:
    """Newton's method on C(q) = 0 from the draws q (S, nq) — the least-norm step −J⁺ C on
    the charts (:func:`retract`), every state at once, each stopping once within ``tol``
    and no longer shrinking — then v projected on J's null space: the admissible state
    nearest the draw's velocity. ``tol``: the largest |C| accepted (the file's lengths)."""
    q, v = np.atleast_2d(np.array(q, float)), np.atleast_2d(np.array(v, float))
    moving = np.ones(len(q), bool)
    last = np.full(len(q), np.inf)
    for _ in range(PROJECTION_STEPS):
        if not moving.any():
            break
        held = rows(tree, closures, q[moving], v[moving])
        size = np.abs(held.value).max(axis=1, initial=0.0)
        done = (size <= tol) & (size >= last[moving] / 2)
        last[moving] = size
        step = moving.copy()
        step[moving] = ~done
        if step.any():
            keep = ~done
            q[step] = retract(tree, q[step], -_least_norm(held.jacobian[keep],
                                                          held.value[keep]))
        moving = step
    held = rows(tree, closures, q, v)
    jac = held.jacobian
    if jac.shape[1]:
        v = v - np.einsum("sij,sj->si", np.linalg.pinv(jac, rcond=1e-12),
                          np.einsum("sij,sj->si", jac, v))
    residual = np.abs(held.value).max(axis=1, initial=0.0)
    rate = np.abs(np.einsum("sij,sj->si", jac, v)).max(axis=1, initial=0.0)
    return Projected(q=q, v=v, residual=residual, rate=rate, converged=residual <= tol)
