"""Step 6 of a model check (``--derivatives``): the derivatives of the smooth dynamics —
∂v̇/∂q, ∂v̇/∂v, ∂v̇/∂τ = M⁻¹ of the forward dynamics at τ = 0 and ∂τ/∂q, ∂τ/∂v of the inverse
dynamics at the sampled v̇ — of every engine that offers them and of the referee, in the
canonical chart, compared pair by pair.

The chart, and an engine's own derivatives mapped into it: :mod:`dyncheck.check.derivative_charts`.

The referee: the recursive Newton–Euler algorithm (:mod:`dyncheck.reference.recursive`,
§2.2's momentum laws (2.2.48)–(2.2.49) body by body), tied to the book's general method
(:mod:`dyncheck.reference.tree`) on this very tree (:mod:`dyncheck.check.referee`: where the
two disagree, the referee's derivatives are not compared and the tie's failed row says why),
differentiated by a complex step along q ⊕ iη eₖ and v + iη eₖ — exact to round-off, with no
truncation error to estimate; the forward derivatives through ∂v̇/∂x = −M⁻¹ ∂τ/∂x at
v̇ = FD(q, v, 0), which follows from differentiating τ = ID(q, v, FD(q, v, τ)).

The step's Jacobian against the chain rule of these derivatives: :mod:`dyncheck.check.steps`.

Tolerances: round-off, 64 ε × tree depth of each matrix's scale (× κ(M) for the forward
ones), plus per entry the referee's own round-off where it is one side, plus an engine's
predicted finite-difference error where it differences (MuJoCo's one-sided differences of
step s: s/2 |∂²τ/∂x²| + 2 δτ/s, δτ the round-off of τ, ∂²τ/∂x² from the referee; through
|M⁻¹| for the forward ones). A difference beyond its prediction is a finding.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from dyncheck.adapters.layout import Canonical
from dyncheck.adapters.model_tree import (
    DerivativeChart,
    Derivatives,
    ModelTree,
)
from dyncheck.adapters.model_tree import derivatives as collect
from dyncheck.check.derivative_charts import perturb, same_layout, to_canonical
from dyncheck.check.derivative_pairs import across_readings, after_defects, compare
from dyncheck.check.describe import depth
from dyncheck.check.dynamics import States
from dyncheck.check.referee import TIE_STATES, ReferenceModel, Tie, tie
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, standing
from dyncheck.results import Verdict

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
    method by :class:`~dyncheck.check.referee.ReferenceModel`) differentiated by a complex
    step — τ(q ⊕ iη e_k, v, v̇) and τ(q, v + iη e_k, v̇), the imaginary part over η: no
    cancellation, so no truncation error and no extrapolation; the error is the recursion's
    round-off. The second and third derivatives along the chart, which bound an engine's
    finite differences, are central differences of these exact first derivatives at
    ±:data:`CURVE`; ∂²τ/∂v_k² = 2 h₀(q, e_k), h₀ the bias without gravity (h is quadratic in
    v). Where ``bounds`` is false (an RK4 stage's referee) only what a step's chain rule
    needs is computed: the forward derivatives (the inverse ones at v̇ = a, the bounds and
    their error estimates are zero), and the tie is ``tied``, the step's own referee's."""
    from dyncheck.adapters.layout import canonical

    canon = canonical(tree)
    model = ReferenceModel(tree)
    solver = model.recursive
    q, v, a = states.q, states.v, states.a
    n, nv = v.shape
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
    depth_ = depth(tree)
    rtol = ROUNDOFF_FACTOR * EPS * depth_
    tau_scale = np.maximum(np.abs(bias).max(axis=1), np.abs(
        np.einsum("sij,sj->si", mass, a)).max(axis=1))
    roundoff = rtol * np.maximum(tau_scale, 1e-300)
    spread = max(1.0, float(np.abs(v).max()))
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
    return Referee(
        derivatives=collect(out, method="recursive Newton-Euler differentiated by a complex "
                            "step (exact to round-off; tied to the general method)"),
        error=error, second_q=second_q, third_q=third_q, second_v=second_v,
        inverse_mass=inverse_mass, roundoff=roundoff, roundoff_v=roundoff / spread,
        forward=forward, tie=tied, standing=standing(*solver.reach(q)))


