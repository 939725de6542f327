"""The referee of a model check's derivatives (step 6, ``--derivatives``; its rows:
:mod:`dyncheck.check.derivatives`, the step's: :mod:`dyncheck.check.steps`): the recursive
Newton–Euler algorithm (:mod:`dyncheck.reference.recursive`, §2.2's momentum laws
(2.2.48)–(2.2.49) body by body), tied to the book's general method
(:mod:`dyncheck.reference.tree`) on this very tree (:mod:`dyncheck.referee.tree`: where the
two disagree, the referee's derivatives are not compared and the tie's failed row says why),
differentiated by a complex step along q ⊕ iη eₖ and v + iη eₖ — exact to round-off, with no
truncation error to estimate; the forward derivatives through ∂v̇/∂x = −M⁻¹ ∂τ/∂x at
v̇ = FD(q, v, 0), which follows from differentiating τ = ID(q, v, FD(q, v, τ)).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from dyncheck.adapters.model_tree import Derivatives, ModelTree
from dyncheck.adapters.model_tree import derivatives as collect
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, standing
from dyncheck.referee.charts import perturb
from dyncheck.referee.computed import depth
from dyncheck.referee.states import States
from dyncheck.referee.tree import TIE_STATES, ReferenceModel, Tie, tie

if TYPE_CHECKING:
    from dyncheck.adapters.model_tree import Canonical
    from dyncheck.reference.recursive import RecursiveDynamics

STEP = 4e-3
"""The largest central-difference step of the implicit step's Richardson extrapolation
(:func:`dyncheck.check.steps.implicit_blocks`; then /2, /4)."""
ETA = 1e-30
"""The complex step through the recursive referee (no cancellation: the result is
η-independent for any η ≪ √ε × scale)."""
STEP_WORK = 2e6
"""The step Jacobians' budget in nv² × depth per state: an engine's finite differences of its
step take 2 nv steps, each O(nv × depth) (its mass matrix's factorization), so a state costs
O(nv² depth): they are compared at the first ⌊STEP_WORK / (nv² depth)⌋ states (at least one;
every state of a 35-dof humanoid, one of a 200-hinge chain — where MuJoCo's three integrators
take ~3 s a state), and the row says how many."""
CURVE = 1e-3
"""The step along the chart between complex-stepped first derivatives, for the second and
third derivatives a finite difference's truncation needs (bounds only: their own error,
O(CURVE²) relative, changes no verdict)."""


def step_states(tree: ModelTree, n: int) -> int:
    """How many of ``n`` states the step Jacobians are compared at (:data:`STEP_WORK`)."""
    return max(1, min(n, int(STEP_WORK // (max(tree.nv, 1) ** 2 * max(depth(tree), 1)))))


def first(found: object, k: int) -> Any:
    """A record of per-state arrays (:class:`Referee`, ``Derivatives``, ``States``) cut to
    its first ``k`` states (an array field whose first axis is not the states' is kept)."""
    n = len(found.forward) if isinstance(found, Referee) else None
    out: dict[str, Any] = {}
    for name, value in vars(found).items():
        if isinstance(value, np.ndarray) and value.ndim and (n is None or len(value) == n):
            out[name] = value[:k]
        elif isinstance(value, dict):
            out[name] = {key: x[:k] for key, x in value.items()}
        elif isinstance(value, Derivatives):
            out[name] = first(value, k)
        else:
            out[name] = value
    return type(found)(**out)


@dataclass(frozen=True, kw_only=True)
class Referee:
    """The referee's derivatives and what bounds the comparisons: its own estimated error
    per entry, and the second derivatives of τ a finite difference's truncation needs."""

    derivatives: Derivatives
    error: dict[str, np.ndarray]
    second_q: dict[str, np.ndarray]  # ∂²τᵢ/∂q_k² at v̇ = a ("inverse") and v̇ = FD ("forward")
    third_q: dict[str, np.ndarray]  # ∂³τᵢ/∂q_k³, likewise: the next term of a one-sided step
    second_v: np.ndarray  # ∂²τᵢ/∂v_k²
    inverse_mass: np.ndarray
    roundoff: np.ndarray  # δτ per state: the round-off of τ
    roundoff_v: np.ndarray  # δτ per unit of v: over the velocities' spread max(1, |v|)
    forward: np.ndarray  # v̇ at τ = 0
    tie: Tie  # the recursive algorithm against the general method on this tree
    standing: float = 1.0  # max(1, X/ℓ): how far from the origin the model stands


def referee(tree: ModelTree, states: States, *, bounds: bool = True,
            tied: Tie | None = None) -> Referee:
    """The referee's derivatives at ``states`` (canonical layout and chart): the recursive
    Newton–Euler referee (:mod:`dyncheck.reference.recursive`, tied to the book's general
    method by :class:`~dyncheck.referee.tree.ReferenceModel`) differentiated by a complex
    step — τ(q ⊕ iη e_k, v, v̇) and τ(q, v + iη e_k, v̇), the imaginary part over η: no
    cancellation, so no truncation error and no extrapolation; the error is the recursion's
    round-off. The second and third derivatives along the chart, which bound an engine's
    finite differences, are central differences of these exact first derivatives at
    ±:data:`CURVE`; ∂²τ/∂v_k² = 2 h₀(q, e_k), h₀ the bias without gravity (h is quadratic in
    v). Where ``bounds`` is false (an RK4 stage's referee) only what a step's chain rule
    needs is computed: the forward derivatives (the inverse ones at v̇ = a, the bounds and
    their error estimates are zero), and the tie is ``tied``, the step's own referee's."""
    from dyncheck.adapters.model_tree import canonical

    canon = canonical(tree)
    model = ReferenceModel(tree)
    solver = model.recursive
    q, v, a = states.q, states.v, states.a
    with np.errstate(all="ignore"):
        # M and h from the general method (the root of trust): its M sums mᵢ Jᵢᵀ Jᵢ with no
        # parallel-axis cancellation, which costs composite bodies the digits of a tiny
        # inertia far from its pivot (the spherical pendulum's 1e-8 kg m² rod: M⁻¹ to 1e-8)
        # (an RK4 stage's referee, ``bounds`` false, takes them from the recursion: a stage's
        # M⁻¹ enters the step's Jacobian times h, far below its finite differences' error)
        mass, bias, _, _ = (model.solver if bounds else solver).at_states(q, v)
    if tied is None:  # the tie at the first states, with the general method's M, h there
        first = slice(0, TIE_STATES)
        tied = tie(model.solver, solver, depth(tree), q[first], v[first], a[first],
                   found=(mass[first], bias[first]))
    with np.errstate(all="ignore"):
        inverse_mass = np.linalg.inv(mass)
        forward = -np.einsum("sij,sj->si", inverse_mass, bias)
        d_q, d_v, second_v = _complex_steps(canon, solver, states, forward, bounds=bounds)
    depth_ = depth(tree)
    rtol = ROUNDOFF_FACTOR * EPS * depth_
    tau_scale = np.maximum(np.abs(bias).max(axis=1), np.abs(
        np.einsum("sij,sj->si", mass, a)).max(axis=1))
    roundoff = rtol * np.maximum(tau_scale, 1e-300)
    spread = max(1.0, float(np.abs(v).max()))
    out, error, second_q, third_q = _assembled(d_q, d_v, inverse_mass, rtol=rtol, bounds=bounds)
    return Referee(
        derivatives=collect(out, method="recursive Newton-Euler differentiated by a complex "
                            "step (exact to round-off; tied to the general method)"),
        error=error, second_q=second_q, third_q=third_q, second_v=second_v,
        inverse_mass=inverse_mass, roundoff=roundoff, roundoff_v=roundoff / spread,
        forward=forward, tie=tied, standing=standing(*solver.reach(q)))


def _complex_steps(canon: Canonical, solver: RecursiveDynamics, states: States,
                   forward: np.ndarray, *, bounds: bool
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The recursion's τ complex-stepped along every coordinate of q (at the offsets 0, ±
    :data:`CURVE` along it where ``bounds``) at v̇ = a and at the forward acceleration, and
    along every coordinate of v; and ∂²τ/∂v_k² = 2 h₀(q, e_k). Shapes: (acc, offset, k, s,
    i), (s, i, k), (s, i, k)."""
    q, v, a = states.q, states.v, states.a
    n, nv = v.shape
    offsets = (0.0, CURVE, -CURVE) if bounds else (0.0,)
    # every complex-stepped state at once: (offset, k) states, two accelerations
    q_c = np.stack([perturb(canon, q, k, t + 1j * ETA) for t in offsets for k in range(nv)])
    columns = np.tile(np.arange(nv), len(offsets))
    acc = np.stack([a, forward] if bounds else [forward])
    rows_q = solver.inverse_along(q, v, acc, columns, q_along=q_c)  # (offset·k, acc, s, i)
    d_q = np.moveaxis((rows_q.imag / ETA).reshape(len(offsets), nv, len(acc), n, nv), 2, 0)
    if not bounds:  # the forward acceleration's only: the inverse ones left zero
        d_q = np.concatenate([np.zeros_like(d_q), d_q])
    v_c = v[None] + 1j * ETA * np.eye(nv)[:, None, :]  # (k, s, i)
    d_v = solver.inverse_along(q, v, np.zeros_like(v), np.arange(nv), v_along=v_c)
    d_v = np.transpose(d_v.imag / ETA, (1, 2, 0))
    second_v = np.zeros((n, nv, nv))
    if bounds:
        unit = np.broadcast_to(np.eye(nv)[:, None, :], (nv, n, nv))
        second_v = np.transpose(2 * solver.inverse_along(
            q, np.zeros_like(v), np.zeros_like(v), np.arange(nv), v_along=unit,
            gravity=False), (1, 2, 0))
    return d_q, d_v, second_v


def _assembled(d_q: np.ndarray, d_v: np.ndarray, inverse_mass: np.ndarray, *, rtol: float,
               bounds: bool) -> tuple[dict[str, np.ndarray], ...]:
    """The derivatives (the forward ones by −M⁻¹ ∂τ), their round-off, and the second and
    third derivatives along the chart (central differences of the exact first ones)."""
    out: dict[str, np.ndarray] = {}
    error: dict[str, np.ndarray] = {}
    second_q: dict[str, np.ndarray] = {}
    third_q: dict[str, np.ndarray] = {}

    def own_roundoff(jacobian: np.ndarray) -> np.ndarray:
        """The recursion's round-off in a complex-stepped Jacobian: c ε × depth of its
        largest entry, per state."""
        return np.broadcast_to(rtol * np.abs(jacobian).max(axis=(1, 2))[:, None, None],
                               jacobian.shape).copy()

    for index, key in enumerate(("inverse", "forward")):
        at = np.transpose(d_q[index], (0, 2, 3, 1))  # (offset, s, i, k)
        if bounds:
            second_q[key] = (at[1] - at[2]) / (2 * CURVE)
            third_q[key] = (at[1] - 2 * at[0] + at[2]) / CURVE**2
        else:
            second_q[key] = third_q[key] = np.zeros_like(at[0])
        if key == "inverse":
            out["inverse_q"] = at[0]
            error["inverse_q"] = own_roundoff(at[0])
        else:
            out["forward_q"] = -inverse_mass @ at[0]
            error["forward_q"] = np.abs(inverse_mass) @ own_roundoff(at[0])
    out["inverse_v"], error["inverse_v"] = d_v, own_roundoff(d_v)
    out["forward_v"] = -inverse_mass @ d_v
    error["forward_v"] = np.abs(inverse_mass) @ error["inverse_v"]
    out["forward_tau"] = inverse_mass
    error["forward_tau"] = np.zeros_like(inverse_mass)
    return out, error, second_q, third_q
