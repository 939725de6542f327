"""Canonical states ↔ an engine's own layout, joint by joint, matched by name.

The canonical layout is MuJoCo's convention in the canonical joint order: a hinge or slide its
coordinate; a quaternion (w, x, y, z); a free joint q = (p, quat) as the world pose of its body,
v = (linear velocity in world axes, angular velocity in local axes); a ball joint v = angular
velocity in local axes (an engine may hold it in roll-pitch-yaw coordinates with v in the
parent-side frame: T = R there, and Ṫ v = 0). Each engine declares its own
(:class:`~dyncheck.adapters.model_tree.Layout`).

Velocities map linearly, v_e = T(q) v_c, with T orthogonal (a permutation of the joints'
blocks, and on a free joint's blocks R or Rᵀ or 1), so that — the kinetic energy and the power
τ·v being invariant — M_c = Tᵀ M_e T, τ_c = Tᵀ τ_e, and accelerations a_e = T a_c + Ṫ v_c, with
Ṫ v_c = −ω × (Rᵀ v_w) on a free joint's linear velocity held in local axes (the only block
whose T depends on q: d(Rᵀ)/dt = −ω̂ Rᵀ, ω in local axes).

This is the one home of these maps: a model check maps one state at a time (:func:`state_map`,
complex-stepped for its derivatives, with a free joint's placement and offset) from the
layouts the engine's own model declares, and a run's case many states at once
(:func:`engine_states`, :func:`canonical_states`) from its engine's tree;
:mod:`.joint_layouts` maps batches through the layouts a
:class:`~dyncheck.adapters.model_tree.StateLayout` declares (sympy.physics.mechanics's chart of
Example 9's angles; the run's quaternions renormalized). The engines'
layouts were found by experiment on the installed versions
(tests/adapters/test_state_layouts.py rotates a body by a known quaternion and reads the
result back):

- MuJoCo: ball-joint qpos (w, x, y, z), qvel ω in body axes; a free joint's qpos (p, w, x, y,
  z), qvel (v, ω), v of the body origin in *world* axes, ω in body axes (the canonical).
- Pinocchio (``JointModelSpherical``, from MJCF or URDF): q (x, y, z, w), v ω in the
  joint's local frame; its free-flyer q (p, x, y, z, w), v (v, ω) *both* in body axes: v_b =
  Rᵀ v_w, so T = diag(Rᵀ, 1) and Ṫ v = (−ω × v_b, 0) — the engine's v̇ is the derivative of
  body-frame components (the "spatial" acceleration Rᵀ p̈ − ω × v_b), not the body's
  acceleration.
- Drake: its MJCF parser turns a ball joint into ``BallRpyJoint``, q = (roll, pitch, yaw),
  v = ω in the parent's (here the world's) axes (T = R); a free joint into
  ``QuaternionFloatingJoint``, q = (w, x, y, z, p), v = (ω, v) both in world axes. Drake
  integrates the quaternion's components, so its norm drifts: :func:`from_engine`
  renormalizes.
- sympy-mechanics (dyncheck's own model): a rotating body in Example 9's angles (body Z, X,
  Z), velocities their rates, so v = J⁻¹ ω̄ (exercise 23) and v̇ picks up −J⁻¹ J̇ q̇ — its
  own chart, which it maps to the canonical layout itself (:mod:`.joint_layouts`): where the
  book has fewer coordinates than the engine (a point mass's spin), least squares and
  least-norm forces are then taken in the canonical coordinates, as for every engine.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.model_tree import (
    Axes,
    Canonical,
    Dynamics,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    TreeJoint,
)
from dyncheck.cases.coordinate_maps import quat_from_matrix, quat_to_matrix
from dyncheck.cases.quaternions import quat_conj, quat_mul, quat_of_rpy, quat_order, unit

IDENTITY = np.eye(4)


def rpy_from_matrix(rot: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw with R = R_z(yaw) R_y(pitch) R_x(roll) (any of the two solutions
    gives the same R; at pitch ±π/2 roll and yaw share one angle, chosen with roll 0)."""
    pitch = _asin(-rot[2, 0])
    if abs(rot[2, 0].real) > 1 - 1e-12:
        return np.array([0.0 * pitch, pitch, _atan2(-rot[0, 1], rot[1, 1])])
    return np.array([_atan2(rot[2, 1], rot[2, 2]), pitch, _atan2(rot[1, 0], rot[0, 0])])


def _atan2(y: complex, x: complex) -> complex:
    """arctan2, and under a complex step (tiny imaginary parts) its first-order extension
    (x dy − y dx)/(x² + y²): numpy's arctan2 takes no complex numbers."""
    yr, xr = float(np.real(y)), float(np.real(x))
    angle = np.arctan2(yr, xr)
    if not (np.iscomplexobj(y) or np.iscomplexobj(x)):
        return angle
    return angle + 1j * (xr * np.imag(y) - yr * np.imag(x)) / (xr * xr + yr * yr)


