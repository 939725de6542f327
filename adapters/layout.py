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
layouts the engine's own model declares; a run's case maps batches (:func:`to_engine`,
:func:`from_engine`, :func:`velocity_frames`, :func:`velocity_frame_rates`) from the layouts
a :class:`~dyncheck.adapters.model_tree.StateLayout` declares (the case's coordinate map into
the canonical layout; sympy.physics.mechanics's chart of Example 9's angles). The engines'
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
  Z), velocities their rates, so v = J⁻¹ ω̄ (exercise 23) and v̇ picks up −J⁻¹ J̇ q̇. Where
  the book has fewer coordinates than the engine (a point mass's spin), least squares and
  least-norm forces are taken in the canonical metric W = T⁻ᵀT⁻¹, not in the angle rates'.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.model_tree import (
    Axes,
    Canonical,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    TreeJoint,
)
from dyncheck.cases.coordinate_maps import EulerAngleMap, quat_from_matrix, quat_to_matrix
from dyncheck.cases.quaternions import quat_conj, quat_mul

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


def quat_order(quat: Orientation) -> list[int]:
    """Where an engine's quaternion components come from in (w, x, y, z): q_engine =
    q_wxyz[..., quat_order(quat)], and back through its ``np.argsort``."""
    return ["wxyz".index(c) for c in str(quat)]


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
    :func:`_unit`)."""
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
            q_c[:, qs : qs + 4] = _quat_of_rpy(chunk) if lay.quat is Orientation.RPY else \
                _unit(chunk[:, np.argsort(quat_order(lay.quat))], tree.eps)
        else:
            q_c[:, qs : qs + 7] = _free_back(lay, chunk, tree.eps)
    return q_c


def _free_back(lay: Layout, q_e: np.ndarray, eps: float = 0.0) -> np.ndarray:
    """A free joint's canonical (p, quat) (n, 7) from its q (n, 7) in the engine's layout
    (:func:`_free` inverted: quat_e = P⁻¹ ⊗ quat ⊗ q(R_o), p_e = P_r⁻¹ (p + R o − P_p)),
    every state at once: the placement's and offset's quaternions are the joint's."""
    quat_e, p_e = (q_e[:, :4], q_e[:, 4:]) if lay.quat_first else (q_e[:, 3:], q_e[:, :3])
    quat_e = _unit(quat_e[:, np.argsort(quat_order(lay.quat))], eps)
    place_r, place_p = lay.placement[:3, :3], lay.placement[:3, 3]
    turned = quat_mul(quat_from_matrix(place_r[None])[0][:, None], quat_e.T)
    undo = quat_conj(quat_from_matrix(lay.offset[None, :3, :3])[0])[:, None]
    quat_w = quat_mul(turned, undo).T
    p_w = np.einsum("ij,nj->ni", place_r, p_e) + place_p
    if np.any(lay.offset[:3, 3]):  # (a case's free body has none: no rotation needed)
        p_w = p_w - np.einsum("nij,j->ni", quat_to_matrix(quat_w), lay.offset[:3, 3])
    return np.concatenate([p_w, quat_w], axis=1)


# Batched maps for the run's cases: canonical states (n, nq) and (n, nv) in the canonical
# joint order, to and from an engine whose joints are laid out one after another
# (:meth:`~dyncheck.adapters.model_tree.StateLayout.joints`). The same conventions as
# :func:`state_map`, for many states at once (a trajectory's), without the check's
# placements and offsets (a case's free body is its own frame, placed at the origin).


def _rotating(kinds: Sequence[JointType]) -> bool:
    return any(JointType(k).rotating for k in kinds)


def _rpy_of(rot: np.ndarray) -> np.ndarray:
    """(roll, pitch, yaw) with R = R_z(yaw) R_y(pitch) R_x(roll), batched (real: the run's
    states; :func:`rpy_from_matrix` takes one state, complex-stepped or not)."""
    return np.stack(
        [
            np.arctan2(rot[:, 2, 1], rot[:, 2, 2]),
            np.arcsin(np.clip(-rot[:, 2, 0], -1.0, 1.0)),
            np.arctan2(rot[:, 1, 0], rot[:, 0, 0]),
        ],
        -1,
    )


