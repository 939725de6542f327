"""A batch of canonical states in a sequence of joint layouts and back: canonical states (n, nq)
and (n, nv) in the canonical joint order, to and from coordinates whose joints are laid out
one after another (:meth:`~dyncheck.adapters.model_tree.StateLayout.joints`): a quaternion's
order, roll-pitch-yaw or Example 9's angles, and the frames (or angle rates) of a rotating
joint's velocities, v = T v_canonical. The conventions of :mod:`.layout`'s tree maps, for
many states at once, without a model check's placements and offsets (a case's free body is
its own frame, placed at the origin): sympy.physics.mechanics's chart
(:class:`~dyncheck.adapters.sympy_mechanics.tree.Chart`), and the run's coordinate map's
quaternions renormalized (:class:`dyncheck.coordinates.NativeMap`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dyncheck.adapters.model_tree import Axes, JointType, Layout, Orientation
from dyncheck.cases.coordinate_maps import EulerAngleMap, quat_to_matrix
from dyncheck.cases.quaternions import quat_of_rpy, quat_order, unit


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
            cols.append(quat_of_rpy(chunk))
        elif kind.rotating and lay.quat is Orientation.EULER:
            if kind is JointType.FREE:
                cols.append(chunk[:, :3])
            cols.append(EulerAngleMap().to_engine(chunk[:, -3:]))
        elif kind is JointType.BALL:
            cols.append(unit(chunk[:, np.argsort(quat_order(lay.quat))]))
        elif kind is JointType.FREE:
            quat, pos = (chunk[:, :4], chunk[:, 4:]) if lay.quat_first else \
                (chunk[:, 3:], chunk[:, :3])
            cols.extend([pos, unit(quat[:, np.argsort(quat_order(lay.quat))])])
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
