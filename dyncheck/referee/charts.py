"""An engine's derivatives in the canonical chart (MuJoCo's, ``mj_integratePos``): q ⊕ δ moves
a hinge or slide by δ, turns a ball or free body by exp(δ) in its body axes (quat ⊗ (cos ½|δ|,
sin ½|δ| δ/|δ|)) and moves a free body's origin by δ in world axes (:func:`perturb`, analytic:
a complex step passes through it). An engine's derivatives come in its own layout and chart
(:class:`~dyncheck.adapters.model_tree.DerivativeChart`); they are mapped by the chain rule
through the check's state map (:func:`~dyncheck.adapters.layout.state_map`: q_e(q), v_e = T v,
v̇_e = T v̇ + Ṫv), whose own derivatives are taken by a complex step (exact to round-off: the
map is analytic), :func:`to_canonical`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from dyncheck.adapters.layout import StateMap
from dyncheck.adapters.model_tree import (
    Axes,
    Canonical,
    DerivativeChart,
    Derivatives,
    Dynamics,
    JointType,
    ModelTree,
    Orientation,
)
from dyncheck.adapters.model_tree import derivatives as collect
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.cases.quaternions import quat_conj, quat_mul, quat_order
from dyncheck.referee.states import States

FIELDS = ("forward_q", "forward_v", "forward_tau", "inverse_q", "inverse_v")

COMPLEX_STEP = 1e-20
"""The complex step of the state map's derivatives (any step ≪ √ε works: no cancellation)."""
def perturb(canon: Canonical, q: np.ndarray, k: int, step: complex) -> np.ndarray:
    """q ⊕ step·e_k for every state (rows of ``q``), in the canonical chart; ``step`` may be
    imaginary (a complex step: cos and sin of i h/2 are analytic)."""
    out = q.astype(np.result_type(q, step, float), copy=True)
    joint = max(j for j in range(len(canon.types)) if canon.v_start[j] <= k)
    kind, qs, offset = canon.types[joint], canon.q_start[joint], k - canon.v_start[joint]
    if kind in (JointType.HINGE, JointType.SLIDE):
        out[:, qs] += step
        return out
    if kind is JointType.FREE and offset < 3:
        out[:, qs + offset] += step
        return out
    axis = offset - 3 if kind is JointType.FREE else offset
    at = qs + 3 if kind is JointType.FREE else qs
    turn = np.zeros((4, 1), out.dtype)
    turn[0], turn[1 + axis] = np.cos(step / 2), np.sin(step / 2)
    out[:, at : at + 4] = quat_mul(out[:, at : at + 4].T, turn).T
    return out


def _chart(tree: ModelTree, chart: DerivativeChart, q_e: np.ndarray,
           dq_e: np.ndarray) -> np.ndarray:
    """A displacement dq_e of the engine's q in the coordinates its derivatives are taken
    in: q itself (COORDINATES), or its velocity coordinates (TANGENT: a rotation's as the
    engine's angular velocity is resolved, a free body's origin as its linear velocity)."""
    if chart is DerivativeChart.COORDINATES:
        return dq_e
    out = np.zeros((tree.nv, *dq_e.shape[1:]))  # dq_e (nq_e,) or (nq_e, columns)
    for joint in tree.joints:
        lay = joint.layout
        qs, vs = lay.q_start, lay.v_start
        if lay.nq == 1:
            out[vs] = dq_e[qs]
        elif lay.cos_sin:  # (cos θ, sin θ): dθ = cos d(sin) − sin d(cos)
            out[vs] = q_e[qs] * dq_e[qs + 1] - q_e[qs + 1] * dq_e[qs]
        elif lay.quat == Orientation.RPY or lay.point is not None:
            raise ValueError(f"{tree.engine}: no tangent chart for {joint.name!r}")
        else:
            at = qs + (0 if joint.type is JointType.BALL or lay.quat_first else 3)
            back = np.argsort(quat_order(lay.quat))  # the engine's order to (w, x, y, z)
            quat, dquat = q_e[at : at + 4][back], dq_e[at : at + 4][back]
            local = lay.angular_axes is Axes.LOCAL
            turn = quat_mul(quat_conj(quat), dquat) if local else quat_mul(dquat, quat_conj(quat))
            omega = 2 * turn[1:]
            if joint.type is JointType.BALL:
                out[vs : vs + 3] = omega
                continue
            p = qs + (4 if lay.quat_first else 0)
            dp = dq_e[p : p + 3]
            if lay.linear_axes is Axes.LOCAL:
                dp = quat_to_matrix(quat[None])[0].T @ dp
            lin, ang = (vs + 3, vs) if lay.angular_first else (vs, vs + 3)
            out[lin : lin + 3], out[ang : ang + 3] = dp, omega
    return out


