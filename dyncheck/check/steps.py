"""The step's Jacobian in a model check (``--derivatives``): MuJoCo's Jacobian of one
semi-implicit Euler, implicitfast and RK4 step (``mjd_transitionFD``, centered differences)
against the same step differentiated by the chain rule from the referee's continuous
derivatives — :func:`euler_step`: exact for Euler, and for implicitfast without damping or
actuators, whose implicit term is then M; :func:`rk4_step`: exact for RK4 through its four
stages — Runge–Kutta–Munthe-Kaas on rotations, as MuJoCo ≥ 4.0 takes them —, each with the
referee's derivatives at the stage's state."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from dyncheck.adapters.model_tree import Canonical, JointType, ModelTree, Transition
from dyncheck.cases.quaternions import dexp_inv, quat_conj, quat_exp, quat_mul
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.referee.charts import right_jacobian, rotations, skew
from dyncheck.referee.computed import depth
from dyncheck.referee.derivatives import Referee, referee
from dyncheck.referee.states import States
from dyncheck.reference.recursive import RecursiveDynamics
from dyncheck.vocabulary import Integrator, Verdict


def euler_step(canon: Canonical, ref: Referee, states: States, h: float) -> np.ndarray:
    """The Jacobian of one semi-implicit Euler step — v₊ = v + h v̇(q, v), q₊ = q ⊕ h v₊ — in
    the canonical chart (δq at q and at q₊, both as q ⊕ δ), by the chain rule from the
    referee's continuous derivatives: exact for this integrator. A rotation turned by
    exp(h ω₊) moves δθ to exp(−h ω₊) δθ and takes δω₊ through h J_r(h ω₊)."""
    n, nv = states.v.shape
    fq, fv = ref.derivatives.forward_q, ref.derivatives.forward_v
    out = np.zeros((n, 2 * nv, 2 * nv))
    eye = np.eye(nv)
    for s in range(n):
        v_next = states.v[s] + h * ref.forward[s]
        dv_q, dv_v = h * fq[s], eye + h * fv[s]
        dq_q, dq_v = eye + h * dv_q, h * dv_v
        for j, kind in enumerate(canon.types):
            vs = canon.v_start[j]
            turning = range(vs + 3, vs + 6) if kind is JointType.FREE else \
                range(vs, vs + 3) if kind is JointType.BALL else range(0)
            if not len(turning):
                continue
            rows = slice(turning.start, turning.stop)
            phi = h * v_next[rows]
            turn = Rotation.from_rotvec(-phi).as_matrix()
            jr = right_jacobian(phi)
            dq_q[rows] = turn @ eye[rows] + jr @ dv_q[rows] * h
            dq_v[rows] = jr @ dv_v[rows] * h
        out[s] = np.block([[dq_q, dq_v], [dv_q, dv_v]])
    return out


RK4_STAGES = ((0.0, 1.0 / 6), (0.5, 1.0 / 3), (0.5, 1.0 / 3), (1.0, 1.0 / 6))
"""RK4's tableau as (cᵢ: the stage's offset along the previous stage's slope, bᵢ: its
weight) — the classical method, as MuJoCo's ``mj_RungeKutta`` with N = 4."""


def _vectors(canon: Canonical) -> tuple[list[int], list[int]]:
    """Velocity and position indices of the coordinates that add (hinge, slide, a free
    joint's position)."""
    vel: list[int] = []
    pos: list[int] = []
    for kind, qs, vs in zip(canon.types, canon.q_start, canon.v_start, strict=True):
        count = 3 if kind is JointType.FREE else 0 if kind is JointType.BALL else 1
        vel += range(vs, vs + count)
        pos += range(qs, qs + count)
    return vel, pos


