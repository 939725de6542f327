"""A model's closures checked (#78): the constraints that close its tree, as the canonical
engine reads them, put to the referee — the tree's Lagrange equations with constraints,
(2.2.23)–(2.2.26), two ways (:mod:`dyncheck.reference.constrained`) — at states moved onto
the constraints (:func:`~dyncheck.reference.closure.project`), and an engine's own answer
on them measured against it:

- its rows: C and J of each constraint against the referee's (a connect's, a coupling's and
  a weld's position rows are the same functions; a weld's rotation rows are ½ · scale ·
  (ω₁ − ω₂) in body 1's axes in MuJoCo, so their row space is compared);
- its accelerations against the referee's soft model (MuJoCo's documented equations, its
  :func:`~dyncheck.reference.constrained.soft`, with the file's solref and solimp and the
  engine's approximation of A's diagonal), and against the rigid answer: their distance is
  what the soft model predicts (R's share of the free motion, and J̇ v on the rows whose
  reference acceleration leaves it out: a joint or tendon coupling in MuJoCo 4, every row
  before it).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.closures import ClosedReading, ClosureKind
from dyncheck.adapters.closures import Closure as Held
from dyncheck.adapters.model_tree import ModelTree
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.referee.computed import bodies
from dyncheck.reference.closure import (
    Closure,
    Connect,
    Coupling,
    Rows,
    Weld,
    project,
    rows,
)
from dyncheck.reference.constrained import RANK_RTOL, multipliers, reduced, soft
from dyncheck.reference.constraints import Softness
from dyncheck.reference.tree import TreeDynamics

ACCELERATION_FLOOR = 1.0
"""The smallest scale of accelerations (m/s²): where the free and constrained motions are
slower (a mechanism moving across gravity, at rest), errors are held absolutely at it."""
PROJECTION_TOL = 1e-12
"""|C| accepted of a state moved onto the constraints, relative to the model's reach. Newton's
method goes on while |C| still halves, so a regular mechanism's states end at round-off
(~1e-16 here) and a singular one's, converging linearly, nearer 1e-14; a draw above this
after its iterations is dropped."""


def referee_closures(tree: ModelTree) -> list[Closure]:
    """The tree's closures as the referee takes them (joints by their place in
    ``tree.joints``, the order :func:`~dyncheck.referee.computed.bodies` gives the general
    method)."""
    index = {j.name: i for i, j in enumerate(tree.joints)}

    def at(name: str | None) -> int:
        return -1 if name is None else index[name]

    out: list[Closure] = []
    for c in tree.closures:
        if c.kind is ClosureKind.CONNECT or _turns_freely(c):
            out.append(Connect(body1=at(c.joint1), body2=at(c.joint2), point1=c.point1,
                               point2=c.point2))
        elif c.kind is ClosureKind.WELD:
            out.append(Weld(body1=at(c.joint1), body2=at(c.joint2), point1=c.point1,
                            point2=c.point2, held=c.held))
        else:
            out.append(Coupling(first=tuple((index[n], k) for n, k in c.first),
                                second=tuple((index[n], k) for n, k in c.second),
                                reference1=c.reference1, reference2=c.reference2,
                                polycoef=c.polycoef))
    return out


def _turns_freely(c: Held) -> bool:
    """A weld that holds no rotation (torquescale 0): the referee's connect."""
    return c.kind is ClosureKind.WELD and c.rotation_scale == 0.0


def row_sizes(tree: ModelTree) -> list[int]:
    """Each closure's rows in the referee (a weld whose rotation is free: a connect's 3)."""
    return [3 if _turns_freely(c) else c.rows for c in tree.closures]


def _per_row(tree: ModelTree) -> list[tuple[Held, Softness, bool]]:
    """Each of the referee's rows: its closure, that closure's soft model, and whether it is
    a weld's rotation row."""
    out: list[tuple[Held, Softness, bool]] = []
    for c, size in zip(tree.closures, row_sizes(tree), strict=True):
        out += [(c, softness(c), size == 6 and k >= 3) for k in range(size)]
    return out


def engine_rows(tree: ModelTree) -> np.ndarray:
    """Where the referee's rows sit among the engine's (a weld whose rotation is free keeps
    its three zero rotation rows in MuJoCo: left out)."""
    out: list[int] = []
    start = 0
    for c, size in zip(tree.closures, row_sizes(tree), strict=True):
        out += range(start, start + size)
        start += c.rows
    return np.array(out, int)


