"""The book's general method on any tree of rigid bodies: the kinetic energy of the bodies gives
the metric g_ij(q), Lagrange's equations (2.2.23)–(2.2.24) give the mass matrix and the bias.

Each body contributes T_b = ½ m |ċ|² + ½ Iᵢⱼ ωᵢ ωⱼ (the inertia tensor (2.2.39) about the
centre of mass, the rotational energy (2.2.40), the translational part from (2.2.44)), so

    g_ij = Σ_b  m_b (∂ċ/∂q̇ⁱ)·(∂ċ/∂q̇ʲ) + (∂ω/∂q̇ⁱ)ᵀ I_b (∂ω/∂q̇ʲ)   (+ rotor inertia aᵢ δᵢⱼ),

and in the form printed after (2.2.36), d/dt(g_ik q̇ᵏ) − ½ ∂ᵢg_jk q̇ʲq̇ᵏ + ∂ᵢV = Qᵢ, i.e.

    M = g,   h_i = (∂_k g_ij − ½ ∂_i g_jk) q̇ʲ q̇ᵏ + ∂_i V,   V = −Σ_b m_b 𝐠·c_b.

The derivatives ∂_k g are exact: complex-step (g evaluated at q + i·η·e_k, η = 1e-30, the
imaginary part / η — no subtraction, so no cancellation: error ~ ε relative). Ball and free
joints are taken in a local chart at the sampled state, R = R_s exp(ξ̂), ξ = 0 there, so that
ξ̇ = ω in the body's axes and (ξ̈ = ω̇ at the chart's centre) Euler's equations come out; a free
joint's pose is held in its parent's axes (the world's at the root: a free body's position is
its world position), as a free flyer below a moving link is in Pinocchio. The chart's exp
and right Jacobian are evaluated by their series in θ² = ξ·ξ, exact here because |ξ| ≤ η.

Inputs are in world axes at the reference configuration (the same point of view as the
engines' neutral trees); coordinates q follow MuJoCo's layout (a free joint (p, w x y z), its
velocity (linear in its parent's axes — the world's at the root —, body angular)); a joint's
angle is measured from ``zero``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KINDS = ("hinge", "slide", "ball", "free")
STEP = 1e-30
"""The complex step η (any value ≪ √ε·scale works: the result is η-independent)."""


@dataclass(frozen=True, kw_only=True)
class Body:
    """A joint and the rigid body it moves: ``kind`` in :data:`KINDS`; ``parent`` the index of
    the joint it hangs from (−1: the world); axis, anchor, frame (the child frame's orientation,
    ball and free), centre of mass and inertia about it — world axes, reference configuration."""

    kind: str
    parent: int
    axis: np.ndarray
    anchor: np.ndarray
    frame: np.ndarray
    zero: float
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    armature: tuple[float, ...]


CHUNK_ROWS = 4096
"""Complex-step rows evaluated together (states × (nv + 1)): numpy's per-call overhead
amortised, memory bounded (a 35-dof tree: ~110 states a chunk, tens of MB)."""
NQ = {"hinge": 1, "slide": 1, "ball": 4, "free": 7}
NV = {"hinge": 1, "slide": 1, "ball": 3, "free": 6}


def hat(x: np.ndarray) -> np.ndarray:
    """(..., 3) → (..., 3, 3) skew matrices, x̂ y = x × y."""
    z = np.zeros_like(x[..., 0])
    return np.stack(
        [
            np.stack([z, -x[..., 2], x[..., 1]], -1),
            np.stack([x[..., 2], z, -x[..., 0]], -1),
            np.stack([-x[..., 1], x[..., 0], z], -1),
        ],
        -2,
    )


def _exp_and_jr(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """exp(ξ̂) and the right Jacobian J_r(ξ) (ω = J_r ξ̇), by their series in s = ξ·ξ
    (complex-analytic; |ξ| ≤ η makes four terms exact)."""
    s = np.einsum("...i,...i->...", xi, xi)[..., None, None]
    a = 1 - s / 6 + s**2 / 120 - s**3 / 5040  # sin θ / θ
    b = 0.5 - s / 24 + s**2 / 720 - s**3 / 40320  # (1 − cos θ) / θ²
    c = 1.0 / 6 - s / 120 + s**2 / 5040 - s**3 / 362880  # (θ − sin θ) / θ³
    k = hat(xi)
    k2 = k @ k
    eye = np.eye(3)
    return eye + a * k + b * k2, eye - b * k + c * k2


def rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues' rotation about a fixed unit axis by angles (...) (complex-analytic)."""
    k = hat(np.asarray(axis, float))
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1 - c) * (k @ k)


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    """(B, 4) unit quaternions (w, x, y, z; normalised here) → (B, 3, 3) rotations."""
    w, x, y, z = (q / np.linalg.norm(q, axis=-1, keepdims=True)).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


