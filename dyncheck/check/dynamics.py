"""Step 5 of a model check: the smooth dynamics of every implementation at the same sampled
states (:func:`dyncheck.check.sampling.sample`), in the canonical layout, compared pair by pair.

Tolerances (relative to the quantity's scale): the recursive algorithms accumulate round-off
along a chain, 64 ε × the tree's depth; forward dynamics solves M v̇ = −h and is amplified by
κ(M), the largest over the states. Potential energies are compared as V(q) − V(q₀) (q₀ the
first state): each engine's datum is its own. A quantity's scale is the largest |value| over
the states, never below the scale the states themselves set (:func:`floors`), so that a
quantity that vanishes or is constant on this model — the potential energy of a model moving
in a horizontal plane, h without gravity — is measured against an absolute scale, never
divided by zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.model_tree import QUANTITY_OF, Dynamics, ModelTree
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, eps_name
from dyncheck.referee.computed import depth, size
from dyncheck.referee.states import States, condition
from dyncheck.referee.tree import GENERAL, RECURSIVE, Tie
from dyncheck.vocabulary import Quantity, Verdict

QUANTITIES: dict[str, str] = {q: f for f, q in QUANTITY_OF.items()}
"""The quantity → the field of Dynamics holding it."""


PARTIAL_ENERGY = ("an energy is a sum over every body, and one of the two engines holds only "
                  "part of the model (the notes say which)")


def floors(tree: ModelTree, dyn: Dynamics, states: States) -> dict[str, tuple[float, str]]:
    """The smallest scale of each quantity, with its name: generalized forces (h, τ) the
    largest |M a| of the sampled accelerations; accelerations the largest sampled |a|;
    energies the larger of the largest kinetic energy and m g L (total mass, |gravity|, the
    model's size)."""
    force = float(np.abs(np.einsum("nij,nj->ni", dyn.mass_matrix, states.a)).max())
    accel = float(np.abs(states.a).max())
    mgl = sum(j.mass for j in tree.joints) * float(np.linalg.norm(tree.gravity)) * size(tree)
    energy = max(float(np.nanmax(np.abs(dyn.kinetic), initial=0.0)), mgl)
    return {
        Quantity.MASS_MATRIX: (0.0, ""),
        Quantity.BIAS_FORCES: (force, "|M a|"), Quantity.INVERSE_DYNAMICS: (force, "|M a|"),
        Quantity.FORWARD_DYNAMICS: (accel, "|a|"),
        Quantity.KINETIC_ENERGY: (energy, "max(T, m g L)"),
        Quantity.POTENTIAL_ENERGY: (energy, "max(T, m g L)"),
    }


def values(dyn: Dynamics, quantity: str) -> np.ndarray:
    """One quantity per state as rows (n, k); the potential energy as V(q) − V(q₀)."""
    value = getattr(dyn, QUANTITIES[quantity])
    if quantity == Quantity.POTENTIAL_ENERGY:
        value = value - value[0]
    return value.reshape(len(value), -1)


@dataclass(frozen=True, kw_only=True)
class Prediction:
    """A predicted difference and why, for a pair and a quantity: per state, its size (n,)
    or the difference b − a itself (n, k), component by component; ``label`` the property
    that predicts it, as :data:`dyncheck.explain.explanations.EXPLANATIONS` registers it."""

    size: np.ndarray
    note: str
    label: str


def _as_predicted(difference: np.ndarray, errors: np.ndarray, predicted: np.ndarray,
                  tolerance: float) -> bool:
    """Whether the differences are the prediction within ``tolerance`` (and 1e-9 of the
    prediction's own size): sizes per state, or the vectors where it predicts them."""
    if predicted.ndim == 1:
        return bool(np.all(np.abs(errors - predicted) <= tolerance + 1e-9 * predicted))
    off = np.abs(difference - predicted.reshape(difference.shape)).max(axis=1)
    return bool(np.all(off <= tolerance + 1e-9 * np.abs(predicted).max(axis=1)))


def _candidates(known: Prediction | None, read: Prediction | None) -> list[Prediction]:
    """The predictions to try in turn: a computing convention, the readings' difference, and
    both together where both are vectors (their effects add, to first order)."""
    out = [p for p in (known, read) if p is not None]
    if known is not None and read is not None and known.size.ndim == read.size.ndim == 2:
        out.append(Prediction(size=known.size + read.size, note=f"{known.note}; and {read.note}",
                              label=known.label))
    return out


def _round_off(*, eps: float, depth: int, standing: float, vertices: float) -> tuple[float, str]:
    """A pair's round-off bound and its basis: c ε × the tree's depth × max(1, X/ℓ), plus
    the inertias' difference where one engine takes them from float32 mesh vertices."""
    rtol = ROUNDOFF_FACTOR * eps * depth * standing + vertices
    basis = f"round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x tree depth {depth}"
    if standing > 1:
        basis += f" x X/l {standing:.3g} (positions far from the origin)"
    if vertices:
        basis += f"; + {vertices:.2g}: one engine's inertia from float32 mesh vertices"
    return rtol, basis


def _unavailable_row(model: str, quantity: str,
                     *sides: tuple[str, Dynamics]) -> CheckRow | None:
    """A skipped row naming the engine(s) that do not compute ``quantity`` on this model
    (their limit, in their words: :attr:`~dyncheck.adapters.model_tree.Dynamics.
    unavailable`), or None."""
    unavailable = [(name, why) for name, dyn in sides
                   for field, why in dyn.unavailable if field == QUANTITIES[quantity]]
    if not unavailable:
        return None
    return CheckRow(
        model=model, section=Section.DYNAMICS, subject=quantity, field="max rel error",
        impl_a=sides[0][0], impl_b=sides[1][0], value_a="", value_b="", error=0.0,
        tolerance=0.0, basis="", verdict=Verdict.SKIPPED,
        note="; ".join(f"{name} does not compute it here: {why}" for name, why in unavailable))


def compare(
    model: str,
    tree: ModelTree,
    *,
    name_a: str,
    dyn_a: Dynamics,
    name_b: str,
    dyn_b: Dynamics,
    explanations: dict[str, Prediction],
    readings: dict[str, Prediction],
    states: States,
    eps: float = EPS,
    kappa: float | None = None,
    vertices: float = 0.0,
    standing: float = 1.0,
    judged_on: str = "",
) -> list[CheckRow]:
    """One row per quantity. A failure is ``explained`` where ``explanations`` predicts it (a
    computing convention an engine declares), or where ``readings`` does (the referee on one
    engine's reading minus on the other's: the measured effect of their reading differently),
    each within prediction + tolerance; else it fails, "cause unknown". ``eps``: the coarser
    precision of the two (a float32 port's ε₃₂: the same bounds in its arithmetic); ``kappa``:
    κ(M) of ``dyn_a`` where the caller has it (one per implementation, not per pair);
    ``vertices``: the relative difference of the two models' inertias where one takes them
    from float32 mesh vertices and the other from the file's digits (M, h, τ and the energies
    are linear in the masses and inertias); ``standing``: max(1, X/ℓ), how far from the world
    origin the model stands in its own lengths (:func:`dyncheck.precision.standing`);
    ``judged_on``: whose reading ``dyn_a`` (the referee) was evaluated on, for the basis."""
    d = depth(tree)
    kappa = condition(dyn_a.mass_matrix) if kappa is None else kappa
    least = floors(tree, dyn_a, states)
    rows = []
    for quantity in QUANTITIES:
        desired, actual = values(dyn_a, quantity), values(dyn_b, quantity)
        if (limit := _unavailable_row(model, quantity, (name_a, dyn_a), (name_b, dyn_b))):
            rows.append(limit)  # an engine's limit on this model: in its words
            continue
        if np.isnan(desired).all() or np.isnan(actual).all():
            rows.append(CheckRow(
                model=model, section=Section.DYNAMICS, subject=quantity, field="max rel error",
                impl_a=name_a, impl_b=name_b, value_a="", value_b="", error=0.0, tolerance=0.0,
                basis="", verdict=Verdict.SKIPPED, note=PARTIAL_ENERGY))
            continue
        floor, floor_name = least[quantity]
        scale = max(float(np.abs(desired).max()), floor, 1e-300)
        errors = np.abs(actual - desired).max(axis=1)
        worst = int(np.argmax(errors))
        rtol, basis = _round_off(eps=eps, depth=d, standing=standing, vertices=vertices)
        if floor >= float(np.abs(desired).max()) and floor_name:
            basis += f"; scale {floor_name} {floor:.3g} (the value's own is smaller)"
        if quantity == Quantity.FORWARD_DYNAMICS:
            rtol *= kappa
            basis += f" x cond(M) {kappa:.3g}"
        error = float(errors[worst]) / scale
        verdict, note, convention = Verdict.PASSED, "", ""
        if error > rtol:
            verdict = Verdict.FAILED
            note = "cause unknown"
            for known in _candidates(explanations.get(quantity), readings.get(quantity)):
                if _as_predicted(actual - desired, errors, known.size, rtol * scale):
                    verdict, note, convention = Verdict.EXPLAINED, known.note, known.label
                    break
            else:
                if quantity in readings:
                    note = ("cause unknown: beyond what the engines' readings account for "
                            "(the referee on each reading)")
        if judged_on:
            basis += f"; the referee on {judged_on}'s reading"
        rows.append(
            CheckRow(
                model=model, section=Section.DYNAMICS, subject=quantity, field="max rel error",
                impl_a=name_a, impl_b=name_b, value_a="", value_b="", error=error,
                tolerance=rtol, basis=basis, verdict=verdict, note=note,
                convention=convention, worst_state=worst,
            )
        )
    return rows


def tie_row(tie: Tie, model: str) -> CheckRow:
    """The referee's tie (:class:`~dyncheck.referee.tree.Tie`) as a row of the dynamics
    section (failed: the referee disagrees with itself, and the general method gave every
    number on the page)."""
    served = ("the recursive algorithm gave the referee's M, h and dynamics at every "
              "state and its derivatives" if tie.agrees else
              "the referee's two methods disagree on this model (a defect of the referee, not "
              "of an engine): no engine's dynamics are judged against it, the engines are "
              "compared with each other only; the referee's derivatives are not to be trusted")
    return CheckRow(
        model=model, section=Section.DYNAMICS, subject="referee",
        field="recursive Newton-Euler against the general method (M, h)",
        impl_a=GENERAL, impl_b=RECURSIVE, value_a="", value_b="",
        error=max(tie.mass_error, tie.bias_error), tolerance=tie.tolerance,
        basis=(f"round-off: {ROUNDOFF_FACTOR} eps x tree depth"
               + (f" x X/l {tie.standing:.3g} (the general method's momenta about the "
                  "world origin)" if tie.standing > 1 else "")
               + f", at {tie.states} states"),
        verdict=Verdict.PASSED if tie.agrees else Verdict.FAILED,
        note=f"M {tie.mass_error:.3g}, h {tie.bias_error:.3g}; {served}")
