"""The closures section of a model's check (#78): where the file closes its tree with
constraints, the states moved onto them, and each engine that computes with them measured
against the referee's constrained method (:mod:`.closures`) — its rows, its soft model, its
distance from the rigid answer; an engine that offers no constrained dynamics has one skipped
row saying so."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dyncheck.adapters import layout
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.model_tree import Canonical, ModelTree, canonical
from dyncheck.adapters.offers import Offer
from dyncheck.check import closure_derivatives, closure_readings, closures
from dyncheck.check.rows import CheckRow, Section
from dyncheck.errors import EngineError, Unsupported
from dyncheck.labels import SOFT_CONSTRAINT
from dyncheck.referee.computed import canonical_reading
from dyncheck.referee.states import States
from dyncheck.vocabulary import REFEREE, Verdict

ROWS_BASIS = "64 eps x reach (lengths), x |J| (rows)"
SOFT_BASIS = "64 eps x k(M) x k(A + R)"


def _row(model: str, *, subject: str, field: str, engine: str, verdict: Verdict, note: str,
         value_a: str = "", value_b: str = "", error: float = 0.0, tolerance: float = 0.0,
         basis: str = "", convention: str = "") -> CheckRow:
    return CheckRow(model=model, section=Section.CLOSURES, subject=subject, field=field,
                    impl_a=REFEREE if engine else "", impl_b=engine, value_a=value_a,
                    value_b=value_b, error=error, tolerance=tolerance, basis=basis,
                    verdict=verdict, note=note, convention=convention)


def _without(name: str) -> str:
    return (f"{name}'s own constrained dynamics are not compared: dyncheck drives no "
            f"constraint solver of {name}'s yet")


def _dropped(states: closures.ClosedStates) -> str:
    """The dropped draws' farthest constraint, as words (empty: none dropped)."""
    if states.unmet is None:
        return ""
    name, far = states.unmet
    return (f"; {states.drawn - len(states.q)} dropped, none closer to meeting {name!r} than "
            f"|C| = {far:.2g}")


def _unread(name: str, tree: ModelTree) -> str:
    """Why an engine's constraints are not compared: the note of the copy it was given
    without them, or that its loader reads none."""
    refused = next((n for n in tree.notes if n.endswith("its constraints are not read")), "")
    if refused:
        return refused
    given = next((n for n in tree.notes if "without its equality constraints" in n), "")
    return (f"{name}'s constraints are not compared: " + (given.split(": ", 1)[-1] if given
            else "dyncheck reads none of its constraint models yet"))


def reach(tree: ModelTree) -> float:
    """The model's size in its lengths: the farthest anchor or closure point from the
    origin (1 at least)."""
    points = [j.anchor for j in tree.joints] + [p for c in tree.closures
                                                 for p in (c.point1, c.point2)]
    return max([1.0, *(float(np.linalg.norm(p)) for p in points)])


def in_canonical(canon: Canonical, engine: ModelEngine, states: closures.ClosedStates,
                 tau: np.ndarray) -> tuple[ModelTree, ClosedReading]:
    """The engine's reading put in the canonical layout, and its answer at the states (given
    canonical, handed to it in its own layout): v̇ = T⁻¹ (v̇ₑ − Ṫ v), J = Jₑ T."""
    tree = canonical_reading(canon, engine.tree)
    maps, q_e, v_e, _ = layout.engine_states(canon, engine.tree, states.q, states.v,
                                                   np.zeros_like(states.v))
    t = np.array([m.t for m in maps])
    tdot_v = np.array([m.tdot_v for m in maps])
    tau_e = layout.back(np.swapaxes(t, 1, 2), tau)  # τ·v invariant
    found = engine.closed(q_e, v_e, tau_e)
    return tree, replace(found, jacobian=found.jacobian @ t,
                         vdot=layout.back(t, found.vdot - tdot_v))


def rows(model: str, canonical_tree: ModelTree, loaded: dict[str, ModelEngine],
         batch: States, *, derivatives: bool = False) -> list[CheckRow]:
    """The section's rows (none where the canonical engine reads no closure); with
    ``derivatives`` (``check --derivatives``), those of the closed dynamics where an engine
    offers them (:mod:`.closure_derivatives`)."""
    if not canonical_tree.closures:
        return []
    size = reach(canonical_tree)
    states = closures.on_constraints(canonical_tree, batch.q, batch.v, reach=size)
    kept = len(states.q)
    names = ", ".join(c.name for c in canonical_tree.closures)
    out = [_row(model, subject="states", field="on the constraints", engine="",
                verdict=Verdict.PASSED if kept else Verdict.FAILED,
                value_a=f"{kept} of {states.drawn} kept",
                value_b=f"|C| <= {states.residual:.1e}, |J v| <= {states.rate:.1e}",
                note=f"{kept} of {states.drawn} sampled states moved onto {names} by "
                     "Newton's method on C(q) = 0 (a draw that does not converge is dropped"
                     f"{_dropped(states)}), velocities onto J's null space: |C| <= "
                     f"{states.residual:.1e}, |J v| <= {states.rate:.1e}" if kept else
                     f"no sampled state could be moved onto {names}{_dropped(states)}: the "
                     "constraints cannot all be met near the sampled configurations (they "
                     "conflict, or a loop cannot close with the file's lengths)")]
    if not kept:
        return out
    for name, engine in loaded.items():
        if not engine.tree.closures_read:
            out.append(_row(model, subject="model", field="closures", engine=name,
                            verdict=Verdict.SKIPPED, note=_unread(name, engine.tree)))
            continue
        out += closure_readings.rows(model, canonical_tree, engine.tree, reach=size)
        if not engine.tree.closures:
            continue  # (its reading rows say it holds none: nothing to compute with)
        if Offer.CLOSURES not in engine.offers:
            out.append(_row(model, subject="model", field="closed dynamics", engine=name,
                            verdict=Verdict.SKIPPED,
                            note=_without(name)))
            continue
        out += _engine_rows(model, name, engine, states, size=size,
                            canonical_tree=canonical_tree, derivatives=derivatives)
    return out


