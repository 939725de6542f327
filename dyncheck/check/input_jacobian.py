"""∂x₊/∂u in a model check: an engine's Jacobian of one step in its controls (MuJoCo's B, by
``mjd_transitionFD``; MJX's, by JAX's ``jacfwd`` through ``mjx.step``) against the chain
rule through the referee — the book's general method on the engine's reading for M and h
((2.2.23)–(2.2.24)), the clean-room actuator law of
:mod:`dyncheck.reference.actuation` for τ(u) —, differentiated in u by a complex step:

    semi-implicit Euler:  v₊ = v + h M⁻¹ (τ(q, v, u) − h(q, v)),
    implicitfast:         v₊ = v + h (M − h ∂τ/∂v)⁻¹ (τ(q, v, u) − h(q, v)),
    q₊ = q ⊕ h v₊ (a rotation's tangent through J_r(h ω₊), as in :mod:`.steps`),
    act₊ = act + h ȧ(u, act) (the filter's exact step where asked for),

with the activation state equal to the control (as the engine's side sets it). The controls
are sampled inside their ranges (a step's differences across a clamp's corner would measure
neither side)."""

from __future__ import annotations

import numpy as np

from dyncheck import labels
from dyncheck.adapters.actuators import EULER_DAMPING, InputJacobian
from dyncheck.adapters.model_tree import Canonical, ModelTree
from dyncheck.check.rows import COMPUTED, CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.referee.charts import right_jacobian, rotations
from dyncheck.referee.computed import depth
from dyncheck.reference import actuation as law
from dyncheck.vocabulary import Integrator, Verdict

COMPLEX_STEP = 1e-30
"""The complex step in u: exact to round-off whatever its size (no subtraction)."""


def chain_rule(canon: Canonical, acts: law.JointActuators, *, mass: np.ndarray,
               bias: np.ndarray, q: np.ndarray, v: np.ndarray, u: np.ndarray, h: float,
               integrator: str) -> np.ndarray:
    """The referee's ∂x₊/∂u at one state (2 nv + na, nu), x = (δq, v, act)."""
    nv, nu = len(v), len(u)
    stateful = np.flatnonzero(acts.stateful)
    out = np.zeros((2 * nv + len(stateful), nu))
    implicit = integrator == Integrator.IMPLICITFAST
    for k in range(nu):
        pushed = u.astype(complex)
        pushed[k] += 1j * COMPLEX_STEP
        tau = law.generalized_force(acts, q[None], v[None], pushed[None], act=u[None])[0]
        solve = mass - h * law.velocity_derivative(acts, q[None], v[None], pushed[None],
                                                   act=u[None])[0] if implicit else mass
        v_next = v + h * np.linalg.solve(solve, tau - bias)
        act_next = law.activation_step(acts, pushed[None], u[None].astype(complex), h)[0]
        dv = v_next.imag / COMPLEX_STEP
        dq = h * dv
        for va, _ in rotations(canon):  # a ball's, a free joint's angular velocity
            turning = slice(va, va + 3)
            dq[turning] = right_jacobian(h * v_next.real[turning]) @ (h * dv[turning])
        out[:nv, k], out[nv:2 * nv, k] = dq, dv
        out[2 * nv:, k] = act_next.imag[stateful] / COMPLEX_STEP
    return out