def rotation_rows(tree: ModelTree) -> np.ndarray:
    """Which of the referee's rows are a weld's rotation rows (bool, one per row)."""
    out: list[bool] = []
    for size in row_sizes(tree):
        out += [False] * 3 + [True] * 3 if size == 6 else [False] * size
    return np.array(out, bool)


def softness(c: Held) -> Softness:
    """A closure's soft model (MuJoCo's solref, solimp)."""
    return Softness(*c.solref[:2], *c.solimp[:5])


@dataclass(frozen=True, kw_only=True)
class ClosedStates:
    """States on the constraints: the draws kept (q, v), how many were drawn, and the
    largest |C| and |J v| of the kept."""

    q: np.ndarray
    v: np.ndarray
    drawn: int
    residual: float
    rate: float
    unmet: tuple[str, float] | None = None
    """Of the dropped draws: the closure none of them came close to meeting, and the
    smallest |C| they left it at (None: none dropped)."""


def on_constraints(tree: ModelTree, q: np.ndarray, v: np.ndarray, *,
                   reach: float) -> ClosedStates:
    """The draws (q, v) moved onto the tree's closures; a draw whose Newton iteration does
    not converge is dropped and counted."""
    solver = TreeDynamics(bodies(tree), tree.gravity)
    held = referee_closures(tree)
    moved = project(solver, held, q, v, tol=PROJECTION_TOL * max(reach, 1.0))
    kept = moved.converged
    unmet = None
    if not kept.all():  # the constraint the dropped draws came least close to meeting
        left = np.abs(rows(solver, held, moved.q[~kept], moved.v[~kept]).value)
        ends = np.cumsum([0, *row_sizes(tree)])
        far = [float(left[:, a:b].max(axis=1, initial=0.0).min())
               for a, b in itertools.pairwise(ends)]
        worst = int(np.argmax(far))
        unmet = (tree.closures[worst].name, far[worst])
    return ClosedStates(q=moved.q[kept], v=moved.v[kept], drawn=len(q),
                        residual=float(moved.residual[kept].max(initial=0.0)),
                        rate=float(moved.rate[kept].max(initial=0.0)), unmet=unmet)


@dataclass(frozen=True, kw_only=True)
class RefereeAnswer:
    """The referee at S states: its rows, M and h there, and v̇ (S, nv) rigid (both ways)
    and soft."""

    rows: Rows
    mass: np.ndarray
    bias: np.ndarray
    reduced: np.ndarray
    multipliers: np.ndarray
    soft: np.ndarray


def regularizer(tree: ModelTree, *, diagonal: np.ndarray, value: np.ndarray) -> np.ndarray:
    """R's diagonal on the referee's rows at one state: (1 − d)/d times the engine's
    approximation of A's diagonal (``diagonal``, on its rows), a weld's rotation rows by
    4/scale² (the engine's rows are ½ · scale times a rotation of the referee's: the same
    soft solve needs R scaled by the inverse square)."""
    rows_of = _per_row(tree)
    scale = np.array([4.0 / c.rotation_scale**2 if turning else 1.0
                      for c, _, turning in rows_of])
    d = np.array([s.impedance(np.array([r]))[0]
                  for (_, s, _), r in zip(rows_of, value, strict=True)])
    return (1 - d) / d * diagonal * scale


def reference_row(tree: ModelTree, *, value: np.ndarray, rate: np.ndarray,
                  jdot_v: np.ndarray) -> np.ndarray:
    """a_ref = −b ṙ − k d(r) r of every row (MuJoCo's documented reference acceleration),
    less J̇ v on the rows of a closure whose engine takes it in
    (:attr:`~dyncheck.adapters.closures.Closure.bias_in_reference`)."""
    out: list[float] = []
    for k, (c, s, _) in enumerate(_per_row(tree)):
        d = float(s.impedance(np.array([value[k]]))[0])
        out.append(-s.damping * rate[k] - s.stiffness * d * value[k]
                   - (jdot_v[k] if c.bias_in_reference else 0.0))
    return np.array(out)