class Tree:
    """A tree of :class:`Body` records and its coordinates' layout: where each joint's q and
    v start, the rotor inertia (armature) of every velocity, and each body's ancestor
    columns (the velocities that move it) — what both the general method and the recursive
    algorithm (:mod:`dyncheck.reference.recursive`) are evaluated on."""

    def __init__(self, bodies: list[Body], gravity: np.ndarray) -> None:
        for b in bodies:
            if b.kind not in KINDS:
                raise ValueError(f"joint kind must be one of {KINDS}, got {b.kind!r}")
        self.bodies = bodies
        self.gravity = np.asarray(gravity, float)
        self.q_start = np.cumsum([0] + [NQ[b.kind] for b in bodies])[:-1]
        self.v_start = np.cumsum([0] + [NV[b.kind] for b in bodies])[:-1]
        self.nv = int(sum(NV[b.kind] for b in bodies))
        self.armature = np.concatenate([np.asarray(b.armature, float) for b in bodies]) \
            if bodies else np.zeros(0)
        chains: list[list[int]] = []
        for j, b in enumerate(bodies):
            chains.append([*(chains[b.parent] if b.parent >= 0 else []), j])
        self.ancestor_columns = [
            np.concatenate([np.arange(self.v_start[i], self.v_start[i] + NV[bodies[i].kind])
                            for i in chain])
            for chain in chains
        ]


_Pose = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""A body on its rows: R, t, Ω, V (see :meth:`TreeDynamics._walk`)."""
_Column = tuple[slice, np.ndarray, "np.ndarray | None"]
"""A joint's velocity columns on each row: their span in v, the columns (angular or linear),
and the pivot of angular ones (None: linear)."""


@dataclass(frozen=True, kw_only=True)
class _Sums:
    """What :meth:`TreeDynamics._at_chunk` adds up over the bodies of a chunk of states (its
    arrays filled in place): M, h and V; the joints' real columns at the unperturbed row
    (angular, pivot, linear); each subtree's momentum P and L at the v row."""

    mass: np.ndarray
    h: np.ndarray
    potential: np.ndarray
    angular0: np.ndarray
    pivot0: np.ndarray
    linear0: np.ndarray
    momentum: np.ndarray
    spin_sum: np.ndarray


@dataclass(frozen=True, kw_only=True)
class PointMotion:
    """A body point at S states: its position x (S, 3); the rows J_x = ∂ẋ/∂v and J_ω = ∂ω/∂v
    (S, 3, nv) of its velocity and of its body's angular velocity (world axes); and their
    accelerations at v̇ = 0, J̇_x v and J̇_ω v (S, 3) — exact: the velocity along the path
    q ⊕ s v (v held, which keeps v̇ = 0 on every chart) differentiated by the complex step."""

    position: np.ndarray
    rotation: np.ndarray
    """A_b (S, 3, 3): the body's rotation from the reference configuration."""
    linear: np.ndarray
    angular: np.ndarray
    linear_bias: np.ndarray
    angular_bias: np.ndarray


