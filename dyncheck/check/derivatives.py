"""Step 6 of a model check (``--derivatives``): the derivatives of the smooth dynamics —
∂v̇/∂q, ∂v̇/∂v, ∂v̇/∂τ = M⁻¹ of the forward dynamics at τ = 0 and ∂τ/∂q, ∂τ/∂v of the inverse
dynamics at the sampled v̇ — of every engine that offers them and of the referee, in the
canonical chart, compared pair by pair.

The chart, and an engine's own derivatives mapped into it: :mod:`dyncheck.referee.charts`.

The referee: the recursive Newton–Euler algorithm (:mod:`dyncheck.reference.recursive`,
§2.2's momentum laws (2.2.48)–(2.2.49) body by body), tied to the book's general method
(:mod:`dyncheck.reference.tree`) on this very tree (:mod:`dyncheck.referee.tree`: where the
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
from dataclasses import replace
from functools import partial

import numpy as np

from dyncheck.adapters.base import ModelEngine, Offer
from dyncheck.adapters.model_tree import (
    Canonical,
    DerivativeChart,
    Derivatives,
    ModelTree,
)
from dyncheck.check.derivative_pairs import (
    across_readings,
    after_defects,
    with_defects,
)
from dyncheck.check.dynamics import tie_row
from dyncheck.check.rows import CheckRow, Section
from dyncheck.check.steps import step_rows
from dyncheck.errors import Unsupported
from dyncheck.referee.charts import same_layout, to_canonical
from dyncheck.referee.derivatives import Referee, first, referee, step_states
from dyncheck.referee.states import States
from dyncheck.vocabulary import Verdict


def _row(model: str, engine: str, verdict: Verdict, note: str) -> CheckRow:
    return CheckRow(model=model, section=Section.DERIVATIVES, subject="derivatives",
                    field="offered", impl_a=engine, impl_b="", value_a="", value_b="",
                    error=0.0, tolerance=0.0, basis="", verdict=verdict, note=note)


def _collect(engine: ModelEngine, name: str,
             seconds: dict[str, float]) -> Derivatives | Exception:
    """An engine's own derivatives, submitted earlier (an engine in a process of its own
    computed them meanwhile), or the exception it raised; its seconds into ``seconds``."""
    try:
        own, took = engine.collect()
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


def rows(model: str, canon: Canonical, tree: ModelTree, engines: Mapping[str, ModelEngine],
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

    seconds = {} if seconds is None else seconds
    names = (["reference"] if with_referee else []) + list(engines)
    out: list[CheckRow] = []
    inputs = {}
    # an engine in its own process whose layout is the canonical one (MuJoCo's) is asked for
    # its derivatives and its step Jacobians in one request: it steps while the referee works
    canonical_layout = {name: same_layout(canon, engine.tree, states)
                        for name, engine in engines.items()}
    at_steps = step_states(tree, len(states.q))
    both: set[str] = set()
    for name, engine in engines.items():
        inputs[name] = layout.engine_states(canon, engine.tree, states.q, states.v,
                                                  states.a)[1:]
        if with_referee and canonical_layout[name] and Offer.TRANSITION in engine.offers:
            engine.submit_both(*inputs[name], at_steps)
            both.add(name)
        else:
            engine.submit(*inputs[name], kind="derivatives")
    stepping: dict[str, object] = {}  # engine → its step Jacobians, or how they failed
    t0 = time.perf_counter()
    ref = referee(tree, states)
    own_refs = {name: judged for name, reading in (readings or {}).items() if name in engines
                and (judged := referee(reading, states)).tie.agrees}
    seconds["d reference"] = time.perf_counter() - t0
    trusted = with_referee and ref.tie.agrees
    if with_referee and not trusted:  # never silently trusted: its rows give way to this one
        out.append(replace(tie_row(ref.tie, model), section=Section.DERIVATIVES))
    found: dict[str, Derivatives] = {"reference": ref.derivatives} if trusted else {}
    # the engines still stepping (MuJoCo's derivatives and steps in one request) last: the
    # others' derivatives are mapped meanwhile
    for name, engine in sorted(engines.items(), key=lambda item: item[0] in both):
        own = _answer(engine, name, stepping=stepping, seconds=seconds) if name in both \
            else _collect(engine, name, seconds)
        if isinstance(own, Unsupported):
            out.append(_row(model, name, Verdict.SKIPPED, str(own)))
        elif isinstance(own, Exception):  # an engine failing costs its own rows
            out.append(_row(model, name, Verdict.FAILED, f"{type(own).__name__}: {own}"))
        else:
            assert isinstance(own, Derivatives)
            t0 = time.perf_counter()
            try:
                found[name] = _canonical(canon, engine, states, own, inputs=inputs[name],
                                         same=canonical_layout[name])
            except Exception as exc:  # an engine failing costs its own rows
                out.append(_row(model, name, Verdict.FAILED, f"{type(exc).__name__}: {exc}"))
            seconds["d map"] = seconds.get("d map", 0.0) + time.perf_counter() - t0
    if trusted:  # (no trusted referee: no step rows)
        for name, steps in stepping.items():
            out += _stepping_rows(model, canon, tree, name, steps=steps, states=states,
                                  ref=ref, at_steps=at_steps)
    order = [n for n in names if n in found]
    out.extend(_pair_rows(model, tree, order=order, found=found, engines=engines, ref=ref,
                          own_refs=own_refs))
    return out


def _answer(engine: ModelEngine, name: str, *, stepping: dict[str, object],
            seconds: dict[str, float]) -> object:
    """The derivatives of an engine asked for them and its step Jacobians in one request
    (its process died: the exception, for both); the Jacobians go to ``stepping``."""
    try:
        own_part, step_part = engine.collect_both()
    except Exception as exc:  # its process died: its rows say so
        own_part = step_part = exc
    if isinstance(own_part, tuple):
        seconds[f"d {name}"] = own_part[1]
    stepping[name] = step_part if isinstance(step_part, Exception) else step_part[0]
    return own_part if isinstance(own_part, Exception) else own_part[0]


def _canonical(canon: Canonical, engine: ModelEngine, states: States, own: Derivatives, *,
               inputs: tuple[np.ndarray, ...], same: bool) -> Derivatives:
    """An engine's derivatives in the canonical layout and chart (as given where its layout
    is the canonical one and its chart the tangent one: nothing to map), its own finite
    differences mapped with them."""
    if own.chart is DerivativeChart.TANGENT and same:
        return own
    values = engine.dynamics(*inputs)
    mine = engine.tree
    mapped = to_canonical(canon, mine, states, own, values)
    if own.own_differences is not None:
        mapped = replace(mapped, defect=own.defect, own_differences=to_canonical(
            canon, mine, states, own.own_differences, values))
    return mapped


def _stepping_rows(model: str, canon: Canonical, tree: ModelTree, name: str, *, steps: object,
                   states: States, ref: Referee, at_steps: int) -> list[CheckRow]:
    """An engine's step Jacobians against the referee's chain rule (none where it offers no
    steps; one failed row where they failed)."""
    if isinstance(steps, Unsupported):
        return []
    if isinstance(steps, Exception):  # costs its own row
        return [_row(model, name, Verdict.FAILED, f"{type(steps).__name__}: {steps}")]
    out: list[CheckRow] = []
    for step in steps:  # type: ignore[attr-defined]
        out.extend(step_rows(model, canon, tree, first(states, at_steps),
                             first(ref, at_steps), name, step, of=len(states.q)))
    return out


def _pair_rows(model: str, tree: ModelTree, *, order: list[str], found: dict[str, Derivatives],
               engines: Mapping[str, ModelEngine], ref: Referee,
               own_refs: dict[str, Referee]) -> list[CheckRow]:
    """The rows of every pair of ``order`` (the sides whose derivatives were ``found``): a
    pair with an engine that reads the model otherwise (``own_refs``: the referee on its own
    reading) is compared on that reading; a declared defect is compared after it."""
    rows: list[CheckRow] = []
    for i, a_name in enumerate(order):
        for b_name in order[i + 1 :]:
            eps = max((engines[n].tree if n in engines else tree).eps for n in (a_name, b_name))
            if a_name == "reference" and b_name in own_refs:  # on b's own reading
                on_b = own_refs[b_name]
                rows.extend(replace(r, basis=f"{r.basis}; the referee on {b_name}'s reading")
                           for r in after_defects(model, tree, name_a=a_name,
                                                  da=on_b.derivatives, name_b=b_name,
                                                  db=found[b_name], ref=on_b, eps=eps))
            elif a_name in own_refs or b_name in own_refs:  # (a declared defect after it)
                rows.extend(with_defects(partial(
                    across_readings, model, tree, name_a=a_name, name_b=b_name,
                    ref_a=own_refs.get(a_name, ref), ref_b=own_refs.get(b_name, ref), eps=eps),
                    name_a=a_name, da=found[a_name], name_b=b_name, db=found[b_name]))
            else:
                rows.extend(after_defects(model, tree, name_a=a_name, da=found[a_name],
                                         name_b=b_name, db=found[b_name], ref=ref, eps=eps))
    return rows
