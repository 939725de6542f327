"""Differences between two engines' dynamics predicted from what an engine declares it does
(:class:`~dyncheck.adapters.model_tree.TreeJoint`'s ``rotor_in_kinetic`` and
``gravity_frame``): a row whose difference matches the prediction is ``explained`` by it,
anything beyond stays ``failed``."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dyncheck.adapters.layout import engine_states
from dyncheck.adapters.model_tree import (
    Canonical,
    Dynamics,
    GravityFrame,
    JointType,
    ModelTree,
    reversed_rpy,
)
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.check.dynamics import Prediction, values
from dyncheck.labels import ARMATURE_AXES, BASE_GRAVITY, COMPUTED_INERTIA, READING, ROTOR_ENERGY
from dyncheck.referee.computed import canonical_armature, computed_inertia_effect
from dyncheck.referee.states import States
from dyncheck.referee.tree import ReferenceModel
from dyncheck.vocabulary import Quantity

PREDICTIONS = (ROTOR_ENERGY, BASE_GRAVITY, ARMATURE_AXES, READING, COMPUTED_INERTIA)
"""Every label a check's prediction carries (each registered in ``EXPLANATIONS``)."""


def differences(canon: Canonical, canonical_tree: ModelTree, tree_a: ModelTree,
                tree_b: ModelTree, states: States, dyn_a: Dynamics) -> dict[str, Prediction]:
    """Quantity → the predicted difference b − a, for the pair (a, b)."""
    out: dict[str, Prediction] = {}
    rotor = rotor_energy(canon, canonical_tree, tree_a, tree_b, states.v)
    if rotor is not None:
        out[Quantity.KINETIC_ENERGY] = rotor
    for tree, sign in ((tree_b, 1.0), (tree_a, -1.0)):
        out |= base_gravity(canon, canonical_tree, tree, states, dyn_a, sign)
    armature = armature_axes(canon, tree_a, tree_b, states, dyn_a)
    for tree, sign in ((tree_b, 1.0), (tree_a, -1.0)):
        armature = _added(armature, inertia_computed(canon, tree, states, sign))
    for quantity, prediction in armature.items():
        mine = out.get(quantity)
        if mine is not None and mine.size.ndim == prediction.size.ndim:  # both act: they add
            out[quantity] = replace(mine, size=mine.size + prediction.size,
                                    note=f"{mine.note}; and {prediction.note}")
        elif mine is None:
            out[quantity] = prediction
    return out


def _armature_terms(canon: Canonical, tree: ModelTree,
                    states: States) -> tuple[np.ndarray, np.ndarray] | None:
    """ΔM = Tᵀ A_e T − A and Δh = Tᵀ A_e Ṫ v per state, where ``tree``'s engine adds the
    armature A_e in its own velocity coordinates v_e = T v (:mod:`dyncheck.adapters.layout`):
    its τ_e holds A_e v̇_e = A_e (T v̇ + Ṫ v), which the canonical equations (A v̇, A the
    armature on the canonical velocities) read as Tᵀ A_e T v̇ + Tᵀ A_e Ṫ v. None where that
    is the canonical armature (T constant and A_e = A: a hinge, a slide, a world-axes free
    joint)."""
    if not any(any(j.armature) for j in tree.joints):
        return None
    a_e = np.zeros(tree.nv)
    a_c = np.zeros(canon.nv)
    for k, name in enumerate(canon.names):
        joint = tree.joint(name)
        arm = np.asarray(joint.armature, float)
        a_e[joint.layout.v_start : joint.layout.v_start + len(arm)] = arm
        a_c[canon.v_start[k] : canon.v_start[k] + len(arm)] = canonical_armature(joint)
    maps, _, _, _ = engine_states(canon, tree, states.q, states.v, states.a)
    t = np.array([m.t for m in maps])
    tdot_v = np.array([m.tdot_v for m in maps])
    mass = np.einsum("nki,k,nkj->nij", t, a_e, t) - np.diag(a_c)
    bias = np.einsum("nki,k,nk->ni", t, a_e, tdot_v)
    if not (np.abs(mass).max() > 0 or np.abs(bias).max() > 0):
        return None
    return mass, bias


