"""The check's state map (:mod:`dyncheck.adapters.layout`) for a batch of real states at once:
the same formulas as the one-state map (:func:`~dyncheck.adapters.layout.state_map`, which a
complex step goes through), each state a row (tests/adapters/test_layout.py holds the two
equal over every layout variant)."""

from __future__ import annotations

import numpy as np

from dyncheck.adapters.layout import IDENTITY, StateMap, canonical_positions, mapper, quat_order
from dyncheck.adapters.model_tree import (
    Axes,
    Canonical,
    Dynamics,
    JointType,
    Layout,
    ModelTree,
    Orientation,
)
from dyncheck.cases.coordinate_maps import quat_from_matrix, quat_to_matrix
from dyncheck.cases.quaternions import quat_mul


def batch_map(canon: Canonical, tree: ModelTree, q_c: np.ndarray,
               v_c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_state_map` for every state at once (real states): q_e (n, nq_e), T (n, nv_e,
    nv), Ṫ v (n, nv_e) — the same formulas, batched (tests/check/test_layout.py holds the two
    equal)."""
    n = len(q_c)
    q_e = np.zeros((n, tree.nq))
    t = np.zeros((n, tree.nv, canon.nv))
    tdot_v = np.zeros((n, tree.nv))
    for name, kind, qs, vs, zero in zip(canon.names, canon.types, canon.q_start, canon.v_start,
                                        canon.zeros, strict=True):
        joint = tree.joint(name)
        lay = joint.layout
        qe, ve = lay.q_start, lay.v_start
        if kind in (JointType.HINGE, JointType.SLIDE):
            value = q_c[:, qs] - zero + lay.zero
            if lay.cos_sin:
                q_e[:, qe], q_e[:, qe + 1] = np.cos(value), np.sin(value)
            else:
                q_e[:, qe] = value
            t[:, ve, vs] = 1.0
        elif kind is JointType.BALL:
            rot = quat_to_matrix(q_c[:, qs : qs + 4])
            if lay.quat == Orientation.RPY:
                q_e[:, qe : qe + 3] = rpy_batch(rot)
            else:
                q_e[:, qe : qe + 4] = q_c[:, qs : qs + 4][:, quat_order(lay.quat)]
            t[:, ve : ve + 3, vs : vs + 3] = rot if lay.angular_axes is Axes.PARENT \
                else np.eye(3)
        else:
            place = quat_from_matrix(lay.placement[:3, :3].T[None])[0]
            q_e[:, qe : qe + 7], t[:, ve : ve + 6, vs : vs + 6], tdot_v[:, ve : ve + 6] = \
                free_batch(lay, place, q_c[:, qs : qs + 7], v_c[:, vs : vs + 6])
    return q_e, t, tdot_v


def back(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """T⁻¹ x at each state (T: (n, engine nv, canonical nv)); where the engine holds
    velocity coordinates beyond the canonical ones (Newton's loop joints, #78: constraints
    with coordinates of their own, which T never reaches), T's left inverse T⁺, exact for
    the x an engine gives there (zero on those coordinates)."""
    if t.shape[-1] == t.shape[-2]:
        return np.linalg.solve(t, x[..., None])[..., 0]
    return (np.linalg.pinv(t) @ x[..., None])[..., 0]


def canonical_states(canon: Canonical, tree: ModelTree, q_e: np.ndarray,
                     v_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Engine states (n, tree.nq), (n, tree.nv) back to canonical ones: the positions by
    :func:`~.layout.canonical_positions`, and v_c = T⁻¹ v_e with T at the canonical q found,
    every state at once (:func:`batch_map`)."""
    q_c = canonical_positions(canon, tree, q_e)
    if not len(q_c):
        return q_c, np.zeros((0, canon.nv))
    _, t, _ = batch_map(canon, tree, q_c, np.zeros((len(q_c), canon.nv)))
    return q_c, back(t, np.asarray(v_e, float))


def rpy_batch(rot: np.ndarray) -> np.ndarray:
    """:func:`rpy_from_matrix` for every state at once (real)."""
    pitch = np.arcsin(np.clip(-rot[:, 2, 0], -1.0, 1.0))
    locked = np.abs(rot[:, 2, 0]) > 1 - 1e-12
    roll = np.where(locked, 0.0, np.arctan2(rot[:, 2, 1], rot[:, 2, 2]))
    yaw = np.where(locked, np.arctan2(-rot[:, 0, 1], rot[:, 1, 1]),
                   np.arctan2(rot[:, 1, 0], rot[:, 0, 0]))
    return np.stack([roll, pitch, yaw], -1)


def free_batch(lay: Layout, place_quat: np.ndarray, q_c: np.ndarray,
                v_c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_free` for every state at once (real): the same formulas, each state's row."""
    n = len(q_c)
    p_w, quat_w = q_c[:, :3], q_c[:, 3:7]
    rot = quat_to_matrix(quat_w)
    r_o = lay.offset[:3, :3]
    offset = not np.array_equal(lay.offset, IDENTITY)
    place_r, place_p = lay.placement[:3, :3], lay.placement[:3, 3]
    origin = p_w + rot @ lay.offset[:3, 3] if offset else p_w
    p_e = (origin - place_p) @ place_r  # place_rᵀ x, row by row
    p_o = lay.offset[:3, 3] if lay.point is None else np.asarray(lay.point, float)
    turned = quat_mul(quat_w.T, quat_from_matrix(r_o[None])[0]).T if offset else quat_w
    quat_e = quat_mul(place_quat, turned.T).T[:, quat_order(lay.quat)]
    q_e = np.concatenate([quat_e, p_e] if lay.quat_first else [p_e, quat_e], axis=1)
    t = np.zeros((n, 6, 6))
    tdot_v = np.zeros((n, 6))
    lin = slice(3, 6) if lay.angular_first else slice(0, 3)
    ang = slice(0, 3) if lay.angular_first else slice(3, 6)
    omega = v_c[:, 3:6]
    cross_p = np.array([[0.0, -p_o[2], p_o[1]], [p_o[2], 0.0, -p_o[0]], [-p_o[1], p_o[0], 0.0]])
    centripetal = np.cross(omega, np.cross(omega, p_o))
    if lay.linear_axes is Axes.LOCAL:
        r_e = rot @ r_o
        t[:, lin, 0:3] = np.swapaxes(r_e, 1, 2)
        t[:, lin, 3:6] = -r_o.T @ cross_p
        linear = np.einsum("nij,nj->ni", t[:, lin, :], v_c)
        tdot_v[:, lin] = centripetal @ r_o - np.cross(omega @ r_o, linear)
    else:
        t[:, lin, 0:3] = np.eye(3)
        t[:, lin, 3:6] = -rot @ cross_p
        tdot_v[:, lin] = np.einsum("nij,nj->ni", rot, centripetal)
    t[:, ang, 3:6] = rot if lay.angular_axes is Axes.WORLD else r_o.T
    return q_e, t, tdot_v


def engine_states(
    canon: Canonical, tree: ModelTree, q: np.ndarray, v: np.ndarray, a: np.ndarray
) -> tuple[list[StateMap], np.ndarray, np.ndarray, np.ndarray]:
    """The batch in the engine's layout: maps, q_e, v_e, a_e (real states: every state at
    once, :func:`batch_map`; complex-stepped: one at a
    time, :func:`~dyncheck.adapters.layout.mapper`)."""
    if np.iscomplexobj(q) or np.iscomplexobj(v) or not len(q):
        one = mapper(canon, tree)
        maps = [one(qi, vi) for qi, vi in zip(q, v, strict=True)]
        q_e = np.array([s.q for s in maps])
        v_e = np.array([s.t @ vi for s, vi in zip(maps, v, strict=True)])
        a_e = np.array([s.t @ ai + s.tdot_v for s, ai in zip(maps, a, strict=True)])
        return maps, q_e, v_e, a_e
    q_e, t, tdot_v = batch_map(canon, tree, np.asarray(q, float), np.asarray(v, float))
    maps = [StateMap(q=qi, t=ti, tdot_v=di) for qi, ti, di in zip(q_e, t, tdot_v, strict=True)]
    v_e = (t @ np.asarray(v, float)[..., None])[..., 0]
    a_e = (t @ np.asarray(a, float)[..., None])[..., 0] + tdot_v
    return maps, q_e, v_e, a_e


def to_canonical(maps: list[StateMap], dyn: Dynamics) -> Dynamics:
    """An engine's dynamics in the canonical layout (see the module's docstring)."""
    if not maps:
        return dyn
    t = np.array([s.t for s in maps])
    tdot_v = np.array([s.tdot_v for s in maps])
    m_e = np.asarray(dyn.mass_matrix)
    # v_e = T v: accelerations map back by T⁻¹ (T is not orthogonal where a free joint's
    # velocity is that of an offset point); forces, duals, by Tᵀ
    t_t = np.swapaxes(t, 1, 2)
    return Dynamics(
        mass_matrix=t_t @ m_e @ t,
        bias=(t_t @ (dyn.bias + (m_e @ tdot_v[..., None])[..., 0])[..., None])[..., 0],
        forward=back(t, dyn.forward - tdot_v),
        inverse=(t_t @ np.asarray(dyn.inverse)[..., None])[..., 0],
        kinetic=dyn.kinetic, potential=dyn.potential, unavailable=dyn.unavailable,
    )
