"""Recursive Newton–Euler on a tree of rigid bodies: §2.2's momentum laws applied body by body,
the referee's O(n) algorithm for derivatives beside the general method of
:mod:`dyncheck.reference.tree` (Lagrange (2.2.23)–(2.2.24)), which stays the root of trust:
the comparison layer ties the two together on every model it checks.

Each body's linear momentum G = m ċ and angular momentum H obey dG/dt = F (2.2.48) and
dH/dt = M (2.2.49) — in the body's own axes Euler's equations (2.2.70). Written here in world
axes about the world origin O, a body's velocity is the pair V = (ω, v_O) (v_O the velocity of
the body point passing through O, so ċ = v_O + ω × c), its momentum (H_O, G) with
G = m(v_O + ω × c) and H_O = I_c ω + c × G, and the two laws together read

    (M_O, F) = d/dt (H_O, G) = 𝕀 A + V ×* 𝕀 V,    A = dV/dt,

with ×* the cross product of a velocity with a momentum, (ω, v) ×* (n, f) =
(ω × n + v × f, ω × f). Outward from the root, each joint adds its own motion: V = V_parent +
S v_j (S the joint's columns: a rotation w about a point p is (w, p × w), a translation w is
(0, w)), A = A_parent + S v̇_j + Ṡ v_j; inward, each body's force is its own plus what its
children need, and the joint takes its share τ_j = Sᵀ F (a rotation's: the moment about its
pivot). Gravity enters as the root's acceleration (0, −𝐠): the same forces as the weights
m 𝐠 at the centres of mass. M comes from composite bodies (each joint's column against the
inertia of everything it carries, the same sums).

Inputs and layout as :class:`~dyncheck.reference.tree.TreeDynamics` (world axes at the
reference configuration; MuJoCo's coordinates: a free joint (p, w x y z) in its parent's
axes with velocity (linear in those axes, body angular), a ball's velocity in its child's
axes). Every operation is analytic (rotations by sin and cos, a quaternion normalised by
q·q, not |q|²), so the algorithm runs on complex numbers: a complex step through it gives its
derivatives exactly to round-off.
"""

from __future__ import annotations

import numpy as np

from dyncheck.reference.tree import NQ, NV, Tree, hat, rotation


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z), not necessarily unit, → (..., 3, 3) rotations,
    analytic in q (normalised by s = q·q, no modulus: a complex step passes through)."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    two = 2.0 / (w * w + x * x + y * y + z * z)
    return np.stack(
        [
            np.stack([1 - two * (y * y + z * z), two * (x * y - w * z), two * (x * z + w * y)], -1),
            np.stack([two * (x * y + w * z), 1 - two * (x * x + z * z), two * (y * z - w * x)], -1),
            np.stack([two * (x * z - w * y), two * (y * z + w * x), 1 - two * (x * x + y * y)], -1),
        ],
        -2,
    )


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis (..., 3), broadcast; numpy's ``cross`` without its axis
    bookkeeping, which costs more than the arithmetic on these small vectors."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], -1)