def armature_axes(canon: Canonical, tree_a: ModelTree, tree_b: ModelTree, states: States,
                  dyn_a: Dynamics) -> dict[str, Prediction]:
    """The dynamics' predicted difference b − a where an engine adds the armature in its own
    velocity coordinates (:func:`_armature_terms`): M by ΔM, h by Δh, inverse dynamics by
    ΔM v̇ + Δh, forward dynamics −(M + ΔM)⁻¹ (h + Δh) against a's, the kinetic energy by
    ½ vᵀ ΔM v where the engine counts its rotors."""
    terms = {t.engine: (_armature_terms(canon, t, states), sign)
             for t, sign in ((tree_a, -1.0), (tree_b, 1.0))}
    found = [(x, sign, name) for name, (x, sign) in terms.items() if x is not None]
    if not found:
        return {}
    d_mass = np.zeros_like(found[0][0][0])
    d_bias = np.zeros_like(found[0][0][1])
    for x, sign, _ in found:
        d_mass += sign * x[0]
        d_bias += sign * x[1]
    n = len(states.q)
    with np.errstate(all="ignore"):
        forward = -np.linalg.solve(dyn_a.mass_matrix + d_mass,
                                   (dyn_a.bias + d_bias)[..., None])[..., 0] - dyn_a.forward
    kinetic = np.zeros(n)
    for x, sign, name in found:
        tree = tree_a if name == tree_a.engine else tree_b
        if all(j.rotor_in_kinetic for j in tree.joints):
            kinetic += sign * 0.5 * np.einsum("ni,nij,nj->n", states.v, x[0], states.v)
    names = " and ".join(name for _, _, name in found)
    size = float(np.abs(d_bias).max())
    note = (f"{names} adds the armature in its own velocity coordinates (a free joint's linear "
            "velocity in body axes), where MuJoCo adds it on the canonical ones: predicted per "
            f"state as ΔM = Tᵀ A T − A, Δh = Tᵀ A Ṫ v (largest |Δh| {size:.3g})")
    out = {Quantity.MASS_MATRIX: Prediction(size=d_mass.reshape(n, -1), note=note,
                                            label=ARMATURE_AXES),
           Quantity.BIAS_FORCES: Prediction(size=d_bias, note=note, label=ARMATURE_AXES),
           Quantity.INVERSE_DYNAMICS: Prediction(
               size=np.einsum("nij,nj->ni", d_mass, states.a) + d_bias, note=note,
               label=ARMATURE_AXES),
           Quantity.FORWARD_DYNAMICS: Prediction(size=forward, note=note, label=ARMATURE_AXES)}
    if np.any(kinetic):
        out[Quantity.KINETIC_ENERGY] = Prediction(size=kinetic[:, None], note=note,
                                                  label=ARMATURE_AXES)
    return {q: p for q, p in out.items() if np.any(p.size)}


def rotor_energy(canon: Canonical, canonical_tree: ModelTree, tree_a: ModelTree,
                 tree_b: ModelTree, v: np.ndarray) -> Prediction | None:
    """The kinetic energies' predicted difference where one engine counts a joint's rotor
    energy ½ aᵢ vᵢ² and the other does not (both hold the armature in M): ½ Σ aᵢ vᵢ² over
    those joints, aᵢ as the canonical engine read it — the difference b − a itself per state
    (n, 1), signed (b leaves it out: −), so that it adds to another prediction of the pair
    (the readings' measured effect, :func:`~.dynamics._candidates`)."""
    names = [n for n in canon.names
             if tree_a.joint(n).rotor_in_kinetic != tree_b.joint(n).rotor_in_kinetic
             and any(canonical_tree.joint(n).armature)]
    if not names:
        return None
    weights = np.zeros(canon.nv)
    for n in names:
        k = canon.names.index(n)
        armature = canonical_tree.joint(n).armature
        sign = 1.0 if tree_b.joint(n).rotor_in_kinetic else -1.0
        weights[canon.v_start[k] : canon.v_start[k] + len(armature)] = sign * np.asarray(
            armature)
    without = [t.engine for t in (tree_a, tree_b)
               if not all(t.joint(n).rotor_in_kinetic for n in names)]
    return Prediction(
        size=0.5 * np.einsum("i,ni,ni->n", weights, v, v)[:, None],
        note=f"{' and '.join(without)}'s kinetic energy leaves out the rotor energy "
        f"½ Σ aᵢ vᵢ² of {', '.join(names)}, which its M holds (predicted per state from the "
        "armature)",
        label=ROTOR_ENERGY,
    )