def _row(model: str, engine: str, verdict: Verdict, note: str) -> CheckRow:
    return CheckRow(model=model, section=Section.DERIVATIVES, subject="derivatives",
                    field="offered", impl_a=engine, impl_b="", value_a="", value_b="",
                    error=0.0, tolerance=0.0, basis="", verdict=verdict, note=note)


def _collect(engine: object, name: str, inputs: tuple[np.ndarray, np.ndarray, np.ndarray],
             seconds: dict[str, float]) -> Derivatives | Exception:
    """An engine's own derivatives (submitted earlier where it runs in a process of its own),
    or the exception it raised; its seconds into ``seconds``."""
    import time

    t0 = time.perf_counter()
    try:
        if hasattr(engine, "submit"):
            own, took = engine.collect()  # type: ignore[attr-defined]
        else:
            own = engine.derivatives(*inputs)  # type: ignore[attr-defined]
            took = time.perf_counter() - t0
    except Exception as exc:  # reported by the caller, as a row of its own
        return exc
    seconds[f"d {name}"] = took
    return own


SECONDS_PER_STATE_DOF2 = 3e-5
"""What the derivatives' rows cost on this machine per state and per nv² (every engine and
the referee; reports/benchmark-check.md: a 35-dof humanoid at 100 states ≈ 3 s, a 200-hinge
chain at 10 states ≈ 14 s): the estimate said before a long derivative check starts."""


def expected_seconds(states: int, nv: int) -> float:
    """About how long the derivatives' rows of ``states`` states of ``nv`` degrees of freedom
    take (:data:`SECONDS_PER_STATE_DOF2`)."""
    return SECONDS_PER_STATE_DOF2 * states * nv * nv


