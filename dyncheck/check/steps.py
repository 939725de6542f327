"""The step's Jacobian in a model check (``--derivatives``): MuJoCo's Jacobian of one
semi-implicit Euler, implicitfast and RK4 step (``mjd_transitionFD``, centered differences)
against the same step differentiated by the chain rule from the referee's continuous
derivatives — :func:`euler_step`: exact for Euler, and for implicitfast without damping or
actuators, whose implicit term is then M; :func:`rk4_step`: exact for RK4 through its four
stages, each with the referee's derivatives at the stage's state."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from dyncheck.adapters.layout import Canonical
from dyncheck.adapters.model_tree import JointType, ModelTree, Transition
from dyncheck.check.derivatives import Referee, referee
from dyncheck.check.describe import depth
from dyncheck.check.dynamics import States
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.results import Verdict
from dyncheck.vocabulary import Integrator


def _right_jacobian(phi: np.ndarray) -> np.ndarray:
    """SO(3)'s right Jacobian J_r(φ): exp(φ + δ) = exp(φ) exp(J_r(φ) δ) to first order."""
    theta = float(np.linalg.norm(phi))
    cross = np.array([[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]])
    if theta < 1e-8:
        return np.eye(3) - 0.5 * cross
    return (np.eye(3) - (1 - np.cos(theta)) / theta**2 * cross
            + (theta - np.sin(theta)) / theta**3 * cross @ cross)


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
            jr = _right_jacobian(phi)
            dq_q[rows] = turn @ eye[rows] + jr @ dv_q[rows] * h
            dq_v[rows] = jr @ dv_v[rows] * h
        out[s] = np.block([[dq_q, dq_v], [dv_q, dv_v]])
    return out


RK4_STAGES = ((0.0, 1.0 / 6), (0.5, 1.0 / 3), (0.5, 1.0 / 3), (1.0, 1.0 / 6))
"""RK4's tableau as (cᵢ: the stage's offset along the previous stage's slope, bᵢ: its
weight) — the classical method, as MuJoCo's ``mj_RungeKutta`` with N = 4."""


def rk4_stages(tree: ModelTree, states: States, ref: Referee,
               h: float) -> list[tuple[States, Referee]]:
    """The four stage states Xᵢ = x + cᵢ h Kᵢ₋₁ of one RK4 step (hinge and slide joints: q
    adds), each with the referee at it (its v̇ and derivatives; ``ref``: at x itself)."""
    out = [(states, ref)]
    for c, _ in RK4_STAGES[1:]:
        prev_states, prev = out[-1]
        at = States(q=states.q + c * h * prev_states.v, v=states.v + c * h * prev.forward,
                    a=states.a)
        out.append((at, referee(tree, at)))
    return out


def rk4_step(stages: list[tuple[States, Referee]], h: float) -> np.ndarray:
    """The Jacobian of one classical RK4 step of x = (q, v), ẋ = (v, v̇(q, v)), by the chain
    rule through its stages: dXᵢ = I + cᵢ h dKᵢ₋₁, dKᵢ = J(Xᵢ) dXᵢ with J = [[0, I], [∂v̇/∂q,
    ∂v̇/∂v]], dx₊ = I + h Σ bᵢ dKᵢ — exact for the step (hinge and slide joints, where q ⊕ δ
    = q + δ at every stage)."""
    n, nv = stages[0][0].v.shape
    eye = np.eye(2 * nv)
    total = np.zeros((n, 2 * nv, 2 * nv))
    slope = np.zeros((n, 2 * nv, 2 * nv))
    for (c, b), (_, ref) in zip(RK4_STAGES, stages, strict=True):
        jac = np.zeros((n, 2 * nv, 2 * nv))
        jac[:, :nv, nv:] = np.eye(nv)
        jac[:, nv:, :nv] = ref.derivatives.forward_q
        jac[:, nv:, nv:] = ref.derivatives.forward_v
        slope = jac @ (eye + c * h * slope)
        total += b * slope
    return eye + h * total


def step_rows(model: str, canon: Canonical, tree: ModelTree, states: States, ref: Referee,
              engine: str, found: Transition) -> list[CheckRow]:
    """The engine's step Jacobian against the referee's chain rule: one row. Tolerance:
    round-off, + the engine's finite-difference error estimated from its two steps (centered
    differences: error ≈ |A(2s) − A(s)| / 3) and their round-off 2 δx/(2 s) — δv₊ being
    h v̇'s round-off, κ(M) times its own —, + the referee's estimated error of its
    derivatives times h."""
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
        stages = rk4_stages(tree, states, ref, h)
        expected = rk4_step(stages, h)
        ref_q = np.max([r.error["forward_q"] for _, r in stages], axis=0)
        ref_v = np.max([r.error["forward_v"] for _, r in stages], axis=0)
        rule = "RK4's chain rule through its 4 stages"
    else:
        expected = euler_step(canon, ref, states, h)
        ref_q, ref_v = ref.error["forward_q"], ref.error["forward_v"]
        rule = "the chain rule"
    off = np.abs(found.matrix - expected)
    scale = float(np.abs(expected).max())
    x_scale = max(float(np.abs(states.q).max()), float(np.abs(states.v).max()), 1.0)
    nv = states.v.shape[1]
    fd = np.abs(found.coarse - found.matrix) / 3 + \
        2 * ROUNDOFF_FACTOR * EPS * depth(tree) * x_scale / (2 * found.fd_step)
    # v₊ = v + h v̇: v̇'s round-off is amplified by κ(M) (a point mass on a ball joint: the
    # file's 1e-8 inertia about the rod), and differenced over 2 s
    kappa = np.linalg.cond(ref.inverse_mass)[:, None, None]
    acceleration = np.abs(ref.forward).max(axis=1)[:, None, None]
    amplified = 2 * ROUNDOFF_FACTOR * EPS * depth(tree) * kappa * h * acceleration \
        / (2 * found.fd_step)
    fd[:, nv:] += amplified
    fd[:, :nv] += 2 * h * amplified  # q₊ = q ⊕ h v₊ (J_r ≤ 1 + h|ω|)
    ref_error = np.zeros_like(expected)
    ref_error[:, nv:, :nv] = h * ref_q  # RK4: Σ bᵢ = 1 of the stages' (largest) errors
    ref_error[:, nv:, nv:] = h * ref_v
    ref_error[:, :nv] = np.concatenate([h * ref_error[:, nv:, :nv], h * ref_error[:, nv:, nv:]],
                                       axis=2) * 2  # through q₊ = q ⊕ h v₊ (J_r ≤ 1 + h|ω|)
    allowed = ROUNDOFF_FACTOR * EPS * depth(tree) * scale + fd + ref_error
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
        basis=(f"round-off: {ROUNDOFF_FACTOR} eps x tree depth {depth(tree)}; + {engine}'s "
               f"centered differences' error (steps {found.fd_step:g}, {2 * found.fd_step:g}); "
               "+ the referee's estimated error x h"),
        verdict=Verdict.PASSED if within else Verdict.FAILED, note=note,
        worst_state=int(worst[0]))]