def base_gravity(canon: Canonical, canonical_tree: ModelTree, tree: ModelTree,
                 states: States, dyn_a: Dynamics, sign: float) -> dict[str, Prediction]:
    """Where ``tree``'s engine resolves gravity in a free body's frame through another
    rotation R′ than the state's R (:class:`GravityFrame`): its h and inverse dynamics are
    those of the gravity g′ = R R′ᵀ g, so they differ by G(g′) − G(g), G(g) the generalized
    gravity force — linear in g, so G(g′ − g) = Σₖ (g′ − g)ₖ G(eₖ), with G(eₖ) from the
    referee (h at v = 0 under unit gravity eₖ) —, and its forward dynamics by −M⁻¹ that
    (the vectors per state, ``sign``: +1 where the engine is the pair's second)."""
    frees = [(k, j) for k, j in enumerate(tree.joint(n) for n in canon.names)
             if j.type is JointType.FREE and j.gravity_frame is GravityFrame.RPY_REVERSED]
    if not frees:
        return {}
    gravity = np.asarray(canonical_tree.gravity, float)
    zero = np.zeros_like(states.v)
    unit = [ReferenceModel(replace(canonical_tree, gravity=e)).dynamics(states.q, zero, zero).bias
            for e in np.eye(3)]
    delta = np.zeros_like(states.v)
    for k, joint in frees:
        qs = canon.q_start[k]
        rotation = quat_to_matrix(states.q[:, qs + 3 : qs + 7]) @ joint.layout.offset[:3, :3]
        for i, r in enumerate(rotation):
            shift = r @ reversed_rpy(r).T @ gravity - gravity
            delta[i] += sum(shift[c] * unit[c][i] for c in range(3))
    delta *= sign
    forward = -np.linalg.solve(dyn_a.mass_matrix, delta[..., None])[..., 0]
    note = (f"{tree.engine} resolves gravity in the frame of {', '.join(j.name for _, j in frees)} "
            "through Rx(r) Ry(p) Rz(y) of the orientation's roll, pitch, yaw — the state's "
            "Rz(y) Ry(p) Rx(r) composed in reverse order (measured): predicted per state as "
            "G(g′) − G(g), g′ = R R′ᵀ g")
    return {Quantity.BIAS_FORCES: Prediction(size=delta, note=note, label=BASE_GRAVITY),
            Quantity.INVERSE_DYNAMICS: Prediction(size=delta, note=note, label=BASE_GRAVITY),
            Quantity.FORWARD_DYNAMICS: Prediction(size=forward, note=note, label=BASE_GRAVITY)}


def _added(mine: dict[str, Prediction], more: dict[str, Prediction]) -> dict[str, Prediction]:
    """Two sets of predictions of the same pair, summed where both act."""
    out = dict(mine)
    for quantity, prediction in more.items():
        had = out.get(quantity)
        out[quantity] = prediction if had is None else replace(
            had, size=had.size + prediction.size, note=f"{had.note}; and {prediction.note}")
    return out


def inertia_computed(canon: Canonical, tree: ModelTree, states: States,
                     sign: float) -> dict[str, Prediction]:
    """Where ``tree``'s engine computes with another inertia than it holds: every quantity's
    predicted difference per state (:func:`computed_inertia_effect`; ``sign`` +1 where the
    engine is the pair's second)."""
    found = computed_inertia_effect(canon, tree, q=states.q, v=states.v, a=states.a)
    if found is None:
        return {}
    before, after = found
    named = ", ".join(repr(j.name) for j in tree.joints if j.computed_inertia is not None)
    note = (f"{tree.engine}'s dynamics take the inertia of {named} otherwise than it holds "
            "it (its link's principal moments in the link's axes, the inertial frame's "
            "rotation dropped; measured): predicted per state by the general method on the "
            "inertia it computes with")
    return {quantity: Prediction(size=sign * (values(after, quantity) - values(before, quantity)),
                                 note=note, label=COMPUTED_INERTIA)
            for quantity in (Quantity.MASS_MATRIX, Quantity.BIAS_FORCES,
                             Quantity.FORWARD_DYNAMICS, Quantity.INVERSE_DYNAMICS,
                             Quantity.KINETIC_ENERGY)}