def rows(model: str, *, canon: Canonical, tree: ModelTree, acts: law.JointActuators,
         mass: np.ndarray, bias: np.ndarray, q: np.ndarray, v: np.ndarray, u: np.ndarray,
         found: InputJacobian, damping: np.ndarray | None = None) -> CheckRow:
    """The engine's B against :func:`chain_rule` at every state: one row. Tolerance as the
    step Jacobian's (:func:`dyncheck.check.steps.step_rows`): round-off in the engine's ε,
    and for finite differences their error |B(2s) − B(s)|/3 and their round-off over 2 s,
    v₊'s round-off amplified by κ(M); for automatic differentiation (MJX's), the round-off of
    h M⁻¹ ∂τ/∂u, c ε × depth × κ(M) of the largest entry. ``damping`` (per degree of
    freedom, canonical layout): the engine's Euler step is known to damp implicitly though
    the model's dampers are off (its tree's hint :data:`EULER_DAMPING` says why); a B that
    fails the chain rule but meets it with M + h D is explained, the predicted and the
    measured size on the row."""
    h, engine = found.time_step, tree.engine
    expected = _expected(canon, acts, mass=mass, bias=bias, q=q, v=v, u=u, h=h,
                         integrator=found.integrator)
    off = np.abs(found.matrix - expected)
    # B's scale: its largest entry, the engine's where the chain rule's is 0 (a B the
    # engine finds where none is due is then wrong by 100 %); 1 where both are 0, the
    # error and bound then absolute (a floor of 1e-300 had made the bound ~1e295)
    scale = max(float(np.abs(expected).max(initial=0.0)),
                float(np.abs(found.matrix).max(initial=0.0))) or 1.0
    eps = max(EPS, tree.eps)
    kappa = np.linalg.cond(mass)[:, None, None]
    roundoff = ROUNDOFF_FACTOR * eps * depth(tree)
    if found.differentiated:
        allowed = roundoff * kappa * scale * np.ones_like(off)
        method = (f"{engine}'s automatic differentiation: round-off {ROUNDOFF_FACTOR} eps "
                  f"{eps:.3g} x tree depth {depth(tree)} x cond(M) (up to "
                  f"{float(kappa.max()):.3g})")
    else:
        x_scale = max(float(np.abs(q).max()), float(np.abs(v).max()),
                      float(np.abs(u).max()), 1.0)
        acceleration = np.abs(np.linalg.solve(mass, bias[..., None])[..., 0]).max(axis=1)
        amplified = (2 * roundoff * kappa * h * (acceleration[:, None, None] + x_scale)
                     / (2 * found.fd_step))
        fd = np.abs(found.coarse - found.matrix) / 3 + \
            2 * roundoff * x_scale / (2 * found.fd_step) + amplified
        allowed = roundoff * scale + fd
        method = (f"round-off {ROUNDOFF_FACTOR} eps x tree depth {depth(tree)}; + "
                  f"{engine}'s centered differences' error (steps {found.fd_step:g}, "
                  f"{2 * found.fd_step:g})")
    worst = np.unravel_index(int(np.argmax(off / allowed)), off.shape)
    within = bool(np.all(off <= allowed))
    verdict = Verdict.PASSED if within else Verdict.FAILED
    convention = ""
    note = "" if within else (
        f"{engine} differs from the chain rule at state {worst[0]}, entry ({worst[1]}, "
        f"{worst[2]}): {off[worst]:.3g} beyond its predicted {allowed[worst]:.3g}: "
        "cause unknown")
    if not within and damping is not None and found.integrator == Integrator.EULER:
        damped = _expected(canon, acts, mass=mass + h * np.diag(damping), bias=bias, q=q,
                           v=v, u=u, h=h, integrator=found.integrator)
        if np.all(np.abs(found.matrix - damped) <= allowed):
            verdict, convention = Verdict.EXPLAINED, labels.EULER_DAMPING
            note = (f"{tree.hint('model', EULER_DAMPING)}: predicted "
                    f"{float(np.abs(damped - expected).max()) / scale:.3g} of B's scale, "
                    f"measured {float(off.max()) / scale:.3g}; with M + h D it meets the "
                    "chain rule within the bound")
    return CheckRow(
        model=model, section=Section.ACTUATION,
        subject=f"step Jacobian in the controls ({found.integrator} at h = {h:g})",
        field=COMPUTED, impl_a="reference", impl_b=engine, value_a="", value_b="",
        error=float(off.max()) / scale, tolerance=float(allowed.max()) / scale,
        basis=(f"the chain rule through the referee's M, h and actuator law (complex step "
               f"in u); {method}; controls inside their ranges"),
        verdict=verdict, note=note, convention=convention, worst_state=int(worst[0]))


def _expected(canon: Canonical, acts: law.JointActuators, *, mass: np.ndarray,
              bias: np.ndarray, q: np.ndarray, v: np.ndarray, u: np.ndarray, h: float,
              integrator: str) -> np.ndarray:
    """:func:`chain_rule` at every state."""
    return np.stack([chain_rule(canon, acts, mass=mass[s], bias=bias[s], q=q[s], v=v[s],
                                u=u[s], h=h, integrator=integrator) for s in range(len(q))])



CONTROL_DERIVATIVE = "d(forward)/d(u)"


def derivative_row(model: str, *, tree: ModelTree, acts: law.JointActuators, maps: list,
                   q: np.ndarray, v: np.ndarray, u: np.ndarray, mass: np.ndarray,
                   found: np.ndarray) -> CheckRow:
    """An engine's own ∂v̇/∂u (its layout, mapped by T⁻¹, v_e = T v) against the referee's
    M⁻¹ Tᵀ ∂τ/∂u on its reading (``mass``: the referee's M on it, canonical layout; ∂τ/∂u
    of the clean-room law by a complex step). Round-off: c ε × depth × κ(M)."""
    nu = u.shape[1]
    dtau = np.zeros((len(q), v.shape[1], nu))
    for k in range(nu):
        pushed = u.astype(complex)
        pushed[:, k] += 1j * COMPLEX_STEP
        dtau[:, :, k] = law.generalized_force(acts, q, v, pushed, act=u).imag / COMPLEX_STEP
    t = np.array([s.t for s in maps])
    expected = np.linalg.solve(mass, np.swapaxes(t, 1, 2) @ dtau)
    mapped = np.linalg.solve(t, found)
    kappa = float(np.max(np.linalg.cond(mass), initial=1.0))
    tolerance = ROUNDOFF_FACTOR * max(EPS, tree.eps) * depth(tree) * kappa
    off = np.abs(mapped - expected)
    scale = max(float(np.abs(expected).max(initial=0.0)), 1e-300)
    error = float(off.max(initial=0.0)) / scale
    worst = int(np.argmax(off.reshape(len(q), -1).max(axis=1))) if off.size else -1
    ok = error <= tolerance
    engine = tree.engine
    return CheckRow(
        model=model, section=Section.ACTUATION, subject=CONTROL_DERIVATIVE, field=COMPUTED,
        impl_a="reference", impl_b=engine, value_a="", value_b="", error=error,
        tolerance=tolerance,
        basis=(f"{engine}'s own derivative against the referee's M⁻¹ ∂τ/∂u on its reading "
               f"(complex step in u); round-off {ROUNDOFF_FACTOR} eps x tree depth "
               f"{depth(tree)} x cond(M) {kappa:.3g}; controls inside their ranges"),
        verdict=Verdict.PASSED if ok else Verdict.FAILED,
        note="" if ok else (tree.hint("model", "control derivatives") or "cause unknown"),
        worst_state=worst)