def _turning(canon: Canonical) -> set[int]:
    """The velocity indices of ball and free joints: the state map depends on their q
    nonlinearly (T, Ṫv); a hinge's or slide's q enters only its own coordinate."""
    return {canon.v_start[j] + i for j, kind in enumerate(canon.types)
            if kind in (JointType.BALL, JointType.FREE) for i in range(6 if kind is
                                                                       JointType.FREE else 3)}


def _hinge_maps(canon: Canonical, tree: ModelTree
                ) -> dict[int, Callable[[np.ndarray, np.ndarray], StateMap]]:
    """Per hinge or slide velocity index k, the map of that joint alone (a one-joint tree):
    along it only its own engine coordinates move (T and Ṫv do not), so a complex step
    along it need not map every joint."""
    from dyncheck.adapters.layout import mapper

    out = {}
    for joint, (name, kind) in enumerate(zip(canon.names, canon.types, strict=True)):
        if kind not in (JointType.HINGE, JointType.SLIDE):
            continue
        single = Canonical(names=(name,), types=(kind,), q_start=(0,), v_start=(0,), nq=1,
                           nv=1, zeros=(canon.zeros[joint],))
        mine = tree.joint(name)
        one = replace(tree, joints=(replace(mine, layout=replace(mine.layout, q_start=0,
                                                                 v_start=0)),),
                      nq=mine.layout.nq, nv=1)
        out[canon.v_start[joint]] = mapper(single, one)
    return out


def _along_hinge(canon: Canonical, tree: ModelTree, q: np.ndarray, v: np.ndarray, k: int,
                 h: float, single: Callable[[np.ndarray, np.ndarray], StateMap]
                 ) -> tuple[int, np.ndarray]:
    """d q_e / d q_k along hinge or slide ``k`` (``single``: its map alone, from
    :func:`_hinge_maps`): where in the engine's q, and the derivative of those coordinates
    (T and Ṫv do not move along it)."""
    joint = max(j for j in range(len(canon.types)) if canon.v_start[j] <= k)
    step = single(np.array([q[canon.q_start[joint]] + 1j * h]), v[k : k + 1])
    return tree.joint(canon.names[joint]).layout.q_start, step.q.imag / h


def same_layout(canon: Canonical, tree: ModelTree, states: States) -> bool:
    """Whether ``tree``'s layout is the canonical one at these states (q the same, T = I,
    Ṫv = 0: MuJoCo's own): then its tangent chart is the canonical chart."""
    from dyncheck.adapters.layout import mapper

    if tree.nq != canon.nq or tree.nv != canon.nv:
        return False
    state_map = mapper(canon, tree)
    for q, v in zip(states.q, states.v, strict=True):
        mapped = state_map(q, v)
        if not (np.array_equal(mapped.q, q) and np.array_equal(mapped.t, np.eye(canon.nv))
                and not np.any(mapped.tdot_v)):
            return False
    return True


