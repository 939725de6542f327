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
engine whose velocities on a rotating joint are not the canonical ones (a permutation of
them) differentiates in another chart, which is not mapped here yet: one skipped row says
so. The tolerance is measured, not chosen: each side's
finite-difference error is bounded by twice the gap g between its differences at its step δ
and at 2δ — where truncation (∝ δ²) dominates, the error of the finer is g/3; where round-off
(∝ 1/δ) does, at most 2g (errors of one sign: c/δ − c/2δ = g) — plus 64 ε; the error is
relative to the largest derivative of each block (∂/∂q, ∂/∂v), at least 1 (s⁻², s⁻¹).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from dyncheck.adapters import layout_batch
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.layout import Canonical
from dyncheck.adapters.model_tree import ModelTree
from dyncheck.check import closures
from dyncheck.check.computed import bodies
from dyncheck.check.rows import CheckRow, Section
from dyncheck.errors import EngineError, Unsupported
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.reference.closure import retract
from dyncheck.reference.tree import TreeDynamics
from dyncheck.roster import REFEREE
from dyncheck.vocabulary import Verdict

STATES = 8
"""States whose derivatives are compared (each costs the referee 8 nv solves)."""
STEP = 1e-7
"""The referee's central-difference step: small against the lengths over which a soft
model's impedance changes (solimp's width, 1e-3 m by default; truncation ~ (δ/width)²),
large against round-off (ε |v̇| / δ). Measured on the four-bar's q block: the gap between its
differences at δ and 2δ is 5.9e-5 at 1e-7, against 1.5e-4 at 1e-8 and 0.60 at 1e-5."""
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


def _perturbed(tree: ModelTree, q: np.ndarray,
               v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every state moved by ±δ and ±2δ (:data:`STEP`) along each q direction of MuJoCo's
    chart (the referee's ``retract``) and each v coordinate: (S · 2 steps · 2 signs · 2 nv)
    states."""
    s, nv = v.shape
    cols = np.eye(2 * nv)
    shift = np.array([[sign * step * cols for sign in (1.0, -1.0)]
                      for step in (STEP, 2 * STEP)])  # (2 steps, 2 signs, 2nv, 2nv)
    count = shift.shape[0] * shift.shape[1] * shift.shape[2]
    dq = np.broadcast_to(shift[None, ..., :nv], (s, *shift.shape[:3], nv)).reshape(-1, nv)
    solver = TreeDynamics(bodies(tree), tree.gravity)
    return (retract(solver, np.repeat(q, count, axis=0), dq),
            (v[:, None, None, None, :] + shift[None, ..., nv:]).reshape(-1, nv))


def differences(vdot: np.ndarray, s: int, nv: int) -> np.ndarray:
    """Central differences (S, 2, nv, 2 nv) of v̇ at the :func:`_perturbed` states."""
    found = vdot.reshape(s, 2, 2, 2 * nv, nv)
    steps = np.array([STEP, 2 * STEP])[None, :, None, None]
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
    maps, q_e, v_e, _ = layout_batch.engine_states(canon, engine.tree, q, v, np.zeros_like(v))
    t = np.array([m.t for m in maps])
    other = _other_chart(tree, t)
    if other:
        return [_row(model, name, verdict=Verdict.SKIPPED, note=(
            f"{name}'s derivatives with its constraints are not compared on this model: its "
            f"velocities of {other!r} are not MuJoCo's, so it differentiates in another "
            "chart (mapped between charts on hinges and slides only, as yet)"))]
    try:
        found = engine.closed_derivatives(q_e, v_e, np.zeros_like(v_e))
    except Unsupported as exc:
        return [_row(model, name, verdict=Verdict.SKIPPED, note=str(exc))]
    except EngineError as exc:
        return [_row(model, name, verdict=Verdict.FAILED, note=f"{name} failed: {exc}")]
    mine = _mapped(t, found)
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
                      _why(tree, mine, ref, own(*_perturbed(tree, q, v)), jac=jac,
                           turn=turn))]


def _other_chart(tree: ModelTree, t: np.ndarray) -> str:
    """The first rotating joint (ball, free) whose engine velocities are not the canonical
    ones, permuted (T's columns there not each a single 1, at every state); empty: none."""
    for j in tree.joints:
        if j.layout.nv == 1 and j.layout.nq == 1:
            continue
        cols = t[:, :, j.layout.v_start : j.layout.v_start + j.layout.nv]
        ones = np.round(cols)
        if np.abs(cols - ones).max(initial=0.0) > 1e-12 or (ones < 0).any() or \
                (np.abs(ones).sum(axis=1) != 1).any():
            return j.name
    return ""


def _why(tree: ModelTree, mine: np.ndarray, ref: np.ndarray, vdot: np.ndarray, *,
         jac: np.ndarray, turn: np.ndarray) -> str:
    """Why an engine's derivatives are not the referee's: where central differences of its
    own forward dynamics are the referee's, its derivative routine is not the derivative of
    its own dynamics (measured, with both sizes); else the cause is unknown."""
    s, nv = jac.shape[0], tree.nv
    theirs = differences(vdot, s, nv)
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


def _mapped(t: np.ndarray, found: np.ndarray) -> np.ndarray:
    """The engine's derivatives in the canonical layout: T⁻¹ D blockdiag(T, T) (T constant
    on hinges and slides, a permutation on the rotating joints compared)."""
    s, _, nv_e, _ = found.shape
    nv = t.shape[2]
    out = np.zeros((s, 2, nv, 2 * nv))
    pinv = np.linalg.pinv(t)
    for k in range(2):
        d = found[:, k]
        out[:, k, :, :nv] = pinv @ d[:, :, :nv_e] @ t
        out[:, k, :, nv:] = pinv @ d[:, :, nv_e:] @ t
    return out