def _asin(z: complex) -> complex:
    """arcsin clipped to [−1, 1], with its first-order complex-step extension."""
    zr = float(np.clip(np.real(z), -1.0, 1.0))
    angle = np.arcsin(zr)
    if not np.iscomplexobj(z):
        return angle
    return angle + 1j * np.imag(z) / np.sqrt(max(1.0 - zr * zr, 1e-300))


@dataclass(frozen=True)
class StateMap:
    """One state's map: the engine's q, and T, Ṫ v_c for the velocities."""

    q: np.ndarray
    t: np.ndarray
    tdot_v: np.ndarray


def _state_map(
    canon: Canonical, joints: list[TreeJoint], placements: list[np.ndarray | None],
    tree: ModelTree, q_c: np.ndarray, v_c: np.ndarray,
) -> StateMap:
    """One state; ``joints`` are the engine's joints in canonical order, ``placements`` the
    quaternion of each free joint's placement inverse (None for other joints)."""
    kind_of = np.result_type(q_c, v_c, float)  # complex under a complex step (derivatives)
    q_e = np.zeros(tree.nq, kind_of)
    t = np.zeros((tree.nv, canon.nv), kind_of)
    tdot_v = np.zeros(tree.nv, kind_of)
    for joint, place_quat, kind, qs, vs, zero in zip(
        joints, placements, canon.types, canon.q_start, canon.v_start, canon.zeros, strict=True
    ):
        lay = joint.layout
        qe, ve = lay.q_start, lay.v_start
        if kind in (JointType.HINGE, JointType.SLIDE):
            value = q_c[qs] - zero + lay.zero
            if lay.cos_sin:
                q_e[qe : qe + 2] = np.cos(value), np.sin(value)
            else:
                q_e[qe] = value
            t[ve, vs] = 1.0
        elif kind is JointType.BALL and lay.quat == Orientation.RPY:
            rot = quat_to_matrix(q_c[None, qs : qs + 4])[0]
            q_e[qe : qe + 3] = rpy_from_matrix(rot)
            # ω in F = R ω in the child's axes; d/dt(R ω) = R ω̇ (Ṙ ω = R ω̂ ω = 0): Ṫ v = 0
            t[ve : ve + 3, vs : vs + 3] = rot if lay.angular_axes is Axes.PARENT else np.eye(3)
        elif kind is JointType.BALL:
            q_e[qe : qe + 4] = q_c[qs : qs + 4][quat_order(lay.quat)]
            # ω in the parent-side frame = R ω in the child's axes; Ṫ v = 0 as above
            t[ve : ve + 3, vs : vs + 3] = (quat_to_matrix(q_c[None, qs : qs + 4])[0]
                                           if lay.angular_axes is Axes.PARENT else np.eye(3))
        else:
            q_e[qe : qe + 7], t_free, tdot_v[ve : ve + 6] = _free(
                lay, place_quat, q_c[qs : qs + 7], v_c[vs : vs + 6])
            t[ve : ve + 6, vs : vs + 6] = t_free
    return StateMap(q=q_e, t=t, tdot_v=tdot_v)