def to_canonical(canon: Canonical, tree: ModelTree, states: States, found: Derivatives,
                 dynamics: Dynamics) -> Derivatives:
    """An engine's derivatives (its layout and chart; ``dynamics`` its own values at the same
    states: M, forward and inverse dynamics) in the canonical layout and chart, by the chain
    rule through the state map — τ = Tᵀ τ_e(q_e(q), T v, T v̇ + Ṫv) and
    v̇ = T⁻¹ (v̇_e(q_e(q), T v) − Ṫv) differentiated —, the map's own derivatives (dq_e, dT,
    d(Ṫv)) by a complex step."""
    from dyncheck.adapters.layout import mapper

    n, nv = states.v.shape
    out = {f: np.zeros((n, nv, nv)) for f in FIELDS}
    h = COMPLEX_STEP
    turning = _turning(canon)
    state_map = mapper(canon, tree)
    singles = _hinge_maps(canon, tree)
    for s in range(n):
        q, v, a = states.q[s : s + 1], states.v[s], states.a[s]
        base = state_map(q[0], v)
        t, t_inv = base.t, np.linalg.inv(base.t)
        mass, tau_e, f_e = (dynamics.mass_matrix[s], dynamics.inverse[s], dynamics.forward[s])
        f_c = t_inv @ (f_e - base.tdot_v)
        # the map's derivatives along every canonical direction k: dq_e (nq_e, k),
        # dT (k, nv_e, nv), d(Ṫv)/dq (nv_e, k), d(Ṫv)/dv (nv_e, k)
        d_q = np.zeros((len(base.q), nv))
        d_t = np.zeros((nv, *t.shape))
        d_tdot = np.zeros((len(base.tdot_v), nv))
        d_tdot_v = np.zeros((len(base.tdot_v), nv))
        for k in range(nv):
            if k not in turning:  # T and Ṫv move with a rotation only
                at, moved_q = _along_hinge(canon, tree, q[0], v, k, h, singles[k])
                d_q[at : at + len(moved_q), k] = moved_q
                continue
            moved = state_map(perturb(canon, q, k, 1j * h)[0], v)
            d_q[:, k] = moved.q.imag / h
            d_t[k], d_tdot[:, k] = moved.t.imag / h, moved.tdot_v.imag / h
            pushed = state_map(q[0], v + 1j * h * np.eye(nv)[k])  # Ṫv with its velocities
            d_tdot_v[:, k] = pushed.tdot_v.imag / h
        chi = _chart(tree, found.chart, base.q, d_q)  # (nv_e, k)
        dt_v = np.einsum("kij,j->ik", d_t, v)
        out["inverse_q"][s] = np.einsum("kji,j->ik", d_t, tau_e) + t.T @ (
            found.inverse_q[s] @ chi + found.inverse_v[s] @ dt_v
            + mass @ (np.einsum("kij,j->ik", d_t, a) + d_tdot))
        out["forward_q"][s] = -t_inv @ np.einsum("kij,j->ik", d_t, f_c) + t_inv @ (
            found.forward_q[s] @ chi + found.forward_v[s] @ dt_v - d_tdot)
        out["inverse_v"][s] = t.T @ (found.inverse_v[s] @ t + mass @ d_tdot_v)
        out["forward_v"][s] = t_inv @ (found.forward_v[s] @ t - d_tdot_v)
        out["forward_tau"][s] = t_inv @ found.forward_tau[s] @ t_inv.T
    return collect(out, method=found.method, step=found.step)


def skew(x: np.ndarray) -> np.ndarray:
    """[x]×: the matrix of x × ·."""
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def right_jacobian(phi: np.ndarray) -> np.ndarray:
    """SO(3)'s right Jacobian J_r(φ): exp(φ + δ) = exp(φ) exp(J_r(φ) δ) to first order."""
    theta = float(np.linalg.norm(phi))
    cross = skew(phi)
    if theta < 1e-8:
        return np.eye(3) - 0.5 * cross
    return (np.eye(3) - (1 - np.cos(theta)) / theta**2 * cross
            + (theta - np.sin(theta)) / theta**3 * cross @ cross)


def rotations(canon: Canonical) -> list[tuple[int, int]]:
    """(first velocity index, quaternion index) of every rotation: a ball joint's, a free
    joint's angular part (canonical: w first, turned on the right, body-frame δ)."""
    out = []
    for kind, qs, vs in zip(canon.types, canon.q_start, canon.v_start, strict=True):
        if kind is JointType.BALL:
            out.append((vs, qs))
        elif kind is JointType.FREE:
            out.append((vs + 3, qs + 3))
    return out