def referee(tree: ModelTree, q: np.ndarray, v: np.ndarray, *, tau: np.ndarray,
            diagonal: np.ndarray) -> RefereeAnswer:
    """The referee on ``tree``'s closures at the states (canonical layout), the soft model
    with the engine's ``diagonal`` (S, m); where the engine holds its closures rigidly, the
    soft model is the rigid answer."""
    solver = TreeDynamics(bodies(tree), tree.gravity)
    held = rows(solver, referee_closures(tree), q, v)
    mass, bias, _, _ = solver.at_states(q, v)
    soft_held = any(c.soft for c in tree.closures)
    out: dict[str, list[np.ndarray]] = {"reduced": [], "multipliers": [], "soft": []}
    for s in range(len(q)):
        jac, jdot_v = held.jacobian[s], held.bias[s]
        args = (mass[s], bias[s], tau[s])
        out["reduced"].append(reduced(*args, J=jac, jdot_v=jdot_v).vdot)
        out["multipliers"].append(multipliers(*args, J=jac, jdot_v=jdot_v).vdot)
        if not soft_held:
            out["soft"].append(out["multipliers"][-1])
            continue
        a_ref = reference_row(tree, value=held.value[s], rate=jac @ v[s], jdot_v=jdot_v)
        out["soft"].append(soft(*args, J=jac, a_ref=a_ref, regularizer=regularizer(
            tree, diagonal=diagonal[s], value=held.value[s])).vdot)
    nv = v.shape[1]
    return RefereeAnswer(rows=held, mass=mass, bias=bias,
                         **{k: np.array(x).reshape(-1, nv) for k, x in out.items()})


def row_space_gap(engine: np.ndarray, referee_rows: np.ndarray) -> float:
    """How far two sets of rows span different spaces: the largest |(I − P) x| over the
    engine's unit rows x, P the projector on the referee's row space (0: the same space)."""
    if not engine.size:
        return 0.0
    basis = np.linalg.svd(referee_rows, full_matrices=False)[2]
    unit = engine / np.maximum(np.linalg.norm(engine, axis=1, keepdims=True), 1e-300)
    return float(np.abs(unit - (unit @ basis.T) @ basis).max())


@dataclass(frozen=True, kw_only=True)
class Measured:
    """An engine's answer on its closures against the referee's, at states on them; every
    gap the largest over the states, with the round-off bound it is held to."""

    residual: float
    """max |C − C_ref| of the engine's rows at the referee's states (lengths; 0: the same
    constraint; a weld's rotation rows compared only where both vanish, as every state here
    is on the constraints)."""
    jacobian: float
    """max |J − J_ref| of the rows both state alike, relative to max |J_ref|."""
    row_space: float
    """A weld's rotation rows: how far the engine's leave the referee's row space."""
    ways: float
    """The referee's two ways (independent coordinates, multipliers), apart."""
    soft: float
    """The engine's v̇ against the referee's soft model of it."""
    rigid: float
    """The engine's v̇ against the rigid answer."""
    predicted: float
    """The soft model's distance from the rigid answer: what the engine's should be."""
    scale: float
    """The accelerations' scale: the largest |v̇| of the free tree and of the answers, at
    least :data:`ACCELERATION_FLOOR`."""
    bound: float
    """The round-off bound of the accelerations, relative to ``scale``: 64 ε κ(M) κ(A + R),
    plus an iterative solver's accuracy (its residual in the rows) times that κ, plus what
    the soft model makes of the states' leftover |C| and |J v| (:func:`_reference_spread`)."""
    rows_bound: float
    """The round-off bound of the rows: 64 ε relative to the model's reach and |J|."""