def _motion_cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(ω, v) × (ω₂, v₂) = (ω × ω₂, ω × v₂ + v × ω₂): how a motion b changes seen from a
    frame moving with a; (..., 6)."""
    w, v = a[..., :3], a[..., 3:]
    return np.concatenate([_cross(w, b[..., :3]),
                           _cross(w, b[..., 3:]) + _cross(v, b[..., :3])], -1)


def _force_cross(a: np.ndarray, f: np.ndarray) -> np.ndarray:
    """(ω, v) ×* (n, f) = (ω × n + v × f, ω × f): the rate of a momentum carried with a;
    (..., 6)."""
    w, v = a[..., :3], a[..., 3:]
    return np.concatenate([_cross(w, f[..., :3]) + _cross(v, f[..., 3:]),
                           _cross(w, f[..., 3:])], -1)


def _spatial_inertia(mass: float, com: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """(..., 6, 6): 𝕀 (ω, v_O) = (H_O, G) for a body of ``mass``, centre ``com`` and inertia
    about it ``inertia`` (world axes): [[I_c + m ĉ ĉᵀ, m ĉ], [m ĉᵀ, m 1]]."""
    c = hat(com)
    ct = np.swapaxes(c, -1, -2)
    top = np.concatenate([inertia + mass * c @ ct, mass * c], -1)
    bottom = np.concatenate([mass * ct, np.broadcast_to(mass * np.eye(3), c.shape)], -1)
    return np.concatenate([top, bottom], -2)


def _apply_inertia(mass: float, com: np.ndarray, inertia: np.ndarray,
                   motion: np.ndarray) -> np.ndarray:
    """𝕀 (α, a_O) = (I_c α + c × G, G), G = m (a_O + α × c): a body's momentum for a
    velocity, or the rate of it for an acceleration; com (B, 3), inertia (B, 3, 3),
    motion (..., B, 6)."""
    turn = motion[..., :3]
    linear = mass * (motion[..., 3:] + _cross(turn, com))
    return np.concatenate([(inertia @ turn[..., None])[..., 0]
                           + _cross(com, linear), linear], -1)


def _positions(have: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Where each of ``wanted`` (indices of states) sits among the rows of a body evaluated
    on ``have`` (sorted) and then its base: its own row, or the base row (``len(have)``)."""
    at = np.searchsorted(have, wanted)
    found = (at < len(have)) & (have[np.minimum(at, max(len(have) - 1, 0))] == wanted) \
        if len(have) else np.zeros(len(wanted), bool)
    return np.where(found, at, len(have))


