"""The closures section of a model's check (#78): where the file closes its tree with
constraints, the states moved onto them, and each engine that computes with them measured
against the referee's constrained method (:mod:`.closures`) — its rows, its soft model, its
distance from the rigid answer; an engine that offers no constrained dynamics has one skipped
row saying so."""

from __future__ import annotations

import numpy as np

from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.model_tree import ModelTree
from dyncheck.adapters.offers import Offer
from dyncheck.check import closures
from dyncheck.check.rows import CheckRow, Section
from dyncheck.check.states import States
from dyncheck.errors import EngineError, Unsupported
from dyncheck.roster import REFEREE
from dyncheck.vocabulary import Verdict

ROWS_BASIS = "64 eps x reach (lengths), x |J| (rows)"
SOFT_BASIS = "64 eps x k(M) x k(A + R)"


def _row(model: str, *, subject: str, field: str, engine: str, verdict: Verdict, note: str,
         value_a: str = "", value_b: str = "", error: float = 0.0, tolerance: float = 0.0,
         basis: str = "") -> CheckRow:
    return CheckRow(model=model, section=Section.CLOSURES, subject=subject, field=field,
                    impl_a=REFEREE if engine else "", impl_b=engine, value_a=value_a,
                    value_b=value_b, error=error, tolerance=tolerance, basis=basis,
                    verdict=verdict, note=note)


def _without(name: str) -> str:
    return (f"{name}'s own constrained dynamics are not compared: dyncheck drives no "
            f"constraint solver of {name}'s yet")


def reach(tree: ModelTree) -> float:
    """The model's size in its lengths: the farthest anchor or closure point from the
    origin (1 at least)."""
    points = [j.anchor for j in tree.joints] + [p for c in tree.closures
                                                 for p in (c.point1, c.point2)]
    return max([1.0, *(float(np.linalg.norm(p)) for p in points)])


def rows(model: str, canonical_tree: ModelTree, loaded: dict[str, ModelEngine],
         batch: States) -> list[CheckRow]:
    """The section's rows (none where the canonical engine reads no closure)."""
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
                     "Newton's method on C(q) = 0 (a draw that does not converge is dropped), "
                     f"velocities onto J's null space: |C| <= {states.residual:.1e}, "
                     f"|J v| <= {states.rate:.1e}" if kept else
                     f"no sampled state could be moved onto {names}: the constraints cannot "
                     "be met near the sampled configurations")]
    if not kept:
        return out
    for name, engine in loaded.items():
        if Offer.CLOSURES not in engine.offers:
            out.append(_row(model, subject="model", field="closed dynamics", engine=name,
                            verdict=Verdict.SKIPPED,
                            note=_without(name)))
            continue
        out += _engine_rows(model, name, engine, states, size)
    return out


def _engine_rows(model: str, name: str, engine: ModelEngine, states: closures.ClosedStates,
                 size: float) -> list[CheckRow]:
    """One engine's rows: its constraint rows, its soft model, the rigid answer."""
    tau = np.zeros_like(states.v)
    try:
        reading = engine.closed(states.q, states.v, tau)
    except (EngineError, Unsupported) as exc:
        return [_row(model, subject="model", field="closed dynamics", engine=name,
                     verdict=Verdict.FAILED, note=f"{name} failed: {exc}")]
    found = closures.measure(engine.tree, reading, states, tau=tau, reach=size)
    shape = max(found.residual / size, found.jacobian, found.row_space)
    out = [_row(model, subject="model", field="constraint rows", engine=name,
                verdict=Verdict.PASSED if shape <= found.rows_bound else Verdict.FAILED,
                error=shape, tolerance=found.rows_bound, basis=ROWS_BASIS,
                note="C and J of its constraints at the referee's states" if
                shape <= found.rows_bound else "cause unknown: its constraints are not the "
                "referee's reading of them at the same states"),
           _row(model, subject="forward (soft)", field="max rel error", engine=name,
                verdict=Verdict.PASSED if found.soft <= found.bound else Verdict.FAILED,
                error=found.soft, tolerance=found.bound, basis=SOFT_BASIS,
                note="against the referee's soft model with the file's solref and solimp"
                if found.soft <= found.bound else "cause unknown: not the soft model its "
                "file states")]
    rigid = Verdict.PASSED if found.rigid <= found.bound else (
        Verdict.EXPLAINED if abs(found.rigid - found.predicted) <= 2 * found.bound
        else Verdict.FAILED)
    why = {Verdict.PASSED: "the rigid answer, to round-off",
           Verdict.EXPLAINED: f"its constraints are soft (solref, solimp): the soft model "
                              f"predicts {found.predicted:.3g} from the rigid answer",
           Verdict.FAILED: f"cause unknown: the soft model predicts {found.predicted:.3g}"}
    out.append(_row(model, subject="forward (rigid)", field="max rel error", engine=name,
                    verdict=rigid, error=found.rigid, tolerance=found.bound,
                    basis=SOFT_BASIS, note=why[rigid]))
    return out