def measure(tree: ModelTree, reading: ClosedReading, states: ClosedStates, *,
            tau: np.ndarray, reach: float) -> Measured:
    """The engine's ``reading`` at ``states`` (on ``tree``'s closures) against the referee;
    ε in its bounds the coarser of float64's and the engine's own (``tree.eps``)."""
    pick, rot = engine_rows(tree), rotation_rows(tree)
    q, v = states.q, states.v
    eps = max(EPS, tree.eps)  # (the engine's arithmetic: Newton's float32)
    ref = referee(tree, q, v, tau=tau, diagonal=reading.diagonal[:, pick])
    jac = reading.jacobian[:, pick]
    mass, bias = ref.mass, ref.bias  # (evaluated once, by the referee)
    free = np.linalg.solve(mass, (tau - bias)[..., None])[..., 0]
    kappa, gain = _conditioning(tree, mass, ref.rows, diagonal=reading.diagonal[:, pick])
    scale = max(float(np.abs(free).max(initial=0.0)), float(np.abs(ref.soft).max(initial=0.0)),
                float(np.abs(ref.multipliers).max(initial=0.0)), ACCELERATION_FLOOR)
    leftover = gain * _reference_spread(tree, states, reach=reach,
                                        rows=float(np.abs(ref.rows.jacobian).max(initial=0.0)))
    norm = max(float(np.abs(ref.rows.jacobian).max(initial=0.0)), 1e-300)
    return Measured(
        residual=float(np.abs(reading.value[:, pick] - ref.rows.value).max(initial=0.0)),
        jacobian=float(np.abs(jac[:, ~rot] - ref.rows.jacobian[:, ~rot]).max(initial=0.0))
        / norm,
        row_space=max((row_space_gap(jac[s][rot], ref.rows.jacobian[s][rot])
                       for s in range(len(q))), default=0.0) if rot.any() else 0.0,
        ways=float(np.abs(ref.reduced - ref.multipliers).max(initial=0.0)) / scale,
        soft=float(np.abs(reading.vdot - ref.soft).max(initial=0.0)) / scale,
        rigid=float(np.abs(reading.vdot - ref.multipliers).max(initial=0.0)) / scale,
        predicted=float(np.abs(ref.soft - ref.multipliers).max(initial=0.0)) / scale,
        scale=scale, bound=ROUNDOFF_FACTOR * eps * kappa
        + (reading.accuracy * kappa + leftover) / scale,
        rows_bound=ROUNDOFF_FACTOR * eps * max(reach, 1.0))


def _conditioning(tree: ModelTree, mass: np.ndarray, held: Rows, *,
                  diagonal: np.ndarray) -> tuple[float, float]:
    """κ(M) κ(A + R), the largest over the states, and the largest ‖M⁻¹ Jᵀ (A + R)⁻¹‖₂: how
    much a change of the rows' reference acceleration moves v̇ (0 for a rigid reading)."""
    soft_held = any(c.soft for c in tree.closures)
    kappa, gain = 1.0, 0.0
    for s in range(len(mass)):
        jac = held.jacobian[s]
        reg = regularizer(tree, diagonal=diagonal[s], value=held.value[s]) if soft_held else \
            np.zeros(len(jac))
        kappa = max(kappa, float(np.linalg.cond(mass[s])) * _soft_condition(mass[s], jac, reg))
        if soft_held and jac.size:
            minv_jt = np.linalg.solve(mass[s], jac.T)
            gain = max(gain, float(np.linalg.norm(
                minv_jt @ np.linalg.inv(jac @ minv_jt + np.diag(reg)), 2)))
    return kappa, gain


def _reference_spread(tree: ModelTree, states: ClosedStates, *, reach: float,
                      rows: float) -> float:
    """How far two implementations' reference accelerations a_ref = −b ṙ − k d r may lie
    apart at the states: each rounds the leftover r (≤ |C| + 64 ε reach) and ṙ (≤ |J v| +
    64 ε |J| |v|) its own way, ε the engine's (0 where no closure is soft)."""
    soft = [softness(c) for c in tree.closures if c.soft]
    if not soft:
        return 0.0
    speed = float(np.abs(states.v).max(initial=0.0))
    eps = max(EPS, tree.eps)  # (a float32 engine rounds the state itself)
    rate = states.rate + ROUNDOFF_FACTOR * eps * rows * speed
    residual = states.residual + ROUNDOFF_FACTOR * eps * max(reach, 1.0)
    return max(s.damping for s in soft) * rate + max(s.stiffness for s in soft) * residual


def _soft_condition(mass: np.ndarray, jac: np.ndarray, reg: np.ndarray) -> float:
    """κ(A + R), A = J M⁻¹ Jᵀ, on its range (a redundant row of a rigid constraint adds a
    zero singular value that no solve meets; 1 without rows)."""
    if not jac.size:
        return 1.0
    values = np.linalg.svd(jac @ np.linalg.solve(mass, jac.T) + np.diag(reg), compute_uv=False)
    kept = values[values > RANK_RTOL * values[0]] if values[0] > 0 else values[:1]
    return float(kept[0] / kept[-1]) if kept.size and kept[-1] > 0 else 1.0