def _engine_rows(model: str, name: str, engine: ModelEngine, states: closures.ClosedStates,
                 *, size: float, canonical_tree: ModelTree,
                 derivatives: bool) -> list[CheckRow]:
    """One engine's rows: its constraint rows, its soft model where it holds one, the rigid
    answer — each judged on its own reading of the closures."""
    if {j.name for j in engine.tree.joints} != {j.name for j in canonical_tree.joints}:
        return [_row(model, subject="model", field="closed dynamics", engine=name,
                     verdict=Verdict.SKIPPED, note=f"{name} holds part of the model (its "
                     "reading rows): its closed dynamics are compared only on the whole")]
    tau = np.zeros_like(states.v)
    canon = canonical(canonical_tree)
    try:
        tree, reading = in_canonical(canon, engine, states, tau)
    except Unsupported as exc:  # (what it, or dyncheck, does not compute: said as such)
        return [_row(model, subject="model", field="closed dynamics", engine=name,
                     verdict=Verdict.SKIPPED, note=str(exc))]
    except EngineError as exc:
        return [_row(model, subject="model", field="closed dynamics", engine=name,
                     verdict=Verdict.FAILED, note=f"{name} failed: {exc}")]
    found = closures.measure(tree, reading, states, tau=tau, reach=size)
    if derivatives and Offer.CLOSED_DERIVATIVES in engine.offers:
        derived = closure_derivatives.rows(
            model, name, engine, states, tree=tree, reading=reading, canon=canon,
            own=lambda q, v: in_canonical(canon, engine, replace(states, q=q, v=v),
                                          np.zeros_like(v))[1].vdot)
    else:
        derived = []
    shape = max(found.residual / size, found.jacobian, found.row_space)
    out = [_row(model, subject="model", field="constraint rows", engine=name,
                verdict=Verdict.PASSED if shape <= found.rows_bound else Verdict.FAILED,
                error=shape, tolerance=found.rows_bound, basis=ROWS_BASIS,
                note="C and J of its constraints at the referee's states" if
                shape <= found.rows_bound else "cause unknown: its constraints are not the "
                "referee's reading of them at the same states")]
    soft = any(c.soft for c in tree.closures)
    if found.bound >= 1.0:  # (a relative bound of 1 or more judges nothing)
        out.append(_row(model, subject="forward", field="max rel error", engine=name,
                        verdict=Verdict.SKIPPED, error=found.soft if soft else found.rigid,
                        tolerance=found.bound, basis=SOFT_BASIS, note=(
                            f"not judged: its arithmetic's round-off bound on this model, "
                            f"{found.bound:.3g} of the accelerations (64 eps x k(M) x "
                            "k(A + R), eps its own), allows any answer")))
        return out + derived
    if soft:
        out.append(_row(model, subject="forward (soft)", field="max rel error", engine=name,
                        verdict=Verdict.PASSED if found.soft <= found.bound else Verdict.FAILED,
                        error=found.soft, tolerance=found.bound, basis=SOFT_BASIS,
                        note="against the referee's soft model with the file's solref and "
                             "solimp" if found.soft <= found.bound else "cause unknown: not "
                             "the soft model its file states"))
    rigid = Verdict.PASSED if found.rigid <= found.bound else (
        Verdict.EXPLAINED if soft and abs(found.rigid - found.predicted) <= 2 * found.bound
        else Verdict.FAILED)
    why = {Verdict.PASSED: "the rigid answer, to round-off",
           Verdict.EXPLAINED: f"its constraints are soft (solref, solimp): the soft model "
                              f"predicts {found.predicted:.3g} from the rigid answer",
           Verdict.FAILED: f"cause unknown: the soft model predicts {found.predicted:.3g}"
           if soft else "cause unknown: it holds its constraints rigidly"}
    out.append(_row(model, subject="forward (rigid)", field="max rel error", engine=name,
                    verdict=rigid, error=found.rigid, tolerance=found.bound,
                    basis=SOFT_BASIS, note=why[rigid],
                    convention=SOFT_CONSTRAINT if rigid is Verdict.EXPLAINED else ""))
    return out + derived
