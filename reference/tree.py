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
body's position is its world position. The chart's exp and right Jacobian are evaluated by
their series in θ² = ξ·ξ, exact here because |ξ| ≤ η.

Inputs are in world axes at the reference configuration (the same point of view as the
engines' neutral trees); coordinates q follow MuJoCo's layout (a free joint (p, w x y z), its
velocity (world linear, body angular)); a joint's angle is measured from ``zero``.
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


NQ = {"hinge": 1, "slide": 1, "ball": 4, "free": 7}
NV = {"hinge": 1, "slide": 1, "ball": 3, "free": 6}


def _hat(x: np.ndarray) -> np.ndarray:
    """(B, 3) → (B, 3, 3) skew matrices, x̂ y = x × y."""
    z = np.zeros_like(x[:, 0])
    return np.stack(
        [
            np.stack([z, -x[:, 2], x[:, 1]], -1),
            np.stack([x[:, 2], z, -x[:, 0]], -1),
            np.stack([-x[:, 1], x[:, 0], z], -1),
        ],
        -2,
    )


def _exp_and_jr(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """exp(ξ̂) and the right Jacobian J_r(ξ) (ω = J_r ξ̇), by their series in s = ξ·ξ
    (complex-analytic; |ξ| ≤ η makes four terms exact)."""
    s = np.einsum("bi,bi->b", xi, xi)[:, None, None]
    a = 1 - s / 6 + s**2 / 120 - s**3 / 5040  # sin θ / θ
    b = 0.5 - s / 24 + s**2 / 720 - s**3 / 40320  # (1 − cos θ) / θ²
    c = 1.0 / 6 - s / 120 + s**2 / 5040 - s**3 / 362880  # (θ − sin θ) / θ³
    k = _hat(xi)
    k2 = k @ k
    eye = np.eye(3)[None]
    return eye + a * k + b * k2, eye - b * k + c * k2


def _rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues' rotation about a fixed unit axis by angles (B,) (complex-analytic)."""
    k = _hat(np.broadcast_to(axis, (len(angle), 3)).astype(angle.dtype))
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3)[None] + s * k + (1 - c) * (k @ k)


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


class TreeDynamics:
    """M, h, forward and inverse dynamics, T and V of a tree of :class:`Body` records."""

    def __init__(self, bodies: list[Body], gravity: np.ndarray) -> None:
        for b in bodies:
            if b.kind not in KINDS:
                raise ValueError(f"joint kind must be one of {KINDS}, got {b.kind!r}")
        self.bodies = bodies
        self.gravity = np.asarray(gravity, float)
        self.q_start = np.cumsum([0] + [NQ[b.kind] for b in bodies])[:-1]
        self.v_start = np.cumsum([0] + [NV[b.kind] for b in bodies])[:-1]
        self.nv = int(sum(NV[b.kind] for b in bodies))
        self.armature = np.concatenate([np.asarray(b.armature, float) for b in bodies])
        chains: list[list[int]] = []
        for j, b in enumerate(bodies):
            chains.append([*(chains[b.parent] if b.parent >= 0 else []), j])
        self.ancestor_columns = [
            np.concatenate([np.arange(self.v_start[i], self.v_start[i] + NV[bodies[i].kind])
                            for i in chain])
            for chain in chains
        ]

    def _kinematics(
        self, q: np.ndarray, x: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, list[list[tuple[slice, np.ndarray, np.ndarray | None]]]]:
        """At the state q (chart centre) displaced by chart coordinates x (B, nv), complex:
        each body's rigid transform x ↦ R x + t (R (nb, B, 3, 3), t (nb, B, 3)) and each
        joint's Jacobian columns (angular about a pivot, or linear: pivot None)."""
        nb, batch = len(self.bodies), x.shape[0]
        dtype = x.dtype
        rot = np.empty((nb, batch, 3, 3), dtype)
        trans = np.empty((nb, batch, 3), dtype)
        # Per joint: its Jacobian columns — angular (B, 3, d) about a pivot (B, 3), or linear.
        columns: list[list[tuple[slice, np.ndarray, np.ndarray | None]]] = []
        for j, body in enumerate(self.bodies):
            qs, vs = int(self.q_start[j]), int(self.v_start[j])
            cols = slice(vs, vs + NV[body.kind])
            xj = x[:, cols]
            if body.parent >= 0:
                rp, tp = rot[body.parent], trans[body.parent]
            else:
                rp = np.broadcast_to(np.eye(3, dtype=dtype), (batch, 3, 3))
                tp = np.zeros((batch, 3), dtype)
            anchor = np.asarray(body.anchor, float)
            pivot = np.einsum("bij,j->bi", rp, anchor) + tp
            if body.kind == "hinge":
                local = _rotation(body.axis, q[qs] - body.zero + xj[:, 0])
                w = np.einsum("bij,j->bi", rp, body.axis)[:, :, None]
                columns.append([(cols, w, pivot)])
            elif body.kind == "slide":
                local = np.broadcast_to(np.eye(3, dtype=dtype), (batch, 3, 3))
                disp = (q[qs] - body.zero + xj[:, 0])[:, None] * body.axis
                w = np.einsum("bij,j->bi", rp, body.axis)[:, :, None]
                columns.append([(cols, w, None)])
            elif body.kind == "ball":
                e, jr = _exp_and_jr(xj)
                frame = body.frame
                current = frame @ _quat_matrix(q[qs : qs + 4]) @ e  # (B, 3, 3)
                local = current @ frame.T
                columns.append([(cols, rp @ current @ jr, pivot)])
            else:  # free: q = (p, quat) world pose; x = (dp, ξ)
                e, jr = _exp_and_jr(xj[:, 3:])
                world = _quat_matrix(q[qs + 3 : qs + 7]) @ e
                p = q[qs : qs + 3] + xj[:, :3]
                rot[j] = world @ body.frame.T
                trans[j] = p - np.einsum("bij,j->bi", rot[j], anchor)
                columns.append(
                    [
                        (slice(vs, vs + 3), np.broadcast_to(np.eye(3), (batch, 3, 3)), None),
                        (slice(vs + 3, vs + 6), world @ jr, p),
                    ]
                )
                continue
            rot[j] = rp @ local  # x ↦ Rp (a + L (x − a)) + tp
            trans[j] = pivot - np.einsum("bij,j->bi", rot[j], anchor)
            if body.kind == "slide":
                trans[j] = trans[j] + np.einsum("bij,bj->bi", rp, disp)
        return rot, trans, columns

    def at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
        """M, h, T, V at one state (MuJoCo layout). A body's energy depends only on its
        ancestors' coordinates, so each body is evaluated on the complex steps of those
        columns alone (plus the unperturbed state, the last row)."""
        nv = self.nv
        x = np.zeros((nv + 1, nv), complex)
        x[np.arange(nv), np.arange(nv)] = 1j * STEP
        rot, trans, columns = self._kinematics(np.asarray(q, float), x)
        mass = np.diag(self.armature).astype(float)
        dg = np.zeros((nv, nv, nv))  # dg[k] = ∂_k g
        dv = np.zeros(nv)
        potential = 0.0
        # All joints' columns at once: angular (B, 3, nv) with their pivots, linear (B, 3, nv).
        angular = np.zeros((nv + 1, 3, nv), complex)
        pivots = np.zeros((nv + 1, 3, nv), complex)
        linear = np.zeros((nv + 1, 3, nv), complex)
        for joint_columns in columns:
            for span, w, pivot in joint_columns:
                if pivot is None:
                    linear[:, :, span] = w
                else:
                    angular[:, :, span] = w
                    pivots[:, :, span] = pivot[:, :, None]
        for b, body in enumerate(self.bodies):
            if body.mass == 0.0 and not np.any(body.inertia):
                continue
            cols = self.ancestor_columns[b]
            rows = np.append(cols, nv)
            r, t = rot[b][rows], trans[b][rows]
            c = np.einsum("bij,j->bi", r, body.com) + t
            jw = angular[np.ix_(rows, np.arange(3), cols)]
            arm = c[:, :, None] - pivots[np.ix_(rows, np.arange(3), cols)]
            jc = linear[np.ix_(rows, np.arange(3), cols)] + np.stack(  # ω × (c − p)
                [
                    jw[:, 1] * arm[:, 2] - jw[:, 2] * arm[:, 1],
                    jw[:, 2] * arm[:, 0] - jw[:, 0] * arm[:, 2],
                    jw[:, 0] * arm[:, 1] - jw[:, 1] * arm[:, 0],
                ],
                1,
            )
            inertia = r @ body.inertia @ np.swapaxes(r, 1, 2)
            gb = body.mass * np.swapaxes(jc, 1, 2) @ jc + np.swapaxes(jw, 1, 2) @ inertia @ jw
            mass[np.ix_(cols, cols)] += gb[-1].real
            dg[np.ix_(cols, cols, cols)] += gb[:-1].imag / STEP
            dv[cols] -= body.mass * (self.gravity @ jc[-1].real)
            potential -= body.mass * float(self.gravity @ c[-1].real)
        h = np.einsum("kij,k,j->i", dg, v, v) - 0.5 * np.einsum("ijk,j,k->i", dg, v, v) + dv
        return mass, h, 0.5 * float(v @ mass @ v), potential
