"""The referee on each engine's own reading, and the effect of a reading difference measured.

Two questions per engine, each with its own rows: does it *read* the model as the canonical
engine does (the description rows, :mod:`dyncheck.check.describe`), and does it *compute what
it read* (its dynamics against the referee evaluated on the tree that engine read back, not on
the canonical engine's). Where two engines read the model differently, the effect of that on
the dynamics is measured, not inferred: the referee on one reading against the referee on the
other (M, h, forward and inverse dynamics, T, V: (2.2.23)–(2.2.24)), and its share per field
by substitution — one differing field group of the second reading put into the first tree,
the referee evaluated again, and how much of the difference goes recorded on the row.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.model_tree import Dynamics, ModelTree
from dyncheck.check import partial
from dyncheck.check.dynamics import QUANTITIES, Prediction, values
from dyncheck.check.placement import placement
from dyncheck.labels import READING
from dyncheck.referee.computed import bodies, canonical_armature, in_layout, parents_first
from dyncheck.referee.states import States
from dyncheck.referee.tree import TIE_STATES, ReferenceModel
from dyncheck.reference.recursive import RecursiveDynamics

SUBSTITUTED = ("axis", "anchor", "mass", "com", "inertia", "armature")
"""The joint fields a substitution moves one at a time (with ``gravity`` and ``placement``)."""


def own_tree(canonical_tree: ModelTree, tree: ModelTree) -> ModelTree | None:
    """``tree`` (an engine's reading, joints already matched by name) in the canonical
    engine's state layout and joint order, so that the referee evaluates it at the same
    canonical states — parents first where the engine chains a body's joints in another
    order (Newton's D6: the referee gathers the columns,
    :func:`~dyncheck.referee.computed.in_layout`); None where its joints are not the
    canonical ones (other names or types: that engine holds another tree, which the
    description rows report)."""
    names = [j.name for j in canonical_tree.joints]
    if sorted(j.name for j in tree.joints) != sorted(names):
        return None
    joints = []
    for name in names:
        mine, theirs = tree.joint(name), canonical_tree.joint(name)
        if mine.type is not theirs.type:
            return None
        joints.append(replace(mine, layout=theirs.layout, armature=canonical_armature(mine),
                              rotor_in_kinetic=True, gravity_frame=theirs.gravity_frame,
                              computed_inertia=None))
    return replace(tree, joints=parents_first(joints), nq=canonical_tree.nq,
                   nv=canonical_tree.nv)


def same_dynamics_fields(a: ModelTree, b: ModelTree) -> bool:
    """Whether two trees in the same order hold, bit for bit, every field the referee uses
    (then the referee's numbers on one are its numbers on the other)."""
    if not np.array_equal(a.gravity, b.gravity) or len(a.joints) != len(b.joints):
        return False
    return all(_body_equal(x, y) for x, y in zip(bodies(a), bodies(b), strict=True))


def _body_equal(x: object, y: object) -> bool:
    return all(np.array_equal(np.asarray(u), np.asarray(w))
               for u, w in zip(vars(x).values(), vars(y).values(), strict=True))


def _quick(tree: ModelTree, states: States) -> dict[str, np.ndarray]:
    """The referee's quantities on ``tree`` at ``states`` (the recursive algorithm: the
    substitutions' cheap evaluation; its tie to the general method is the page's row)."""
    mass, bias, kinetic, potential = in_layout(
        RecursiveDynamics(bodies(tree), tree.gravity), tree).at_states(states.q, states.v)
    with np.errstate(all="ignore"):
        try:
            forward = np.linalg.solve(mass, -bias[..., None])[..., 0]
        except np.linalg.LinAlgError:
            forward = np.full_like(bias, np.nan)
    dyn = Dynamics(mass_matrix=mass, bias=bias, forward=forward,
                   inverse=np.einsum("sij,sj->si", mass, states.a) + bias, kinetic=kinetic,
                   potential=potential)
    return {q: values(dyn, q) for q in QUANTITIES}


def _substituted(a: ModelTree, b: ModelTree, group: str) -> ModelTree:
    """``a`` with ``b``'s values of one field group (joints matched by name)."""
    if group == "gravity":
        return replace(a, gravity=b.gravity)
    if group == "mass":  # the body's mass with its centre and inertia kept
        return replace(a, joints=tuple(replace(x, mass=b.joint(x.name).mass)
                                       for x in a.joints))
    return replace(a, joints=tuple(replace(x, **{group: getattr(b.joint(x.name), group)})
                                   for x in a.joints))


@dataclass(frozen=True, kw_only=True)
class ReadingEffect:
    """What the readings of two engines change in the dynamics: the referee on ``b``'s
    reading minus on ``a``'s, per quantity (n, k), and the measured share of each field group
    per quantity (fraction of the difference's norm that goes when the group alone is
    substituted, at the first :data:`TIE_STATES` states)."""

    a: str
    b: str
    difference: dict[str, np.ndarray]
    shares: dict[str, dict[str, float]]

    def prediction(self, quantity: str) -> Prediction | None:
        diff = self.difference.get(quantity)
        if diff is None or not np.any(diff):
            return None
        share = self.shares.get(quantity, {})
        named = ", ".join(f"{g} {s:.0%}" for g, s in sorted(share.items(),
                                                             key=lambda kv: -kv[1]))
        return Prediction(
            size=diff,
            note=(f"{self.a} and {self.b} read the model differently: the referee on "
                  f"{self.b}'s reading minus on {self.a}'s accounts for the difference (measured"
                  + (f"; by substitution, of the difference at {TIE_STATES} states: {named}"
                     if named else "; its share per field not measured") + ")"),
            label=READING)


def effect(canonical_tree: ModelTree, name_a: str, tree_a: ModelTree, dyn_a: Dynamics,
           name_b: str, tree_b: ModelTree, dyn_b: Dynamics, states: States,
           groups: list[str]) -> ReadingEffect:
    """The referee's difference between two readings (both in the canonical layout, their
    referee dynamics ``dyn_a``, ``dyn_b`` at ``states``) and each field group's share of it
    (``groups``: the fields read differently; a whole-model placement is undone first and its
    share is that of the placement)."""
    difference = {q: values(dyn_b, q) - values(dyn_a, q) for q in QUANTITIES}
    first = States(q=states.q[:TIE_STATES], v=states.v[:TIE_STATES], a=states.a[:TIE_STATES])
    length = max(float(np.abs(j.anchor).max(initial=0.0)) for j in canonical_tree.joints) or 1.0
    moved = placement(tree_a, tree_b, 1e-9 * length)
    reference = _quick(tree_a, first)
    target = _quick(tree_b, first)
    trials: dict[str, ModelTree] = {}
    if moved is not None:  # b's reading carried back into a's placement: what goes is its share
        trials["placement"] = replace(tree_b, joints=tuple(moved.undo(j) for j in tree_b.joints))
    else:
        trials = {g: _substituted(tree_a, tree_b, g) for g in groups
                  if g in SUBSTITUTED or g == "gravity"}
    shares: dict[str, dict[str, float]] = {}
    for group, tree in trials.items():
        with np.errstate(all="ignore"):
            after = _quick(tree, first)
        for quantity in QUANTITIES:
            norm = float(np.linalg.norm(target[quantity] - reference[quantity]))
            if not np.isfinite(norm) or norm == 0:
                continue
            left = (after[quantity] - reference[quantity] if group == "placement"
                    else target[quantity] - after[quantity])
            share = 1.0 - float(np.linalg.norm(left)) / norm
            if np.isfinite(share) and share > 0.005:
                shares.setdefault(quantity, {})[group] = min(share, 1.0)
    return ReadingEffect(a=name_a, b=name_b, difference=difference, shares=shares)


@dataclass(frozen=True, kw_only=True)
class Reading:
    """An engine's reading in the canonical layout (:func:`readings.own_tree`) and the
    referee's dynamics on it at the sampled states."""

    tree: ModelTree
    dynamics: Dynamics


def own_readings(canonical_tree: ModelTree, batch: States,
                  loaded: dict[str, ModelEngine],
                  parts: dict[str, partial.Part | None], referee: Dynamics,
                  own: dict[str, Reading]) -> None:
    """The referee on every engine's own reading (whole trees; the canonical engine's is the
    referee's own): computed anew wherever a field it uses differs, bit for bit, from the
    canonical reading."""
    first = next(iter(loaded))
    base = own_tree(canonical_tree, canonical_tree)
    assert base is not None
    own[first] = Reading(tree=base, dynamics=referee)
    for engine, m in loaded.items():
        if engine == first or parts.get(engine, 0) is not None:
            continue
        tree = own_tree(canonical_tree, m.tree)
        if tree is None:
            continue
        if same_dynamics_fields(tree, base):
            own[engine] = Reading(tree=tree, dynamics=referee)
            continue
        with np.errstate(all="ignore"):
            own[engine] = Reading(tree=tree, dynamics=ReferenceModel(tree).dynamics(
                batch.q, batch.v, batch.a))


def pair_effect(canonical_tree: ModelTree, a: str, b: str, own: dict[str, Reading],
                    batch: States, differing: dict[str, list[str]]) -> dict[str, Prediction]:
    """Quantity → the measured effect of a and b reading the model differently (the
    referee on b's reading minus on a's, with each differing field's share by substitution);
    empty where one of them holds no whole reading or they read every field alike."""
    groups = list(dict.fromkeys(f for e in (a, b) for f in differing.get(e, ())))
    if not groups or a not in own or b not in own or own[a].dynamics is own[b].dynamics:
        return {}
    found = effect(canonical_tree, a, own[a].tree, own[a].dynamics, b, own[b].tree,
                            own[b].dynamics, batch, groups)
    return {q: p for q in QUANTITIES if (p := found.prediction(q)) is not None}