def _quat_of_rpy(rpy: np.ndarray) -> np.ndarray:
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


def _unit(quat: np.ndarray, eps: float = 0.0) -> np.ndarray:
    """Engines that integrate quaternion components (Drake) let the norm drift: renormalize
    where it drifted beyond :data:`UNIT_ROUNDING` ε of the engine's arithmetic (``eps``; 0:
    always). A quaternion the engine normalized is its own: a float32 port's, whose norm is
    1 to ε₃₂, carries its round-off into the comparison as the engine computed it."""
    norm = np.linalg.norm(quat, axis=-1, keepdims=True)
    return np.where(np.abs(norm - 1.0) <= UNIT_ROUNDING * eps, quat, quat / norm)


def to_engine(layouts: Sequence[Layout], kinds: Sequence[JointType],
              q_c: np.ndarray) -> np.ndarray:
    """Canonical positions (quaternions (w, x, y, z); a free joint's position first) to the
    engine's (each joint's orientation and order as its layout says), batched."""
    if not _rotating(kinds):
        return q_c
    cols, i = [], 0
    for lay, kind in zip(layouts, map(JointType, kinds), strict=True):
        chunk = q_c[:, i : i + kind.nq]
        if kind is JointType.BALL:
            if lay.quat is Orientation.RPY:
                cols.append(_rpy_of(quat_to_matrix(chunk)))
            elif lay.quat is Orientation.EULER:
                cols.append(EulerAngleMap().to_book(chunk))
            else:
                cols.append(chunk[:, quat_order(lay.quat)])
        elif kind is JointType.FREE and lay.quat is Orientation.EULER:
            cols.extend([chunk[:, :3], EulerAngleMap().to_book(chunk[:, 3:])])
        elif kind is JointType.FREE:
            quat = chunk[:, 3:][:, quat_order(lay.quat)]
            cols.extend([quat, chunk[:, :3]] if lay.quat_first else [chunk[:, :3], quat])
        else:
            cols.append(chunk)
        i += kind.nq
    return np.concatenate(cols, -1)


def from_engine(layouts: Sequence[Layout], kinds: Sequence[JointType],
                q_e: np.ndarray) -> np.ndarray:
    """The engine's positions back to canonical ones (:func:`to_engine` inverted), batched;
    quaternions renormalized."""
    if not _rotating(kinds):
        return q_e
    cols = []
    for lay, kind in zip(layouts, map(JointType, kinds), strict=True):
        chunk = q_e[:, lay.q_start : lay.q_start + lay.nq]
        if kind is JointType.BALL and lay.quat is Orientation.RPY:
            cols.append(_quat_of_rpy(chunk))
        elif kind.rotating and lay.quat is Orientation.EULER:
            if kind is JointType.FREE:
                cols.append(chunk[:, :3])
            cols.append(EulerAngleMap().to_engine(chunk[:, -3:]))
        elif kind is JointType.BALL:
            cols.append(_unit(chunk[:, np.argsort(quat_order(lay.quat))]))
        elif kind is JointType.FREE:
            quat, pos = (chunk[:, :4], chunk[:, 4:]) if lay.quat_first else \
                (chunk[:, 3:], chunk[:, :3])
            cols.extend([pos, _unit(quat[:, np.argsort(quat_order(lay.quat))])])
        else:
            cols.append(chunk)
    return np.concatenate(cols, -1)


def _canonical_velocities(lay: Layout, kind: JointType) -> bool:
    if kind is JointType.BALL:
        return lay.angular_axes is Axes.LOCAL
    if kind is JointType.FREE:
        return lay.linear_axes is Axes.WORLD and lay.angular_axes is Axes.LOCAL \
            and not lay.angular_first
    return True