class TreeDynamics(Tree):
    """M, h, forward and inverse dynamics, T and V of a tree of :class:`Body` records."""

    def __init__(self, bodies: list[Body], gravity: np.ndarray) -> None:
        super().__init__(bodies, gravity)
        self._rows()

    def at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
        """M, h, T, V at one state (MuJoCo layout); :meth:`at_states` for several."""
        mass, h, kinetic, potential = self.at_states(np.asarray(q, float)[None],
                                                     np.asarray(v, float)[None])
        return mass[0], h[0], float(kinetic[0]), float(potential[0])

    def at_states(
        self, q: np.ndarray, v: np.ndarray, chunk: int = CHUNK_ROWS
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """M (S, nv, nv), h (S, nv), T (S,), V (S,) at S states, evaluated together in
        chunks of about ``chunk`` states × rows (memory bounded whatever S)."""
        q, v = np.asarray(q, float), np.asarray(v, float)
        per = max(1, chunk // (self.nv + 2))
        parts = [self._at_chunk(q[i : i + per], v[i : i + per]) for i in range(0, len(q), per)]
        if not parts:
            nv = self.nv
            return np.empty((0, nv, nv)), np.empty((0, nv)), np.empty(0), np.empty(0)
        mass, h, kinetic, potential = (np.concatenate(x) for x in zip(*parts, strict=True))
        return mass, h, kinetic, potential

    def point_motion(self, q: np.ndarray, v: np.ndarray, *, body: int,
                     point: np.ndarray) -> PointMotion:
        """A point fixed on joint ``body``'s body (world coordinates at the reference
        configuration; −1: fixed in the world) at S states: where it is, and its and the
        body's rows of velocity and of acceleration at v̇ = 0 (what the closures of
        :mod:`.closure` are made of); :meth:`points_motion` for several, one walk."""
        return self.points_motion(q, v, [(body, point)])[0]

    def points_motion(self, q: np.ndarray, v: np.ndarray,
                      points: list[tuple[int, np.ndarray]]) -> list[PointMotion]:
        """:meth:`point_motion` of each (body, point), the tree walked once."""
        q, v = np.atleast_2d(np.asarray(q, float)), np.atleast_2d(np.asarray(v, float))
        walked = self._walk(q, v) if any(b >= 0 for b, _ in points) else None
        return [self._point(walked, len(q), body=b, point=np.asarray(p, float))
                for b, p in points]

    def _point(self, walked: tuple[list[_Pose], list[list[_Column]]] | None, ns: int, *,
               body: int, point: np.ndarray) -> PointMotion:
        """One point's motion from the tree's walk (None: no body moves; see
        :meth:`point_motion`)."""
        zeros = np.zeros((ns, 3, self.nv))
        if body < 0 or walked is None:
            fixed = np.broadcast_to(point, (ns, 3)).copy()
            return PointMotion(position=fixed, rotation=np.tile(np.eye(3), (ns, 1, 1)),
                               linear=zeros, angular=zeros.copy(),
                               linear_bias=np.zeros((ns, 3)), angular_bias=np.zeros((ns, 3)))
        poses, columns_of = walked
        rot, trans, omega, vel = poses[body]
        n = len(self.ancestor_columns[body])
        x = np.einsum("srij,j->sri", rot, point) + trans
        x0 = x[:, -1].real
        linear, angular = zeros, zeros.copy()
        chain = [body]
        while self.bodies[chain[-1]].parent >= 0:
            chain.append(self.bodies[chain[-1]].parent)
        for j in chain:
            for part, w, pivot in columns_of[j]:
                w0 = w[:, -1].real
                if pivot is None:
                    linear[..., part] = w0
                else:
                    angular[..., part] = w0
                    linear[..., part] = np.cross(w0, (x0 - pivot[:, -1].real)[..., None],
                                                 axis=1)
        moving = vel[:, n] + np.cross(omega[:, n], x[:, n])  # ẋ along q ⊕ iη v
        return PointMotion(position=x0, rotation=rot[:, -1].real.copy(), linear=linear,
                           angular=angular,
                           linear_bias=moving.imag / STEP, angular_bias=omega[:, n].imag / STEP)

    def _rows(self) -> None:
        """Each body's rows of complex steps: one per ancestor column (that column stepped),
        then the velocity direction, then the unperturbed state; and, for each ancestor
        joint, which of that joint's rows each of these rows is (a column that is not the
        ancestor's own is its unperturbed row)."""
        self.rows_of: list[dict[int, np.ndarray]] = []
        for j, body in enumerate(self.bodies):
            cols = self.ancestor_columns[j]
            n = len(cols)
            maps: dict[int, np.ndarray] = {j: np.arange(n + 2)}
            if body.parent >= 0:
                parent_cols = list(self.ancestor_columns[body.parent])
                pn = len(parent_cols)
                to_parent = np.array(
                    [parent_cols.index(c) if c in parent_cols else pn + 1 for c in cols]
                    + [pn, pn + 1]
                )
                for ancestor, rows in self.rows_of[body.parent].items():
                    maps[ancestor] = rows[to_parent]
            self.rows_of.append(maps)

    def _moved(self, body: Body, q: np.ndarray, xj: np.ndarray, *,
               parent: tuple[np.ndarray, np.ndarray], qs: int, vs: int, own: int
               ) -> tuple[np.ndarray, np.ndarray, list[_Column]]:
        """A joint's body pose (R, t) on each row of :meth:`_at_chunk`, its parent's pose
        ``parent`` and its chart coordinates ``xj`` given, with its velocity columns: (span,
        angular columns, pivot) or (span, linear columns, None)."""
        rp, tp = parent
        anchor = np.asarray(body.anchor, float)
        pivot = np.einsum("srij,j->sri", rp, anchor) + tp
        span = slice(vs, vs + own)
        if body.kind in ("hinge", "slide"):
            axis = np.einsum("srij,j->sri", rp, body.axis)
            coordinate = (q[:, qs] - body.zero)[:, None] + xj[..., 0]
            columns = [(span, axis[..., None], pivot if body.kind == "hinge" else None)]
        if body.kind == "hinge":
            rot = rp @ rotation(body.axis, coordinate)
            trans = pivot - np.einsum("srij,j->sri", rot, anchor)
        elif body.kind == "slide":
            rot = np.asarray(rp)
            trans = tp + coordinate[..., None] * axis
        elif body.kind == "ball":
            e, jr = _exp_and_jr(xj)
            current = body.frame @ _quat_matrix(q[:, qs : qs + 4])[:, None] @ e
            rot = rp @ current @ body.frame.T
            trans = pivot - np.einsum("srij,j->sri", rot, anchor)
            columns = [(span, rp @ current @ jr, pivot)]
        else:  # free: q = (p, quat) pose in the parent's axes (the world's at the root)
            e, jr = _exp_and_jr(xj[..., 3:])
            world = rp @ _quat_matrix(q[:, qs + 3 : qs + 7])[:, None] @ e
            position = np.einsum("srij,srj->sri", rp, q[:, None, qs : qs + 3] + xj[..., :3]) + tp
            rot = world @ body.frame.T
            trans = position - np.einsum("srij,j->sri", rot, anchor)
            columns = [(slice(vs, vs + 3), np.broadcast_to(rp, rot.shape), None),
                       (slice(vs + 3, vs + 6), world @ jr, position)]
        return rot, trans, columns

    def _walk(self, q: np.ndarray, v: np.ndarray
              ) -> tuple[list[_Pose], list[list[_Column]]]:
        """Each joint's body on its rows (:meth:`_rows`): its pose (R, t), its twist (Ω, V:
        the angular velocity and the velocity of the body point at the world origin), and
        its joint's velocity columns, from the root outward."""
        ns = len(q)
        step = 1j * STEP
        poses: list[_Pose] = []
        columns_of: list[list[_Column]] = []
        for j, body in enumerate(self.bodies):
            n, own = len(self.ancestor_columns[j]), NV[body.kind]
            qs, vs = int(self.q_start[j]), int(self.v_start[j])
            xj = np.zeros((ns, n + 2, own), complex)  # this joint's chart coordinates
            xj[:, np.arange(n - own, n), np.arange(own)] = step
            xj[:, n, :] = step * v[:, vs : vs + own]
            if body.parent >= 0:
                up = self.rows_of[j][body.parent]
                rp, tp, omega, vel = (x[:, up] for x in poses[body.parent])
            else:
                rp = np.broadcast_to(np.eye(3), (ns, n + 2, 3, 3))
                tp = np.zeros((ns, n + 2, 3))
                omega = vel = np.zeros((ns, n + 2, 3), complex)
            rot, trans, columns = self._moved(body, q, xj, parent=(rp, tp), qs=qs, vs=vs,
                                              own=own)
            for part, w, point in columns:  # the twist: the parent's plus this joint's
                turn = np.einsum("srik,sk->sri", w, v[:, part])
                if point is None:
                    vel = vel + turn
                else:
                    omega = omega + turn
                    vel = vel + np.cross(point, turn)
            poses.append((rot, trans, omega, vel))
            columns_of.append(columns)
        return poses, columns_of

    def _at_chunk(
        self, q: np.ndarray, v: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """M, h, T, V at the states q (S, nq), v (S, nv).

        Each body b is evaluated on its rows (:meth:`_rows`): the chart coordinates x of its
        ancestors stepped by iη one at a time, then by iη v, then not at all. With g the
        metric (the formula in the module's docstring), 2T_b = vᵀ g_b v = m |ċ|² + ωᵀ I ω, and

            Σ_k ∂_k g_ij vᵏ vʲ = Im(g(q + iηv) v)_i / η,   ∂_i (vᵀ g_b v) = Im(2T_b)_i / η,

        so h needs no tensor ∂g: (g v)_i is joint i's axis against the momentum of the
        bodies it carries — w·(L − p × P) for a rotation about pivot p, w·P for a
        translation (L the angular momentum about the world origin, P the linear) — and
        every body's ċ, ω come from its twist, its parent's plus its own joint's. M is g at
        the unperturbed row. A body's kinematics depend only on its ancestors' coordinates:
        c_b + 2 rows each."""
        ns, nv = len(q), self.nv
        nb = len(self.bodies)
        sums = _Sums(
            mass=np.tile(np.diag(self.armature).astype(float), (ns, 1, 1)),
            h=np.zeros((ns, nv)), potential=np.zeros(ns),
            angular0=np.zeros((ns, 3, nv)), pivot0=np.zeros((ns, 3, nv)),
            linear0=np.zeros((ns, 3, nv)),
            momentum=np.zeros((nb, ns, 3), complex),  # P of the subtree, at the v row
            spin_sum=np.zeros((nb, ns, 3), complex))  # L about the origin, at the v row
        poses, columns_of = self._walk(q, v)
        # per joint, at its v row (complex): columns as (angular (S, 3, k), pivot (S, 3)) or
        # (linear (S, 3, k), None), with their span
        at_v: list[list[tuple[slice, np.ndarray, np.ndarray | None]]] = []
        for j, columns in enumerate(columns_of):
            n = len(self.ancestor_columns[j])
            for part, w, point in columns:  # the joints' real columns (unperturbed row)
                sums.angular0[..., part] = w[:, -1].real if point is not None else 0.0
                sums.linear0[..., part] = w[:, -1].real if point is None else 0.0
                if point is not None:
                    sums.pivot0[..., part] = point[:, -1, :, None].real
            at_v.append([(part, w[:, n], None if point is None else point[:, n])
                         for part, w, point in columns])
        for j, body in enumerate(self.bodies):
            if body.mass != 0.0 or np.any(body.inertia):
                self._add_body(j, body, sums, pose=poses[j], n=len(self.ancestor_columns[j]))
        self._inward(sums, at_v)
        kinetic = 0.5 * np.einsum("si,sij,sj->s", v, sums.mass, v)
        return sums.mass, sums.h, kinetic, sums.potential

    def _add_body(self, j: int, body: Body, sums: _Sums, *,
                  pose: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], n: int) -> None:
        """Body j's terms (see :meth:`_at_chunk`), added into ``sums``: h's ∂_i T from its
        2T at the stepped rows, its momentum at the v row, and M, gravity and V at the
        unperturbed row from its ancestors' real columns."""
        rot, trans, omega, vel = pose
        cols = self.ancestor_columns[j]
        com = np.einsum("srij,j->sri", rot, body.com) + trans
        cdot = vel + np.cross(omega, com)
        local = np.einsum("srji,srj->sri", rot, omega) @ body.inertia  # (I₀ symmetric)
        spin = np.einsum("srij,srj->sri", rot, local)  # I ω in world axes
        twice_t = (body.mass * np.einsum("sri,sri->sr", cdot, cdot)
                   + np.einsum("sri,sri->sr", omega, spin))
        sums.h[:, cols] -= 0.5 * twice_t[:, :n].imag / STEP
        sums.momentum[j] += body.mass * cdot[:, n]
        sums.spin_sum[j] += np.cross(com[:, n], body.mass * cdot[:, n]) + spin[:, n]
        # M, gravity and V at the unperturbed row, from the joints' real columns
        com0, rot0 = com[:, -1].real, rot[:, -1].real
        jw = sums.angular0[..., cols]
        arm = com0[..., None] - sums.pivot0[..., cols]
        jc = sums.linear0[..., cols] + np.cross(jw, arm, axis=1)
        inertia = rot0 @ body.inertia @ np.swapaxes(rot0, 1, 2)
        sums.mass[:, cols[:, None], cols[None, :]] += (
            body.mass * np.swapaxes(jc, 1, 2) @ jc + np.swapaxes(jw, 1, 2) @ inertia @ jw)
        sums.h[:, cols] -= body.mass * np.einsum("j,sjc->sc", self.gravity, jc)
        sums.potential[:] -= body.mass * (com0 @ self.gravity)

    def _inward(self, sums: _Sums,
                at_v: list[list[tuple[slice, np.ndarray, np.ndarray | None]]]) -> None:
        """h's (g v)_i terms: each joint against the momentum of what it carries, summed
        from the leaves inward."""
        for j in reversed(range(len(self.bodies))):
            parent = self.bodies[j].parent
            if parent >= 0:
                sums.momentum[parent] += sums.momentum[j]
                sums.spin_sum[parent] += sums.spin_sum[j]
            for part, w, point in at_v[j]:
                arm = sums.momentum[j] if point is None else \
                    sums.spin_sum[j] - np.cross(point, sums.momentum[j])
                sums.h[:, part] += np.einsum("sik,si->sk", w, arm).imag / STEP

