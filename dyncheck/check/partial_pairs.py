"""A pair in which an engine holds only part of the model (:mod:`.partial`: Pinocchio's MJCF
parser reads only the first body under ``<worldbody>``), compared on the joints both hold —
judged as whole pairs are: the referee on the partial engine's own reading of its part (does
it compute what it read, §2.2's general method on the tree it holds), and two engines'
readings of that part measured against each other (the referee on each,
:func:`.readings.effect`). Before this, both were judged against the canonical reading of the
part: a field read differently (a gravity flag, a geom's mass) was "cause unknown"."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.model_tree import Dynamics, ModelTree, canonical
from dyncheck.check import partial, predicted, readings
from dyncheck.check.dynamics import QUANTITIES, Prediction, compare
from dyncheck.check.rows import CheckRow, Section
from dyncheck.referee.states import States
from dyncheck.referee.tree import ReferenceModel
from dyncheck.vocabulary import REFEREE, Verdict


def part_reading(batch: States, part: partial.Part, tree: ModelTree) -> readings.Reading | None:
    """The referee on an engine's reading ``tree`` of its ``part``, at the part's
    coordinates of the sampled states; None where its joints are not the part's."""
    own = readings.own_tree(part.tree, tree)
    if own is None:
        return None
    on = partial.states(batch, part)
    with np.errstate(all="ignore"):
        return readings.Reading(tree=own, dynamics=ReferenceModel(own).dynamics(on.q, on.v,
                                                                                 on.a))


def rows(model: str, canonical_tree: ModelTree, *, a: str, b: str, batch: States,
         results: Mapping[str, Dynamics], trees: Mapping[str, ModelTree],
         parts: Mapping[str, partial.Part | None], loaded: Mapping[str, ModelEngine],
         own: Mapping[str, readings.Reading], differing: Mapping[str, list[str]],
         eps: float, vertices: float, standing: float) -> list[CheckRow]:
    """The pair (a, b), one of them partial, on the coordinates both hold. Where one alone is
    partial: against the referee, the referee on its reading of its part (with the computing
    conventions it declares); against a whole engine, the measured effect of the two reading
    the part differently. Two partial engines: on the joints both hold, nothing predicted."""
    held = {n: None if (p := parts.get(n)) is None else p.v for n in (a, b)}
    common = np.arange(canonical_tree.nv)
    for columns in held.values():
        common = np.intersect1d(common, columns) if columns is not None else common
    if not common.size:  # two partial readings with no joint in common (dm_control's
        # ball_in_cup: Pinocchio holds the cup's joints, PyBullet the ball's)
        return [CheckRow(
            model=model, section=Section.DYNAMICS, subject="model", field="dynamics",
            impl_a=a, impl_b=b, value_a="", value_b="", error=0.0, tolerance=0.0, basis="",
            verdict=Verdict.SKIPPED,
            note=f"{a} and {b} hold no joint in common (each holds part of the model, the "
                 "description rows say which): their dynamics are not compared with each "
                 "other")]
    on = States(q=batch.q, v=batch.v[:, common], a=batch.a[:, common])
    dyn_a = partial.restrict(results[a], partial.columns(held[a], common))
    dyn_b = partial.restrict(results[b], partial.columns(held[b], common))
    judged_on = ""
    explanations: dict[str, Prediction] = {}
    effect: dict[str, Prediction] = {}
    if (parts.get(a) is None) != (parts.get(b) is None):  # one whole, one partial
        name = b if parts.get(b) is not None else a
        part, whole = parts[name], a if name == b else b
        assert part is not None
        reading = part_reading(batch, part, loaded[name].tree) if name in loaded else None
        mine = partial.states(batch, part)
        if reading is not None and whole == REFEREE:  # (the referee comes first: a)
            dyn_a, judged_on, vertices = partial.restrict(
                reading.dynamics, np.arange(len(part.v))), b, 0.0
            explanations = predicted.differences(canonical(part.tree), part.tree,
                                                 reading.tree, trees[b], mine, reading.dynamics)
        elif reading is not None and whole in own:
            theirs = _whole_on_part(batch, part, own[whole].tree, reading.tree)
            if theirs is not None:
                first, second = (theirs, reading) if name == b else (reading, theirs)
                effect = _effect(a, b, first=first, second=second, batch=mine,
                                 part=part, differing=differing)
    return compare(model, canonical_tree, name_a=a, dyn_a=dyn_a, name_b=b, dyn_b=dyn_b,
                   explanations=explanations, readings=effect, states=on, eps=eps,
                   vertices=vertices, standing=standing, judged_on=judged_on)


def _whole_on_part(batch: States, part: partial.Part, whole: ModelTree,
                   held: ModelTree) -> readings.Reading | None:
    """The referee on a whole engine's reading (``whole``, canonical layout) of the joints
    the partial engine holds (``held``), at the part's coordinates."""
    kept = partial.common_part(whole, held)
    return part_reading(batch, part, kept.tree) if kept is not None else None


def _effect(a: str, b: str, *, first: readings.Reading, second: readings.Reading,
            batch: States, part: partial.Part,
            differing: Mapping[str, list[str]]) -> dict[str, Prediction]:
    """Quantity → the measured effect on the part of a's and b's readings differing (the
    referee on b's reading of the part, ``second``, minus on a's, ``first``), each differing
    field's share by substitution."""
    groups = list(dict.fromkeys(f for e in (a, b) for f in differing.get(e, ())))
    if not groups:
        return {}
    found = readings.effect(part.tree, a, first.tree, first.dynamics, b, second.tree,
                            second.dynamics, batch, groups)
    return {q: p for q in QUANTITIES if (p := found.prediction(q)) is not None}