class RecursiveDynamics(Tree):
    """Inverse dynamics τ(q, v, v̇), M by composite bodies, h, T and V of a tree of
    :class:`Body` records, batched over rows of states (real or complex)."""

    def _joint(self, j: int, rp: np.ndarray, tp: np.ndarray, qj: np.ndarray, *,
               absolute: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Body j's rotation R (..., 3, 3) and translation t (..., 3) from the reference
        configuration (a point x there is now at R x + t), and its joint's columns S
        (..., 6, k) in world axes, from its parent's (``rp``, ``tp``) and its own coordinates
        ``qj`` (..., nq_j). Positions are taken from the root joint's point of the body's
        subtree (its anchor; a free body's origin), unless ``absolute``: uniform gravity makes
        the dynamics the same about any point, and lever arms that are differences of
        nearby positions keep their digits wherever the model stands (about the world
        origin, a model 10⁶ m away would lose twelve)."""
        body = self.bodies[j]
        if body.parent < 0 and not absolute:
            tp = tp - np.asarray(body.anchor, float)
        pivot = rp @ body.anchor + tp
        if body.kind in ("hinge", "slide"):
            axis = rp @ np.asarray(body.axis, float)
            if body.kind == "hinge":
                rot = rp @ rotation(body.axis, qj[..., 0] - body.zero)
                return (rot, pivot - rot @ body.anchor,
                        np.concatenate([axis, _cross(pivot, axis)], -1)[..., None])
            return (rp, tp + (qj[..., :1] - body.zero) * axis,
                    np.concatenate([np.zeros_like(axis), axis], -1)[..., None])
        if body.kind == "ball":
            current = body.frame @ quat_matrix(qj)
            rot = rp @ current @ body.frame.T
            w = rp @ current  # the child's axes: its velocity's columns
            return (rot, pivot - rot @ body.anchor,
                    np.concatenate([w, np.cross(pivot[..., None], w, axis=-2)], -2))
        # free: a pose in the parent's axes (the world's at the root), velocity (the anchor's
        # linear in the parent's axes, body angular relative to the parent)
        world = rp @ quat_matrix(qj[..., 3:7])
        if body.parent >= 0:
            position = (rp @ qj[..., :3, None])[..., 0] + tp
        else:  # (broadcast to the parent's rows; about its own origin unless absolute)
            position = (qj[..., :3] if absolute else 0 * qj[..., :3]) + 0 * tp
        rot = world @ body.frame.T
        eye = np.broadcast_to(rp, world.shape)
        linear = np.concatenate([np.zeros_like(eye), eye], -2)
        angular = np.concatenate([world, np.cross(position[..., None], world, axis=-2)], -2)
        return rot, position - rot @ body.anchor, np.concatenate([linear, angular], -1)

    def _kinematics(self, q: np.ndarray, *, absolute: bool = False
                    ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Per body, :meth:`_joint` at rows q (B, nq)."""
        out: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        rows = len(q)
        for j, body in enumerate(self.bodies):
            qs = self.q_start[j]
            if body.parent >= 0:
                rp, tp, _ = out[body.parent]
            else:
                rp, tp = np.broadcast_to(np.eye(3), (rows, 3, 3)), np.zeros((rows, 3))
            out.append(self._joint(j, rp, tp, q[:, qs : qs + NQ[body.kind]],
                                   absolute=absolute))
        return out

    def _outward(self, j: int, cols: np.ndarray, parent: tuple[np.ndarray, np.ndarray] | None,
                 root: np.ndarray, vj: np.ndarray, aj: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Body j's velocity V = V_parent + S v_j and acceleration A = A_parent + S v̇_j +
        Ṡ v_j ((..., 6) each) — Ṡ v_j = V_parent × S v_j for columns fixed in a body, and
        ṗ × ω for a free joint's translation, whose columns are its parent's axes."""
        motion = (cols @ vj[..., None])[..., 0]
        if parent is not None:
            vp, ap = parent
            vel, acc = vp + motion, ap + _motion_cross(vp, motion)
        else:
            vel, acc = motion, root
        acc = acc + (cols @ aj[..., None])[..., 0]
        if self.bodies[j].kind == "free":  # its translation's columns: the parent's axes
            slid = (cols[..., 3:, :3] @ vj[..., :3, None])[..., 0]
            acc = acc + np.concatenate([np.zeros_like(slid), _cross(slid, motion[..., :3])], -1)
        return vel, acc

    def _force(self, j: int, rot: np.ndarray, trans: np.ndarray, vel: np.ndarray,
               acc: np.ndarray) -> np.ndarray | None:
        """Body j's (M_O, F) = 𝕀 A + V ×* 𝕀 V (..., 6), None where it carries nothing."""
        placed = self._placed(j, rot, trans)
        if placed is None:
            return None
        com, inertia = placed
        mass = self.bodies[j].mass
        momentum = _apply_inertia(mass, com, inertia, vel)
        return _apply_inertia(mass, com, inertia, acc) + _force_cross(vel, momentum)

    def inverse_along(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, columns: np.ndarray,
                      *, q_along: np.ndarray | None = None, v_along: np.ndarray | None = None,
                      gravity: bool = True) -> np.ndarray:
        """τ at K states, each the base state (q (B, nq); v, v̇ = ``a`` (..., B, nv)) moved
        along one velocity column ``columns[d]`` (K,): its coordinates from ``q_along``
        (K, B, nq) and its velocities from ``v_along`` (K, ..., B, nv), which differ from the
        base in that column's joint only (a complex step, a step along a chart). Such a
        move changes only the joint's subtree: each body is evaluated on the states whose
        column is its own or an ancestor's and once at the base, the forces summed inward
        over every state; the work is Σ_bodies (ancestors' columns), not bodies × columns.
        Returns (K, ..., B, nv)."""
        rows = len(q)
        lead = np.broadcast_shapes(v.shape, a.shape)[:-2]
        dtype = np.result_type(q, v, a, float, *(x for x in (q_along, v_along) if x is not None))
        k_all = len(columns)
        root = np.zeros((*lead, 1, rows, 6), dtype)
        if gravity:
            root[..., 3:] = -self.gravity
        a = np.broadcast_to(a, (*lead, rows, self.nv))
        v = np.broadcast_to(v, (*lead, rows, self.nv))
        if v_along is not None:  # (K, ..., B, nv) → (..., K, B, nv)
            v_along = np.moveaxis(np.broadcast_to(v_along, (k_all, *lead, rows, self.nv)), 0,
                                  -3)
        sel, state, force_rows = self._outward_along(q, v, a, columns, root=root,
                                                     q_along=q_along, v_along=v_along)
        tau = self._inward_along(sel, state, force_rows, shape=(*lead, k_all, rows, self.nv),
                                 dtype=dtype, moved=q_along is not None)
        return np.moveaxis(tau + self.armature * a[..., None, :, :], -3, 0)

    def _outward_along(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, columns: np.ndarray,
                       *, root: np.ndarray, q_along: np.ndarray | None,
                       v_along: np.ndarray | None) -> tuple[list[np.ndarray], list, list]:
        """:meth:`inverse_along`'s outward pass: per body, the states (indices into K) it is
        evaluated on (its ancestors' columns; its base last), its pose, columns, velocity and
        acceleration on them, and its force (v, a broadcast to (..., B, nv); v_along moved to
        (..., K, B, nv))."""
        rows, lead = len(q), v.shape[:-2]
        sel: list[np.ndarray] = []  # per body: the states (indices into K) it is evaluated on
        state: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        force_rows: list[np.ndarray | None] = []
        for j, body in enumerate(self.bodies):
            mine = np.flatnonzero(np.isin(columns, self.ancestor_columns[j]))
            sel.append(mine)
            qs, vs, own = self.q_start[j], self.v_start[j], NV[body.kind]
            qj = q[None, :, qs : qs + NQ[body.kind]]
            if q_along is not None:
                qj = np.concatenate([q_along[mine, :, qs : qs + NQ[body.kind]], qj])
            vj = v[..., None, :, vs : vs + own]
            if v_along is not None:
                vj = np.concatenate([v_along[..., mine, :, vs : vs + own], vj], -3)
            else:
                vj = np.broadcast_to(vj, (*lead, len(mine) + 1, rows, own))
            aj = a[..., None, :, vs : vs + own]
            if body.parent >= 0:  # the parent's row of each of these states (its base: last)
                up = np.append(_positions(sel[body.parent], mine), len(sel[body.parent]))
                rp, tp, _, vp, ap = state[body.parent]
                vp, ap = vp[..., up, :, :], ap[..., up, :, :]
                if q_along is not None:  # else one pose for every state: the base's
                    rp, tp = rp[up], tp[up]
                rot, trans, cols = self._joint(j, rp, tp, qj)
                vel, acc = self._outward(j, cols, (vp, ap), root, vj, aj)
            else:
                eye = np.broadcast_to(np.eye(3), (1, rows, 3, 3))
                rot, trans, cols = self._joint(j, eye, np.zeros((1, rows, 3)), qj)
                vel, acc = self._outward(j, cols, None, root, vj, aj)
            if q_along is not None:  # a slide's pose, a joint's columns, need not move with
                count = len(mine) + 1  # its coordinates: one row per state all the same
                rot = np.broadcast_to(rot, (count, *rot.shape[-3:]))
                trans = np.broadcast_to(trans, (count, *trans.shape[-2:]))
                cols = np.broadcast_to(cols, (count, *cols.shape[-3:]))
            common = np.broadcast_shapes(vel.shape, acc.shape)  # one row per state
            vel, acc = np.broadcast_to(vel, common), np.broadcast_to(acc, common)
            state.append((rot, trans, cols, vel, acc))
            force_rows.append(self._force(j, rot, trans, vel, acc))
        return sel, state, force_rows

    def _inward_along(self, sel: list[np.ndarray], state: list, force_rows: list, *,
                      shape: tuple[int, ...], dtype: np.dtype, moved: bool) -> np.ndarray:
        """:meth:`inverse_along`'s inward pass on every state: a body's force where it was not
        evaluated is its base one; the forces summed inward, projected on each joint's columns
        (``moved``: poses differ per state). τ of shape (..., K, B, nv)."""
        nb, k_all = len(self.bodies), shape[-3]
        # inward, on every state: a body's force where it was not evaluated is its base one
        tau = np.zeros(shape, dtype)
        total: list[np.ndarray | None] = [None] * nb
        for j in reversed(range(nb)):
            body = self.bodies[j]
            every = _positions(sel[j], np.arange(k_all))
            own_force = force_rows[j]
            mine_total = total[j]
            if own_force is not None:
                spread = own_force[..., every, :, :]
                mine_total = spread if mine_total is None else mine_total + spread
            if mine_total is None:
                continue
            cols = state[j][2]
            cols = cols[every] if moved else cols
            vs, own = self.v_start[j], NV[body.kind]
            tau[..., vs : vs + own] = (np.swapaxes(cols, -1, -2) @ mine_total[..., None])[..., 0]
            if body.parent >= 0:
                parent_total = total[body.parent]
                total[body.parent] = mine_total if parent_total is None \
                    else parent_total + mine_total
        return tau

    def _placed(self, j: int, rot: np.ndarray, trans: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray] | None:
        """Body j's centre (..., 3) and inertia about it (..., 3, 3) at its pose, world axes
        (None: it carries nothing)."""
        body = self.bodies[j]
        if body.mass == 0.0 and not np.any(body.inertia):
            return None
        return rot @ body.com + trans, rot @ body.inertia @ np.swapaxes(rot, -1, -2)

    def _inertias(self, poses: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
                  ) -> list[tuple[np.ndarray, np.ndarray] | None]:
        """:meth:`_placed` of every body at its pose."""
        return [self._placed(j, rot, trans) for j, (rot, trans, _) in enumerate(poses)]

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *,
                gravity: bool = True) -> np.ndarray:
        """τ = M(q) v̇ + h(q, v) (..., B, nv) at rows q (B, nq) and v, v̇ = ``a``
        (..., B, nv) — leading axes share the rows' kinematics —, by the recursion in the
        module's docstring; ``gravity=False`` leaves the weights out."""
        poses = self._kinematics(q)
        shape = np.broadcast_shapes(v.shape, a.shape)
        dtype = np.result_type(q, v, a, float)
        v, a = np.broadcast_to(v, shape), np.broadcast_to(a, shape)
        root = np.zeros((*shape[:-1], 6), dtype)
        if gravity:
            root[..., 3:] = -self.gravity
        motions: list[tuple[np.ndarray, np.ndarray]] = []
        force: list[np.ndarray] = []
        for j, body in enumerate(self.bodies):
            vs, own = self.v_start[j], NV[body.kind]
            rot, trans, cols = poses[j]
            motions.append(self._outward(
                j, cols, motions[body.parent] if body.parent >= 0 else None, root,
                v[..., vs : vs + own], a[..., vs : vs + own]))
            found = self._force(j, rot, trans, *motions[j])
            force.append(np.zeros_like(motions[j][1]) if found is None else found)
        tau = np.zeros(shape, dtype)
        for j in reversed(range(len(self.bodies))):
            body = self.bodies[j]
            vs, own = self.v_start[j], NV[body.kind]
            cols = poses[j][2]
            tau[..., vs : vs + own] = (np.swapaxes(cols, -1, -2) @ force[j][..., None])[..., 0]
            if body.parent >= 0:
                force[body.parent] = force[body.parent] + force[j]
        return tau + self.armature * a

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q) (B, nv, nv) by composite bodies: M_ij = S_iᵀ 𝕀ᶜ_j S_j for i an ancestor
        of j (or j), 𝕀ᶜ_j the inertia of everything joint j carries; + the armature."""
        poses = self._kinematics(q)
        inertias = self._inertias(poses)
        rows = len(q)
        dtype = np.result_type(q, float)
        columns = np.concatenate([p[2] for p in poses], -1) if poses \
            else np.zeros((rows, 6, 0), dtype)
        composite = [np.zeros((rows, 6, 6), dtype) if x is None
                     else _spatial_inertia(body.mass, *x).astype(dtype)
                     for body, x in zip(self.bodies, inertias, strict=True)]
        out = np.zeros((rows, self.nv, self.nv), dtype)
        for j in reversed(range(len(self.bodies))):
            body = self.bodies[j]
            if body.parent >= 0:
                composite[body.parent] = composite[body.parent] + composite[j]
            vs, own = self.v_start[j], NV[body.kind]
            carried = composite[j] @ poses[j][2]  # (B, 6, own)
            anc = self.ancestor_columns[j]
            block = np.einsum("bia,bik->bak", columns[:, :, anc], carried)
            out[:, anc[:, None], np.arange(vs, vs + own)[None, :]] = block
            out[:, np.arange(vs, vs + own)[:, None], anc[None, :]] = np.swapaxes(block, 1, 2)
        out[:, np.arange(self.nv), np.arange(self.nv)] += self.armature
        return out

    def potential(self, q: np.ndarray) -> np.ndarray:
        """V = −Σ m 𝐠·c (B,): the weights' potential, zero with every centre at the
        origin."""
        out = np.zeros(len(q), np.result_type(q, float))
        for body, (rot, trans, _) in zip(self.bodies, self._kinematics(q, absolute=True),
                                         strict=True):
            if body.mass:
                out -= body.mass * ((rot @ body.com + trans) @ self.gravity)
        return out

    def reach(self, q: np.ndarray) -> tuple[float, float]:
        """(X, ℓ) over the rows q (B, nq): X the largest distance from the world origin of a
        subtree's root point (its root joint's anchor; a free body's origin) — how far the
        model stands from the origin —, ℓ the model's own length: the largest distance of a
        joint point or centre from its subtree's root point, or radius of gyration (at least
        1 mm). A position carries round-off ε X, so a lever arm taken as a difference of
        positions carries ε X / ℓ relative: what a method written about the world origin
        loses (the general method's momenta about O; an engine's world-frame kinematics)."""
        lengths = [1e-3]
        for body in self.bodies:
            inertia = np.asarray(body.inertia, float)
            if body.mass > 0 and np.isfinite(body.mass) and np.all(np.isfinite(inertia)):
                lengths.append(float(np.sqrt(np.abs(np.linalg.eigvalsh(inertia)).max()
                                             / body.mass)))  # (a broken inertia: none)

        def farthest(poses: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> float:
            out = 0.0
            for body, (rot, trans, _) in zip(self.bodies, poses, strict=True):
                for point in (body.anchor, body.com):
                    placed = (rot @ np.asarray(point, float) + trans).real
                    out = max(out, float(np.sqrt((placed**2).sum(-1)).max(initial=0.0)))
            return out

        poses = self._kinematics(q, absolute=True)
        far = 0.0
        for body, (rot, trans, _) in zip(self.bodies, poses, strict=True):
            if body.parent < 0:  # a subtree's root point, where the model stands
                placed = (rot @ np.asarray(body.anchor, float) + trans).real
                far = max(far, float(np.sqrt((placed**2).sum(-1)).max(initial=0.0)))
        return far, max(farthest(self._kinematics(q)), *lengths)

    def at_states(self, q: np.ndarray, v: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """M (S, nv, nv), h (S, nv), T (S,), V (S,) at S states, as
        :meth:`TreeDynamics.at_states <dyncheck.reference.tree.TreeDynamics.at_states>`
        gives them."""
        mass = self.mass_matrix(q)
        bias = self.inverse(q, v, np.zeros_like(v, dtype=np.result_type(v, float)))
        kinetic = 0.5 * np.einsum("si,sij,sj->s", v, mass, v)
        return mass, bias, kinetic, self.potential(q)