def velocity_frames(layouts: Sequence[Layout], kinds: Sequence[JointType],
                    q_c: np.ndarray) -> np.ndarray | None:
    """T(q) with v_engine = T v_canonical (canonical states, batched (n, nv, nv)), or None
    where every joint's velocities are the canonical ones: a ball joint's ω in world or parent
    axes (T = R), a free joint's linear velocity in body axes (Rᵀ) or its ω in world axes (R),
    an Euler chart's angle rates (J⁻¹, exercise 23 inverted)."""
    kinds = [JointType(k) for k in kinds]
    if all(_canonical_velocities(lay, k) for lay, k in zip(layouts, kinds, strict=True)):
        return None
    nv = sum(k.nv for k in kinds)
    t = np.broadcast_to(np.eye(nv), (q_c.shape[0], nv, nv)).copy()
    i = k = 0
    for lay, kind in zip(layouts, kinds, strict=True):
        if kind.rotating and lay.angular_axes is Axes.RATES:
            a, b = (i + 3, k + 3) if kind is JointType.FREE else (i, k)
            angles = EulerAngleMap().to_book(q_c[:, a : a + 4])
            t[:, b : b + 3, b : b + 3] = np.linalg.inv(EulerAngleMap().jacobian(angles))
        elif kind is JointType.BALL and lay.angular_axes in (Axes.WORLD, Axes.PARENT):
            t[:, k : k + 3, k : k + 3] = quat_to_matrix(q_c[:, i : i + 4])
        elif kind is JointType.FREE:
            rot = quat_to_matrix(q_c[:, i + 3 : i + 7])
            lin = np.swapaxes(rot, -1, -2) if lay.linear_axes is Axes.LOCAL else \
                np.broadcast_to(np.eye(3), rot.shape)
            ang = rot if lay.angular_axes is Axes.WORLD else np.broadcast_to(np.eye(3), rot.shape)
            t[:, k : k + 6, k : k + 6] = 0.0
            if lay.angular_first:
                t[:, k : k + 3, k + 3 : k + 6] = ang
                t[:, k + 3 : k + 6, k : k + 3] = lin
            else:
                t[:, k : k + 3, k : k + 3] = lin
                t[:, k + 3 : k + 6, k + 3 : k + 6] = ang
        i += kind.nq
        k += kind.nv
    return t


def velocity_frame_rates(layouts: Sequence[Layout], kinds: Sequence[JointType],
                         q_c: np.ndarray, v_c: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Ṫ v for canonical states and velocities, given T = :func:`velocity_frames` there:
    (−ω × Rᵀ v_w, 0) for a free joint whose linear velocity is in body axes; R ω̄ in world
    axes has Ṙ ω̄ = R (ω̄ × ω̄) = 0; an Euler chart's −J⁻¹ J̇ q̇ (the chart's own (2.2.5)
    term, d/dt (J⁻¹ ω̄) with q̇ = J⁻¹ ω̄)."""
    out = np.zeros_like(v_c)
    i = k = 0
    for lay, kind in zip(layouts, map(JointType, kinds), strict=True):
        if kind.rotating and lay.angular_axes is Axes.RATES:
            a, b = (i + 3, k + 3) if kind is JointType.FREE else (i, k)
            angles = EulerAngleMap().to_book(q_c[:, a : a + 4])
            tb = t[:, b : b + 3, b : b + 3]
            qdot = np.einsum("nij,nj->ni", tb, v_c[:, b : b + 3])
            out[:, b : b + 3] = -np.einsum(
                "nij,nj->ni", tb, EulerAngleMap().hessian_term(angles, qdot))
        elif kind is JointType.FREE and lay.linear_axes is Axes.LOCAL:
            rot = quat_to_matrix(q_c[:, i + 3 : i + 7])
            vb = np.einsum("nji,nj->ni", rot, v_c[:, k : k + 3])
            out[:, k : k + 3] = -np.cross(v_c[:, k + 3 : k + 6], vb)
        i += kind.nq
        k += kind.nv
    return out