def advance(canon: Canonical, q: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """q ⊕ θ for every state (rows): coordinates add, a rotation turns by exp(θ) on the right
    — the canonical chart, in which the referee's derivatives are taken."""
    out = q.copy()
    vel, pos = _vectors(canon)
    out[:, pos] += theta[:, vel]
    for va, qa in rotations(canon):
        turn = np.stack([quat_exp(t) for t in theta[:, va : va + 3]])
        out[:, qa : qa + 4] = quat_mul(out[:, qa : qa + 4].T, turn.T).T
    return out


def _rates(canon: Canonical, theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """kᵢ = dexp⁻¹(θᵢ) vᵢ on every rotation (:func:`dexp_inv`), vᵢ elsewhere."""
    out = v.copy()
    for va, _ in rotations(canon):
        out[:, va : va + 3] = [dexp_inv(t, w) for t, w in
                               zip(theta[:, va : va + 3], v[:, va : va + 3], strict=True)]
    return out


def _dexp_inv_k(angle: float) -> tuple[float, float]:
    """k(t) = 1/t² − (1 + cos t)/(2 t sin t) of dexp⁻¹ and its derivative k′(t) (series
    1/12 + t²/720 + t⁴/30240, t/360 + t³/7560 below 0.05 rad, where the closed forms cancel;
    the next terms are below 1e-12 of k there)."""
    if angle < 0.05:
        return (1 / 12 + angle**2 / 720 + angle**4 / 30240, angle / 360 + angle**3 / 7560)
    half = angle / 2
    k = 1 / angle**2 - (1 + np.cos(angle)) / (2 * angle * np.sin(angle))
    dk = -2 / angle**3 + (angle / np.sin(half)**2 + 2 / np.tan(half)) / (4 * angle**2)
    return float(k), float(dk)


def dexp_inv_matrices(theta: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """D = ∂(dexp⁻¹(θ) v)/∂v and E = ∂(dexp⁻¹(θ) v)/∂θ of one rotation, from
    dexp⁻¹(θ) v = v + ½ θ × v + k(|θ|) θ × (θ × v): D = 1 + ½ [θ]× + k [θ]×², E = −½ [v]× +
    k ((θ·v) 1 + θ vᵀ − 2 v θᵀ) + k′ (θ × (θ × v)) θᵀ/|θ|."""
    angle = float(np.linalg.norm(theta))
    k, dk = _dexp_inv_k(angle)
    cross = skew(theta)
    d = np.eye(3) + 0.5 * cross + k * cross @ cross
    e = -0.5 * skew(v) + k * (float(theta @ v) * np.eye(3) + np.outer(theta, v)
                               - 2 * np.outer(v, theta))
    if angle > 0:
        e += dk * np.outer(np.cross(theta, np.cross(theta, v)), theta / angle)
    return d, e


def rk4_stages(canon: Canonical, tree: ModelTree, states: States, ref: Referee,
               h: float) -> list[tuple[States, Referee, np.ndarray]]:
    """The four stages of one RK4 step as MuJoCo (≥ 4.0) takes them, Runge–Kutta–Munthe-Kaas
    on rotations: θᵢ = cᵢ h kᵢ₋₁, Qᵢ = q ⊕ θᵢ, vᵢ = v + cᵢ h v̇ᵢ₋₁, kᵢ = dexp⁻¹(θᵢ) vᵢ (vᵢ
    where coordinates add) — each stage's state with the referee at it and its θᵢ."""
    theta = np.zeros_like(states.v)
    out = [(states, ref, theta)]
    for c, _ in RK4_STAGES[1:]:
        prev_states, prev, prev_theta = out[-1]
        theta = c * h * _rates(canon, prev_theta, prev_states.v)
        at = States(q=advance(canon, states.q, theta),
                    v=states.v + c * h * prev.forward, a=states.a)
        out.append((at, referee(tree, at, bounds=False, tied=ref.tie), theta))
    return out


def rk4_step(canon: Canonical, stages: list[tuple[States, Referee, np.ndarray]],
             h: float) -> np.ndarray:
    """The Jacobian of one RK4 step (:func:`rk4_stages`) of x = (q, v) in the canonical chart,
    by the chain rule through its stages: dθᵢ = cᵢ h dkᵢ₋₁, dvᵢ = dv + cᵢ h dv̇ᵢ₋₁, dQᵢ =
    R(θᵢ)ᵀ dq + J_r(θᵢ) dθᵢ on rotations (dq + dθᵢ elsewhere), dv̇ᵢ = ∂v̇/∂q dQᵢ + ∂v̇/∂v dvᵢ
    (the referee's, at the stage), dkᵢ = D(θᵢ) dvᵢ + E(θᵢ, vᵢ) dθᵢ; then dΘ = h Σ bᵢ dkᵢ,
    dq₊ = R(Θ)ᵀ dq + J_r(Θ) dΘ, dv₊ = dv + h Σ bᵢ dv̇ᵢ — exact for the step. Where every
    coordinate adds (hinge and slide joints) R, J_r, D are 1 and E is 0: the classical
    chain rule."""
    n, nv = stages[0][0].v.shape
    angular = [va for va, _ in rotations(canon)]
    eye = np.eye(nv)
    out = np.zeros((n, 2 * nv, 2 * nv))
    dq0 = np.hstack([eye, np.zeros((nv, nv))])
    dv0 = np.hstack([np.zeros((nv, nv)), eye])

    def turned(theta: np.ndarray, dtheta: np.ndarray) -> np.ndarray:
        """d(q ⊕ θ) = R(θ)ᵀ dq + J_r(θ) dθ (rotations), dq + dθ (elsewhere)."""
        moved = dq0 + dtheta
        for va in angular:
            rows = slice(va, va + 3)
            moved[rows] = Rotation.from_rotvec(-theta[rows]).as_matrix() @ dq0[rows] \
                + right_jacobian(theta[rows]) @ dtheta[rows]
        return moved

    for s in range(n):
        dk = df = np.zeros((nv, 2 * nv))
        total_k = np.zeros((nv, 2 * nv))
        total_f = np.zeros((nv, 2 * nv))
        for (c, b), (at, ref, theta) in zip(RK4_STAGES, stages, strict=True):
            dtheta = c * h * dk
            dv = dv0 + c * h * df
            df = ref.derivatives.forward_q[s] @ turned(theta[s], dtheta) \
                + ref.derivatives.forward_v[s] @ dv
            dk = dv.copy()
            for va in angular:
                rows = slice(va, va + 3)
                d, e = dexp_inv_matrices(theta[s, rows], at.v[s, rows])
                dk[rows] = d @ dv[rows] + e @ dtheta[rows]
            total_k += b * dk
            total_f += b * df
        big_theta = h * sum(b * _rates(canon, theta[s : s + 1], at.v[s : s + 1])[0]
                            for (_, b), (at, _, theta) in zip(RK4_STAGES, stages, strict=True))
        out[s, :nv] = turned(big_theta, h * total_k)
        out[s, nv:] = dv0 + h * total_f
    return out


def _free_step(solver: RecursiveDynamics, canon: Canonical, q: np.ndarray, v: np.ndarray,
               h: float, joint: int) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's implicitfast step of the standalone free body of canonical joint ``joint``,
    at every state (rows): v₊ = v + h (M + h B)⁻¹ (−h_bias) on its block, B = ∂h_bias/∂v
    there (exact by a central difference: h_bias is quadratic in v), q₊ = q ⊕ h v₊. The
    body is alone in its tree: its block of M and h_bias depends on its own state only."""
    vs, nv = canon.v_start[joint], canon.nv
    block = slice(vs, vs + 6)
    mass, bias, _, _ = solver.at_states(q, v)
    spread = max(1.0, float(np.abs(v).max()))
    nudged = np.repeat(v[None], 12, axis=0)
    for k in range(6):
        nudged[2 * k, :, vs + k] += spread
        nudged[2 * k + 1, :, vs + k] -= spread
    _, bias_w, _, _ = solver.at_states(np.tile(q, (12, 1)), nudged.reshape(-1, nv))
    bias_w = bias_w.reshape(12, len(q), nv)[:, :, block]
    slope = np.stack([(bias_w[2 * k] - bias_w[2 * k + 1]) / (2 * spread) for k in range(6)],
                     axis=-1)
    implicit = mass[:, block, block] + h * slope
    v_next = v[:, block] + h * np.linalg.solve(implicit, -bias[:, block, None])[..., 0]
    theta = np.zeros_like(v)
    theta[:, block] = h * v_next
    return advance(canon, q, theta), v_next


def implicit_blocks(canon: Canonical, tree: ModelTree, states: States, h: float,
                    joints: tuple[str, ...]) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """Per standalone free body (``joints``, MuJoCo's implicitfast with the bias's derivative
    in its block): (its canonical joint, the 12×12 Jacobian of its step in the canonical
    chart — δq₊ its position in world axes and its turn in body axes, δv₊ —, an estimate of
    that Jacobian's error), by central differences of :func:`_free_step` at steps s, s/2,
    s/4 extrapolated twice (Richardson: error O(s⁶)), the estimate the two first
    extrapolations' difference plus the round-off of x₊ over the smallest step."""
    if not joints:
        return []
    from dyncheck.referee.charts import perturb
    from dyncheck.referee.derivatives import STEP
    from dyncheck.referee.tree import ReferenceModel

    solver = ReferenceModel(tree).recursive
    q, v = states.q, states.v
    n = len(q)
    steps = STEP / np.array([1.0, 2.0, 4.0])
    out = []
    for name in joints:
        joint = canon.names.index(name)
        vs, qs = canon.v_start[joint], canon.q_start[joint]
        q_base, v_base = _free_step(solver, canon, q, v, h, joint)
        q_p, v_p = [], []
        for s in steps:
            for sign in (1.0, -1.0):
                for k in range(12):
                    q_p.append(perturb(canon, q, vs + k, sign * s) if k < 6 else q)
                    nudged = v.copy()
                    if k >= 6:
                        nudged[:, vs + k - 6] += sign * s
                    v_p.append(nudged)
        q_next, v_next = _free_step(solver, canon, np.concatenate(q_p), np.concatenate(v_p),
                                    h, joint)
        q_next, v_next = q_next.reshape(3, 2, 12, n, -1), v_next.reshape(3, 2, 12, n, 6)
        base = np.broadcast_to(q_base, q_next.shape)
        turn = quat_mul(quat_conj(base[..., qs + 3 : qs + 7].reshape(-1, 4).T),
                        q_next[..., qs + 3 : qs + 7].reshape(-1, 4).T).T
        moved = np.concatenate([q_next[..., qs : qs + 3] - base[..., qs : qs + 3],
                                Rotation.from_quat(turn, scalar_first=True).as_rotvec()
                                .reshape(*q_next.shape[:-1], 3),
                                v_next - v_base], axis=-1)  # (step, sign, k, state, 12)
        central = (moved[:, 0] - moved[:, 1]) / (2 * steps[:, None, None, None])
        first = (4 * central[1] - central[0]) / 3
        second = (4 * central[2] - central[1]) / 3
        best = np.transpose((16 * second - first) / 15, (1, 2, 0))  # (state, row, column)
        scale = np.maximum(np.abs(np.concatenate([q_base, v_base], axis=1)).max(axis=1), 1.0)
        roundoff = ROUNDOFF_FACTOR * EPS * depth(tree) * scale / steps[-1]
        estimate = np.abs(np.transpose(second - first, (1, 2, 0))) / 15 \
            + roundoff[:, None, None]
        out.append((joint, best, estimate))
    return out


def _block(canon: Canonical, joint: int) -> np.ndarray:
    """A free joint's rows of x = (δq, v): its six chart coordinates, then its velocities."""
    vs = canon.v_start[joint]
    return np.r_[vs : vs + 6, canon.nv + vs : canon.nv + vs + 6]




def step_rows(model: str, canon: Canonical, tree: ModelTree, states: States, ref: Referee,
              engine: str, found: Transition, *, of: int = 0) -> list[CheckRow]:
    """The engine's step Jacobian against the referee's chain rule: one row. Tolerance:
    round-off, + the engine's finite-difference error estimated from its two steps (centered
    differences: error ≈ |A(2s) − A(s)| / 3) and their round-off 2 δx/(2 s) — δv₊ being
    h v̇'s round-off, κ(M) times its own —, + the referee's own round-off in its
    derivatives times h. ``of``: the states sampled, where the step Jacobians are compared at
    fewer (:func:`~dyncheck.referee.derivatives.step_states`): the basis says so."""
    h = found.time_step
    rk4 = found.integrator == Integrator.RK4
    why = found.unfollowed
    if why:
        return [CheckRow(
            model=model, section=Section.DERIVATIVES,
            subject=f"step Jacobian ({found.integrator} at h = {h:g})", field="max rel error",
            impl_a="reference", impl_b=engine, value_a="", value_b="", error=float("nan"),
            tolerance=float("nan"), basis="", verdict=Verdict.SKIPPED,
            note=why)]
    if rk4:
        stages = rk4_stages(canon, tree, states, ref, h)
        expected = rk4_step(canon, stages, h)
        ref_q = np.max([r.error["forward_q"] for _, r, _ in stages], axis=0)
        ref_v = np.max([r.error["forward_v"] for _, r, _ in stages], axis=0)
        rule = "RK4's chain rule through its 4 stages"
    else:
        expected = euler_step(canon, ref, states, h)
        ref_q, ref_v = ref.error["forward_q"], ref.error["forward_v"]
        rule = "the chain rule"
    blocks = implicit_blocks(canon, tree, states, h, found.implicit_bias)
    for joint, block, _ in blocks:  # a standalone free body: M + h ∂h/∂v in its solve
        rows = _block(canon, joint)
        expected[:, rows[:, None], rows[None, :]] = block
    if blocks:
        rule += " (a standalone free body's implicit block differentiated by Richardson)"
    off = np.abs(found.matrix - expected)
    scale = float(np.abs(expected).max())
    x_scale = max(float(np.abs(states.q).max()), float(np.abs(states.v).max()), 1.0)
    nv = states.v.shape[1]
    fd = np.abs(found.coarse - found.matrix) / 3 + \
        2 * ROUNDOFF_FACTOR * EPS * depth(tree) * x_scale / (2 * found.fd_step)
    # v₊ = v + h v̇: v̇'s round-off is amplified by κ(M) (a point mass on a ball joint: the
    # file's 1e-8 inertia about the rod) and by X/ℓ (the engine's lever arms, differences of
    # positions far from the origin), and differenced over 2 s
    kappa = np.linalg.cond(ref.inverse_mass)[:, None, None]
    acceleration = np.abs(ref.forward).max(axis=1)[:, None, None]
    amplified = 2 * ROUNDOFF_FACTOR * EPS * depth(tree) * ref.standing * kappa * h \
        * acceleration / (2 * found.fd_step)
    fd[:, nv:] += amplified
    fd[:, :nv] += 2 * h * amplified  # q₊ = q ⊕ h v₊ (J_r ≤ 1 + h|ω|)
    ref_error = np.zeros_like(expected)
    ref_error[:, nv:, :nv] = h * ref_q  # RK4: Σ bᵢ = 1 of the stages' (largest) errors
    ref_error[:, nv:, nv:] = h * ref_v
    ref_error[:, :nv] = np.concatenate([h * ref_error[:, nv:, :nv], h * ref_error[:, nv:, nv:]],
                                       axis=2) * 2  # through q₊ = q ⊕ h v₊ (J_r ≤ 1 + h|ω|)
    for joint, _, estimate in blocks:
        rows = _block(canon, joint)
        ref_error[:, rows[:, None], rows[None, :]] = estimate
    allowed = ROUNDOFF_FACTOR * EPS * depth(tree) * ref.standing * scale + fd + ref_error
    worst = np.unravel_index(int(np.argmax(off / allowed)), off.shape)
    within = bool(np.all(off <= allowed))
    note = "" if within else (
        f"{engine} differs from {rule} at state {worst[0]}, entry ({worst[1]}, "
        f"{worst[2]}): {off[worst]:.3g} beyond its predicted {allowed[worst]:.3g}")
    return [CheckRow(
        model=model, section=Section.DERIVATIVES,
        subject=f"step Jacobian ({found.integrator} at h = {h:g})", field="max rel error",
        impl_a="reference", impl_b=engine, value_a="", value_b="",
        error=float(off.max()) / scale, tolerance=float(allowed.max()) / scale,
        basis=(f"round-off: {ROUNDOFF_FACTOR} eps x tree depth {depth(tree)}"
               + (f" x X/l {ref.standing:.3g} (positions far from the origin)"
                  if ref.standing > 1 else "") + f"; + {engine}'s "
               f"centered differences' error (steps {found.fd_step:g}, {2 * found.fd_step:g}); "
               "+ the referee's own round-off x h"
               + ("; a standalone free body's implicit block: its Richardson estimate"
                  if blocks else "")
               + (f"; at the first {len(states.q)} of {of} states (the step Jacobians' "
                  "budget: an engine's differences of its step cost O(nv^2 depth) a state)"
                  if of > len(states.q) else "")),
        verdict=Verdict.PASSED if within else Verdict.FAILED, note=note,
        worst_state=int(worst[0]))]