def rows(model: str, canon: Canonical, tree: ModelTree, engines: Mapping[str, object],
         states: States, *, with_referee: bool,
         seconds: dict[str, float] | None = None,
         readings: Mapping[str, ModelTree] | None = None) -> list[CheckRow]:
    """Every pair's derivative rows: ``engines`` are the loaded engines (name → the engine,
    whole trees only) in the canonical order; the referee is a side when ``with_referee``.
    Engines in processes of their own differentiate while the referee does; ``seconds``
    receives each one's own time ("d <name>") and the mapping's ("d map"). ``readings``:
    the engines that read a field the dynamics use otherwise than ``tree`` (name → its own
    reading in the canonical layout): each is judged against the referee on its own reading,
    and a pair with one of them is compared after the readings' measured difference (the
    referee on one reading minus the other's) — explained where that accounts for it."""
    import time

    from dyncheck.adapters import layout
    from dyncheck.check.steps import step_rows  # it imports this module (Referee)
    from dyncheck.errors import Unsupported

    seconds = {} if seconds is None else seconds
    names = (["reference"] if with_referee else []) + list(engines)
    out: list[CheckRow] = []
    inputs = {}
    # an engine in its own process whose layout is the canonical one (MuJoCo's) is asked for
    # its derivatives and its step Jacobians in one request: it steps while the referee works
    canonical_layout = {name: same_layout(canon, engine.tree, states)  # type: ignore[attr-defined]
                        for name, engine in engines.items()}
    at_steps = step_states(tree, len(states.q))
    both: set[str] = set()
    for name, engine in engines.items():
        mine: ModelTree = engine.tree  # type: ignore[attr-defined]
        inputs[name] = layout.engine_states(canon, mine, states.q, states.v, states.a)[1:]
        if with_referee and canonical_layout[name] and hasattr(engine, "submit_both"):
            engine.submit_both(*inputs[name], at_steps)
            both.add(name)
        elif hasattr(engine, "submit"):
            engine.submit(*inputs[name], kind="derivatives")
    stepping: dict[str, object] = {}  # engine → its step Jacobians, or how they failed
    t0 = time.perf_counter()
    ref = referee(tree, states)
    own_refs = {name: judged for name, reading in (readings or {}).items() if name in engines
                and (judged := referee(reading, states)).tie.agrees}
    seconds["d reference"] = time.perf_counter() - t0
    trusted = with_referee and ref.tie.agrees
    if with_referee and not trusted:  # never silently trusted: its rows give way to this one
        out.append(replace(ref.tie.row(model), section=Section.DERIVATIVES))
    found: dict[str, Derivatives] = {"reference": ref.derivatives} if trusted else {}
    # the engines still stepping (MuJoCo's derivatives and steps in one request) last: the
    # others' derivatives are mapped meanwhile
    for name, engine in sorted(engines.items(), key=lambda item: item[0] in both):
        if name in both:
            try:
                own_part, step_part = engine.collect_both()  # type: ignore[attr-defined]
            except Exception as exc:  # its process died: its rows say so
                own_part = step_part = exc
            own = own_part if isinstance(own_part, Exception) else own_part[0]
            if isinstance(own_part, tuple):
                seconds[f"d {name}"] = own_part[1]
            stepping[name] = step_part if isinstance(step_part, Exception) else step_part[0]
        else:
            own = _collect(engine, name, inputs[name], seconds)
        if isinstance(own, Unsupported):
            out.append(_row(model, name, Verdict.SKIPPED, str(own)))
        elif isinstance(own, AttributeError):
            out.append(_row(model, name, Verdict.SKIPPED, f"{name} offers no derivatives"))
        elif isinstance(own, Exception):  # an engine failing costs its own rows
            out.append(_row(model, name, Verdict.FAILED, f"{type(own).__name__}: {own}"))
        else:
            assert isinstance(own, Derivatives)
            t0 = time.perf_counter()
            try:
                if own.chart is DerivativeChart.TANGENT and canonical_layout[name]:
                    found[name] = own  # its layout is the canonical one: nothing to map
                else:
                    values = engine.dynamics(*inputs[name])  # type: ignore[attr-defined]
                    mine = engine.tree  # type: ignore[attr-defined]
                    mapped = to_canonical(canon, mine, states, own, values)
                    if own.own_differences is not None:
                        mapped = replace(mapped, defect=own.defect, own_differences=to_canonical(
                            canon, mine, states, own.own_differences, values))
                    found[name] = mapped
            except Exception as exc:  # an engine failing costs its own rows
                out.append(_row(model, name, Verdict.FAILED, f"{type(exc).__name__}: {exc}"))
            seconds["d map"] = seconds.get("d map", 0.0) + time.perf_counter() - t0
        if (with_referee and canonical_layout[name] and name not in both
                and hasattr(engine, "transition")):
            try:  # in this process: its steps are taken now
                stepping[name] = engine.transition(*(x[:at_steps] for x in inputs[name]))
            except Exception as exc:
                stepping[name] = exc
    for name, steps in stepping.items():
        if not trusted or isinstance(steps, (Unsupported, AttributeError)):
            continue  # no trusted referee, or no steps offered
        if isinstance(steps, Exception):  # costs its own row
            out.append(_row(model, name, Verdict.FAILED, f"{type(steps).__name__}: {steps}"))
            continue
        for step in steps:  # type: ignore[attr-defined]
            out.extend(step_rows(model, canon, tree, first(states, at_steps),
                                 first(ref, at_steps), name, step, of=len(states.q)))
    order = [n for n in names if n in found]
    for i, a_name in enumerate(order):
        for b_name in order[i + 1 :]:
            eps = max(getattr(engines.get(a_name), "tree", tree).eps,
                      getattr(engines.get(b_name), "tree", tree).eps)
            if a_name == "reference" and b_name in own_refs:  # on b's own reading
                on_b = own_refs[b_name]
                out.extend(replace(r, basis=f"{r.basis}; the referee on {b_name}'s reading")
                           for r in compare(model, tree, a_name, on_b.derivatives, b_name,
                                            found[b_name], on_b, eps=eps))
            elif a_name in own_refs or b_name in own_refs:
                out.extend(across_readings(model, tree, a_name, found[a_name], b_name,
                                            found[b_name], own_refs.get(a_name, ref),
                                            own_refs.get(b_name, ref), eps))
            else:
                out.extend(after_defects(model, tree, a_name, found[a_name], b_name,
                                         found[b_name], ref, eps=eps))
    return out


