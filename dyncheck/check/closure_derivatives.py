"""The derivatives of a closed tree's forward dynamics (#78): an engine's own ∂v̇/∂(q, v) with
its constraints on (MuJoCo: ``mjd_transitionFD`` of its constrained step) against central
differences of the referee's constrained method on the engine's reading of them — the soft
model with the engine's parameters where it holds them softly, the rigid answer where it holds
them rigidly (:func:`.closures.referee`; Lagrange (2.2.23)–(2.2.26) closed by J v̇ = −J̇ v) —
at the first :data:`STATES` states on the constraints. A soft model is defined at every
state and compared in every direction; a rigid one only on the constraint manifold, and is
compared along it (:func:`along`), as is a weld holding a rotation (:func:`on_manifold`).

Compared in MuJoCo's chart (the canonical layout's): q ⊕ δ adds on hinges and slides, moves
a free body by its world displacement and turns a ball or a free body by exp(δ) in its own
axes (``mj_integratePos``; the referee's :func:`~dyncheck.reference.closure.retract`). An
engine holding other velocities (Pinocchio's free flyer: its linear velocity in the body's
axes) differentiates in its own chart, mapped into MuJoCo's (:func:`_mapped`). The
tolerance is measured, not chosen: each side's
finite-difference error is bounded by twice the gap g between its differences at its step δ
and at 2δ — where truncation (∝ δ²) dominates, the error of the finer is g/3; where round-off
(∝ 1/δ) does, at most 2g (errors of one sign: c/δ − c/2δ = g) — plus 64 ε; the error is
relative to the largest derivative of each block (∂/∂q, ∂/∂v), at least 1 (s⁻², s⁻¹).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from dyncheck.adapters import layout
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.model_tree import Canonical, ModelTree
from dyncheck.check import closures
from dyncheck.check.rows import CheckRow, Section
from dyncheck.errors import EngineError, Unsupported
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.referee.computed import bodies
from dyncheck.reference.closure import retract
from dyncheck.reference.tree import TreeDynamics
from dyncheck.vocabulary import REFEREE, Verdict

STATES = 8
"""States whose derivatives are compared (each costs the referee 8 nv solves)."""
STEP = 1e-7
"""The referee's central-difference step: small against the lengths over which a soft
model's impedance changes (solimp's width, 1e-3 m by default; truncation ~ (δ/width)²),
large against round-off (ε |v̇| / δ). Measured on the four-bar's q block: the gap between its
differences at δ and 2δ is 5.9e-5 at 1e-7, against 1.5e-4 at 1e-8 and 0.60 at 1e-5."""
OWN_STEP = 1e-4
"""The step of the engine's own differences where its derivatives are not the referee's
(:func:`_why`): its forward dynamics may come from an iterative solver exact only to its
stopping accuracy (Pinocchio's proximal solver on the four-bar on a free base: 1.6e-7 m/s²
apart between nearby states, measured), which at the referee's step would swamp the
differences; at 1e-4 that is 1.6e-3 of them, truncation ~1e-8."""
MAP_STEP = 1e-6
"""The central-difference step of the layout map's own derivatives (:func:`_map_rates`):
truncation ~1e-12, round-off ~1e-10 of its entries (order one)."""
BASIS = "2 x each side's finite-difference gap between its step and twice it, + 64 eps"
SPREAD_FACTOR = 2.0
"""A central difference's error per unit of its gap to the one at twice the step (round-off
bound; truncation needs 1/3)."""
SUBJECT = "derivatives"


def _row(model: str, engine: str, *, verdict: Verdict, note: str, error: float = 0.0,
         tolerance: float = 0.0) -> CheckRow:
    return CheckRow(model=model, section=Section.CLOSURES, subject=SUBJECT,
                    field="max rel error", impl_a=REFEREE, impl_b=engine, value_a="",
                    value_b="", error=error, tolerance=tolerance,
                    basis=BASIS if tolerance else "", verdict=verdict, note=note)


def _perturbed(tree: ModelTree, q: np.ndarray, v: np.ndarray, *,
               step: float = STEP) -> tuple[np.ndarray, np.ndarray]:
    """Every state moved by ±δ and ±2δ (``step``) along each q direction of MuJoCo's
    chart (the referee's ``retract``) and each v coordinate: (S · 2 steps · 2 signs · 2 nv)
    states."""
    s, nv = v.shape
    cols = np.eye(2 * nv)
    shift = np.array([[sign * size * cols for sign in (1.0, -1.0)]
                      for size in (step, 2 * step)])  # (2 steps, 2 signs, 2nv, 2nv)
    count = shift.shape[0] * shift.shape[1] * shift.shape[2]
    dq = np.broadcast_to(shift[None, ..., :nv], (s, *shift.shape[:3], nv)).reshape(-1, nv)
    solver = TreeDynamics(bodies(tree), tree.gravity)
    return (retract(solver, np.repeat(q, count, axis=0), dq),
            (v[:, None, None, None, :] + shift[None, ..., nv:]).reshape(-1, nv))


def differences(vdot: np.ndarray, s: int, nv: int, *, step: float = STEP) -> np.ndarray:
    """Central differences (S, 2, nv, 2 nv) of v̇ at the :func:`_perturbed` states."""
    found = vdot.reshape(s, 2, 2, 2 * nv, nv)
    steps = np.array([step, 2 * step])[None, :, None, None]
    return np.swapaxes((found[:, :, 0] - found[:, :, 1]) / (2 * steps), 2, 3)


def _referee(tree: ModelTree, q: np.ndarray, v: np.ndarray,
             diagonal: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Central differences of the referee's v̇ (:func:`differences`), every perturbed state
    in one call; and, from the same calls, its rows J (S, m, nv) and ∂(J v)/∂q (S, m, nv)
    at the states."""
    s, nv = v.shape
    qs, vs = _perturbed(tree, q, v)
    answer = closures.referee(tree, qs, vs, tau=np.zeros_like(vs),
                              diagonal=np.repeat(diagonal, 4 * 2 * nv, axis=0))
    rows = answer.rows.jacobian.reshape(s, 2, 2, 2 * nv, -1, nv)[:, 0, :, :nv]
    jac = rows[:, 0, 0] / 2 + rows[:, 1, 0] / 2  # (J at q ± δ e₀, averaged: O(δ²))
    turn = np.einsum("sjmn,sn->smj", rows[:, 0] - rows[:, 1], v)
    return differences(answer.soft, s, nv), jac, turn / (2 * STEP)


def along(d: np.ndarray, jac: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Derivatives (S, 2, nv, 2 nv) along the constraint manifold only (S, 2, nv, 2 k):
    along δq = T z (T a basis of J's null space) with the δv = −J⁺ ∂(J v)/∂q T z that keeps
    J v = 0, and along δv = T z. A rigid constraint's dynamics is defined on the manifold
    alone: off it, each way of writing the rows (world or body axes) gives its own v̇, and its
    derivatives there are the formulation's, not the mechanism's."""
    s, _, nv, _ = d.shape
    out = []
    for k in range(s):
        u, sv, vt = np.linalg.svd(jac[k])
        rank = int(np.sum(sv > closures.RANK_RTOL * sv[0])) if sv.size and sv[0] > 0 else 0
        basis = vt[rank:].T
        pinv = vt[:rank].T @ np.diag(1 / sv[:rank]) @ u[:, :rank].T
        follow = -pinv @ turn[k] @ basis
        out.append(np.concatenate([d[k, :, :, :nv] @ basis + d[k, :, :, nv:] @ follow,
                                   d[k, :, :, nv:] @ basis], axis=2))
    return np.array(out)


def on_manifold(tree: ModelTree) -> bool:
    """Whether the derivatives are compared along the constraint manifold alone: a rigid
    reading (defined on it alone), or a weld holding a rotation — off the manifold its soft
    answer depends on how the rotation's error is written (the referee: log(R₁ R₂ᵀ), rows
    ω₁ − ω₂; MuJoCo: torquescale times the error quaternion's vector, rows its exact
    derivative — measured on the weld test model off the manifold, ``efc_J`` = ∂``efc_pos``/∂q
    to 2e-11), whose rows differ at first order in the error, so at O(1) in the derivatives
    across the manifold; along it the error and its first-order change vanish."""
    return not any(c.soft for c in tree.closures) or bool(closures.rotation_rows(tree).any())


def _gaps(mine: np.ndarray, ref: np.ndarray, nv: int) -> tuple[float, float]:
    """The error and its tolerance, each block (the first ``nv`` columns, the rest) relative
    to its scale."""
    error = tolerance = 0.0
    for block in (slice(0, nv), slice(nv, 2 * nv)):
        scale = max(float(np.abs(ref[:, 0, :, block]).max(initial=0.0)), 1.0)
        gap = float(np.abs(mine[:, 0, :, block] - ref[:, 0, :, block]).max(initial=0.0))
        spread = float(np.abs(mine[:, 0, :, block] - mine[:, 1, :, block]).max(initial=0.0)
                       + np.abs(ref[:, 0, :, block] - ref[:, 1, :, block]).max(initial=0.0))
        error, tolerance = max(error, gap / scale), max(tolerance, spread / scale)
    return error, SPREAD_FACTOR * tolerance + ROUNDOFF_FACTOR * EPS


def rows(model: str, name: str, engine: ModelEngine, states: closures.ClosedStates, *,
         canon: Canonical, tree: ModelTree, reading: ClosedReading,
         own: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> list[CheckRow]:
    """The engine's derivatives row (none where it offers none): ``tree`` its reading of
    the closures in the canonical layout, ``reading`` its answer at ``states``, ``own`` its
    constrained v̇ at canonical states (to measure, where it differs, whether its derivatives
    are those of its own forward dynamics)."""
    q, v = states.q[:STATES], states.v[:STATES]
    _, q_e, v_e, _ = layout.engine_states(canon, engine.tree, q, v, np.zeros_like(v))
    try:
        found = engine.closed_derivatives(q_e, v_e, np.zeros_like(v_e))
    except Unsupported as exc:
        return [_row(model, name, verdict=Verdict.SKIPPED, note=str(exc))]
    except EngineError as exc:
        return [_row(model, name, verdict=Verdict.FAILED, note=f"{name} failed: {exc}")]
    mine = _mapped(canon, engine.tree, tree, q=q, v=v, found=found,
                   vdot=reading.vdot[: len(q)])
    ref, jac, turn = _referee(tree, q, v,
                              reading.diagonal[: len(q), closures.engine_rows(tree)])
    if on_manifold(tree):
        mine, ref = along(mine, jac, turn), along(ref, jac, turn)
    error, tolerance = _gaps(mine, ref, mine.shape[3] // 2)
    ok = error <= tolerance
    return [_row(model, name, verdict=Verdict.PASSED if ok else Verdict.FAILED,
                 error=error, tolerance=tolerance,
                 note="∂v̇/∂(q, v) with its constraints, against the referee's (central "
                      "differences of its constrained method on this reading)" if ok else
                      _why(tree, mine, ref, own(*_perturbed(tree, q, v, step=OWN_STEP)),
                           jac=jac, turn=turn))]


def _why(tree: ModelTree, mine: np.ndarray, ref: np.ndarray, vdot: np.ndarray, *,
         jac: np.ndarray, turn: np.ndarray) -> str:
    """Why an engine's derivatives are not the referee's: where central differences of its
    own forward dynamics are the referee's, its derivative routine is not the derivative of
    its own dynamics (measured, with both sizes); else the cause is unknown."""
    s, nv = jac.shape[0], tree.nv
    theirs = differences(vdot, s, nv, step=OWN_STEP)
    if on_manifold(tree):
        theirs = along(theirs, jac, turn)
    k = mine.shape[3] // 2
    apart, bound = _gaps(theirs, ref, k)
    if apart > bound:
        return "cause unknown: its derivatives with its constraints are not the referee's " \
               "on its reading"
    off, _ = _gaps(mine, theirs, k)
    return (f"its derivative routine is not the derivative of its own constrained dynamics: "
            f"against central differences of them it is off by {off:.3g} (relative), while "
            f"those differences are the referee's to {apart:.3g} (bound {bound:.3g}): the "
            "engine's, measured")


def _map_rates(canon: Canonical, engine_tree: ModelTree, tree: ModelTree, *, q: np.ndarray,
               v: np.ndarray) -> tuple[np.ndarray, ...]:
    """T (S, nv_e, nv) of v_e = T v at the states, and by central differences of the layout
    map (dyncheck's own smooth arithmetic, step :data:`MAP_STEP`) ∂T/∂δ (S, nv_e, nv, nv)
    along each direction δ of the canonical chart, ∂(Ṫ v)/∂δ and ∂(Ṫ v)/∂v (S, nv_e, nv)."""
    s, nv = v.shape
    solver = TreeDynamics(bodies(tree), tree.gravity)

    def at(qq: np.ndarray, vv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        maps = layout.engine_states(canon, engine_tree, qq, vv, np.zeros_like(vv))[0]
        return np.array([m.t for m in maps]), np.array([m.tdot_v for m in maps])

    t, _ = at(q, v)
    d_t = np.zeros((*t.shape, nv))
    d_rate_q, d_rate_v = np.zeros((s, t.shape[1], nv)), np.zeros((s, t.shape[1], nv))
    for k in range(nv):
        step = np.zeros((s, nv))
        step[:, k] = MAP_STEP
        (ahead, rate_a), (behind, rate_b) = (at(retract(solver, q, sign * step), v)
                                             for sign in (1.0, -1.0))
        d_t[..., k] = (ahead - behind) / (2 * MAP_STEP)
        d_rate_q[..., k] = (rate_a - rate_b) / (2 * MAP_STEP)
        d_rate_v[..., k] = (at(q, v + step)[1] - at(q, v - step)[1]) / (2 * MAP_STEP)
    return t, d_t, d_rate_q, d_rate_v


def _mapped(canon: Canonical, engine_tree: ModelTree, tree: ModelTree, *, q: np.ndarray,
            v: np.ndarray, found: np.ndarray, vdot: np.ndarray) -> np.ndarray:
    """The engine's derivatives (its layout, its chart) in the canonical ones. With
    v_e = T v, v̇ = T⁻¹ (v̇_e − Ṫ v), and its chart moving q along its own velocities
    (δ_e = T δ: Pinocchio's ``integrate``, MuJoCo's ``mj_integratePos``):
    ∂v̇/∂δ = T⁻¹ (D_q T + D_v (∂T/∂δ) v − ∂(Ṫ v)/∂δ − (∂T/∂δ) v̇) and
    ∂v̇/∂v = T⁻¹ (D_v T − ∂(Ṫ v)/∂v); on hinges and slides T is constant and Ṫ v = 0."""
    s, _, nv_e, _ = found.shape
    nv = v.shape[1]
    t, d_t, d_rate_q, d_rate_v = _map_rates(canon, engine_tree, tree, q=q, v=v)
    pinv = np.linalg.pinv(t)
    turned_v = np.einsum("senk,sn->sek", d_t, v)
    turned_vdot = np.einsum("senk,sn->sek", d_t, vdot)
    out = np.zeros((s, 2, nv, 2 * nv))
    for k in range(2):
        d_q, d_v = found[:, k, :, :nv_e], found[:, k, :, nv_e:]
        out[:, k, :, :nv] = pinv @ (d_q @ t + d_v @ turned_v - d_rate_q - turned_vdot)
        out[:, k, :, nv:] = pinv @ (d_v @ t - d_rate_v)
    return out