def _free(lay: Layout, place_quat: np.ndarray, q_c: np.ndarray,
          v_c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A free joint's q, T and Ṫ v in the engine's layout, from the canonical (p, quat) of
    the body's frame and v = (linear velocity of its origin, world axes; ω, body axes).

    The engine's q holds the pose of the frame O = ``lay.offset`` fixed in the body (R_o,
    origin o): p = p_w + R o, R_O = R R_o; its linear velocity is that of the body's point
    p_o (``lay.point``, else o), v_O = v + R (ω × p_o) (world axes; in O's axes R_Oᵀ v_O), its
    angular velocity R ω (world) or R_oᵀ ω (O's axes). Ṫ v holds the terms of the engine's
    acceleration that are not T v̇: R (ω × (ω × p_o)), and −ω_O × v_O in O's rotating axes."""
    p_w, quat_w = q_c[:3], q_c[3:7]
    rot = quat_to_matrix(quat_w[None])[0]
    r_o = lay.offset[:3, :3]
    offset = not np.array_equal(lay.offset, IDENTITY)  # most engines: q holds the body frame
    place_r, place_p = lay.placement[:3, :3], lay.placement[:3, 3]
    p_e = place_r.T @ (p_w + rot @ lay.offset[:3, 3] - place_p) if offset else \
        place_r.T @ (p_w - place_p)
    p_o = lay.offset[:3, 3] if lay.point is None else np.asarray(lay.point, float)
    turned = quat_mul(quat_w, quat_from_matrix(r_o[None])[0]) if offset else quat_w
    quat_e = quat_mul(place_quat, turned)[quat_order(lay.quat)]
    q_e = np.concatenate([quat_e, p_e]) if lay.quat_first else np.concatenate([p_e, quat_e])
    kind_of = np.result_type(q_c, v_c, float)
    t = np.zeros((6, 6), kind_of)
    tdot_v = np.zeros(6, kind_of)
    lin = slice(3, 6) if lay.angular_first else slice(0, 3)
    ang = slice(0, 3) if lay.angular_first else slice(3, 6)
    omega = v_c[3:6]
    cross_p = np.array([[0.0, -p_o[2], p_o[1]], [p_o[2], 0.0, -p_o[0]], [-p_o[1], p_o[0], 0.0]])
    centripetal = np.cross(omega, np.cross(omega, p_o))
    if lay.linear_axes is Axes.LOCAL:
        r_e = rot @ r_o
        t[lin, 0:3] = r_e.T
        t[lin, 3:6] = -r_o.T @ cross_p
        tdot_v[lin] = r_o.T @ centripetal - np.cross(r_o.T @ omega, t[lin] @ v_c)
    else:
        t[lin, 0:3] = np.eye(3)
        t[lin, 3:6] = -rot @ cross_p
        tdot_v[lin] = rot @ centripetal
    t[ang, 3:6] = rot if lay.angular_axes is Axes.WORLD else r_o.T
    return q_e, t, tdot_v


def mapper(canon: Canonical, tree: ModelTree) -> Callable[[np.ndarray, np.ndarray], StateMap]:
    """One state's map into ``tree``'s layout as a function of (q_c, v_c) (real, or
    complex under a complex step), the engine's joints and placements looked up once."""
    joints = [tree.joint(name) for name in canon.names]
    placements = [
        quat_from_matrix(j.layout.placement[:3, :3].T[None])[0]
        if kind is JointType.FREE else None
        for j, kind in zip(joints, canon.types, strict=True)
    ]
    return lambda q_c, v_c: _state_map(canon, joints, placements, tree, q_c, v_c)


def state_map(canon: Canonical, tree: ModelTree, q_c: np.ndarray,
              v_c: np.ndarray) -> StateMap:
    """One state's map into ``tree``'s layout (real, or complex under a complex step)."""
    return mapper(canon, tree)(q_c, v_c)


def canonical_positions(canon: Canonical, tree: ModelTree, q_e: np.ndarray) -> np.ndarray:
    """Engine positions (n, tree.nq) back to canonical ones: :func:`state_map` inverted joint
    by joint (a free joint's placement and offset undone, a quaternion renormalized where its
    norm drifted beyond the rounding of the engine's arithmetic, ``tree.eps``:
    :func:`~dyncheck.cases.quaternions.unit`)."""
    joints = [tree.joint(name) for name in canon.names]
    q_c = np.zeros((len(q_e), canon.nq))
    for joint, kind, qs, zero in zip(joints, canon.types, canon.q_start, canon.zeros,
                                     strict=True):
        lay = joint.layout
        chunk = q_e[:, lay.q_start : lay.q_start + lay.nq]
        if kind in (JointType.HINGE, JointType.SLIDE):
            value = np.arctan2(chunk[:, 1], chunk[:, 0]) if lay.cos_sin else chunk[:, 0]
            q_c[:, qs] = value - lay.zero + zero
        elif kind is JointType.BALL:
            q_c[:, qs : qs + 4] = quat_of_rpy(chunk) if lay.quat is Orientation.RPY else \
                unit(chunk[:, np.argsort(quat_order(lay.quat))], tree.eps)
        else:
            q_c[:, qs : qs + 7] = _free_back(lay, chunk, tree.eps)
    return q_c


def _free_back(lay: Layout, q_e: np.ndarray, eps: float = 0.0) -> np.ndarray:
    """A free joint's canonical (p, quat) (n, 7) from its q (n, 7) in the engine's layout
    (:func:`_free` inverted: quat_e = P⁻¹ ⊗ quat ⊗ q(R_o), p_e = P_r⁻¹ (p + R o − P_p)),
    every state at once: the placement's and offset's quaternions are the joint's."""
    quat_e, p_e = (q_e[:, :4], q_e[:, 4:]) if lay.quat_first else (q_e[:, 3:], q_e[:, :3])
    quat_e = unit(quat_e[:, np.argsort(quat_order(lay.quat))], eps)
    place_r, place_p = lay.placement[:3, :3], lay.placement[:3, 3]
    turned = quat_mul(quat_from_matrix(place_r[None])[0][:, None], quat_e.T)
    undo = quat_conj(quat_from_matrix(lay.offset[None, :3, :3])[0])[:, None]
    quat_w = quat_mul(turned, undo).T
    p_w = np.einsum("ij,nj->ni", place_r, p_e) + place_p
    if np.any(lay.offset[:3, 3]):  # (a case's free body has none: no rotation needed)
        p_w = p_w - np.einsum("nij,j->ni", quat_to_matrix(quat_w), lay.offset[:3, 3])
    return np.concatenate([p_w, quat_w], axis=1)


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
