"""The controls in a model check: does each engine read the file's actuators as the canonical
engine does (field by field: :mod:`dyncheck.check.actuator_readings`), and does the same
control make the same generalized force — each engine against the referee's
actuator law on that engine's own reading (:mod:`dyncheck.reference.actuation`: does it
compute what it read), and against the canonical engine (do they read it alike, measured).

The controls are sampled per actuator over 1.5 times its control range about its centre (a
third of them outside it: clamped), or, where the control is unlimited and the force is not,
over 1.5 times the control that reaches the force bound (saturated); else in [−1, 1].
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from dyncheck.adapters import layout
from dyncheck.adapters.actuators import EULER_DAMPING, Activation, Actuator
from dyncheck.adapters.base import ModelEngine, Offer
from dyncheck.adapters.model_tree import Canonical, Dynamics, ModelTree
from dyncheck.check.actuator_readings import UNKNOWN, match, reading_rows
from dyncheck.check.actuator_readings import section_row as _row
from dyncheck.check.dynamics import QUANTITIES
from dyncheck.check.engines import REFEREE
from dyncheck.check.rows import COMPUTED, CheckRow
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.referee.computed import depth
from dyncheck.referee.states import States, condition
from dyncheck.reference import actuation as law
from dyncheck.vocabulary import Quantity, Verdict

FORCE = "actuator force"
DYNAMICS = {Activation.NONE: law.NONE, Activation.INTEGRATOR: law.INTEGRATOR,
            Activation.FILTER: law.FILTER, Activation.FILTER_EXACT: law.FILTER_EXACT}


def joint_actuators(tree: ModelTree) -> law.JointActuators | None:
    """The referee's law of a tree's actuators in its own layout; None where one is outside
    the neutral form (a tendon's, a muscle's: MuJoCo-only)."""
    if not all(a.modelled for a in tree.actuators):
        return None
    acts = tree.actuators

    def bounds(ranges: list[tuple[float, float] | None]) -> tuple[np.ndarray, np.ndarray]:
        return (np.array([r[0] if r else -np.inf for r in ranges]),
                np.array([r[1] if r else np.inf for r in ranges]))
    ctrl, force, act, joint = (bounds([getattr(a, f) for a in acts])
                               for f in ("ctrl_range", "force_range", "act_range", "joint_range"))
    return law.JointActuators(
        dof=np.array([tree.joint(a.joint).layout.v_start for a in acts], int),
        q_index=np.array([tree.joint(a.joint).layout.q_start for a in acts], int),
        gear=np.array([a.gear for a in acts]), gain=np.array([a.gain for a in acts]),
        bias=np.array([a.bias for a in acts]), ctrl_low=ctrl[0], ctrl_high=ctrl[1],
        force_low=force[0], force_high=force[1],
        dynamics=np.array([DYNAMICS[a.activation] for a in acts], int),
        time_constant=np.array([a.time_constant for a in acts]),
        act_low=act[0], act_high=act[1], joint_low=joint[0], joint_high=joint[1])


def sample_controls(actuators: tuple[Actuator, ...], n: int, seed: int, *,
                    spread: float = 1.5) -> np.ndarray:
    """Controls (n, nu), see the module's docstring (``spread``: the interval's half-width
    over the range's)."""
    rng = np.random.default_rng(seed + 7919)
    out = np.zeros((n, len(actuators)))
    for k, a in enumerate(actuators):
        centre, half = 0.0, 1.0
        if a.ctrl_range is not None:
            centre, half = sum(a.ctrl_range) / 2, max((a.ctrl_range[1] - a.ctrl_range[0]) / 2,
                                                      1e-12)
        elif a.force_range is not None and a.gain[0] != 0.0:
            half = max(abs(a.force_range[0]), abs(a.force_range[1])) / abs(a.gain[0])
        out[:, k] = centre + half * rng.uniform(-spread, spread, n)
    return out


@dataclass(frozen=True, kw_only=True)
class Forces:
    """One engine's answer at the sampled controls: its actuator force (its layout), the
    controls in its actuators' order, and the states in its layout."""

    tau: np.ndarray
    controls: np.ndarray
    q: np.ndarray
    v: np.ndarray
    maps: list
    floor: float = 0.0
    """The size the engine's round-off is relative to beyond the force's own (its
    :attr:`~dyncheck.adapters.actuators.Actuation.floor`)."""
    joint_tau: np.ndarray | None = None
    """Its joint actuators' force alone, where it holds others (its
    :attr:`~dyncheck.adapters.actuators.Actuation.joint_tau`)."""


def controls_for(canonical: ModelTree, tree: ModelTree, u: np.ndarray) -> np.ndarray:
    """The canonical controls in ``tree``'s actuators' order (0 where it holds an actuator
    the canonical reading has not)."""
    out = np.zeros((len(u), len(tree.actuators)))
    for k, j in match(canonical.actuators, tree.actuators).items():
        out[:, j] = u[:, k]
    return out


def force_rows(model: str, *, canon: Canonical, canonical: ModelTree, batch: States,
               loaded: dict[str, ModelEngine], u: np.ndarray,
               differing: dict[str, list[str]], smooth: dict[str, Dynamics] | None = None,
               own: dict[str, Dynamics] | None = None) -> list[CheckRow]:
    """Every actuated engine's force at the sampled states and controls: against the
    referee's law on its own reading, and against the canonical engine (on the velocity
    coordinates of the joints both hold); and what that force adds to its forward dynamics
    (its ``smooth`` dynamics at τ = 0, canonical layout) against the referee's M⁻¹ τ on its
    ``own`` reading."""
    rows: list[CheckRow] = []
    found: dict[str, Forces] = {}
    for engine, m in loaded.items():
        if Offer.ACTUATION in m.offers and not m.tree.actuators:
            continue  # (its reading rows say it holds none)
        if Offer.ACTUATION not in m.offers:
            rows.append(_row(model, subject="model", field=FORCE, a=engine, b="",
                             verdict=Verdict.SKIPPED, note=_unsupported(m)))
            continue
        maps, q_e, v_e, _ = layout.engine_states(canon, m.tree, batch.q, batch.v,
                                                       batch.a)
        u_e = controls_for(canonical, m.tree, u)
        try:
            answer = m.actuation(q_e, v_e, u_e)
        except Exception as exc:  # a failing engine costs its own rows
            rows.append(_row(model, subject="model", field=FORCE, a=engine, b="",
                             verdict=Verdict.FAILED, note=f"{type(exc).__name__}: {exc}"))
            continue
        found[engine] = Forces(tau=answer.tau, controls=u_e, q=q_e, v=v_e, maps=maps,
                               floor=float(np.max(answer.floor, initial=0.0))
                               if answer.floor is not None else 0.0, joint_tau=answer.joint_tau)
        acts = joint_actuators(m.tree)
        if acts is None:
            others = ", ".join(a.what for a in m.tree.actuators if not a.modelled)
            rows.append(_row(model, subject=FORCE, field=COMPUTED, a=REFEREE, b=engine,
                             verdict=Verdict.SKIPPED, note=f"the referee models joint "
                             f"actuators only; {engine} holds {others}"))
            continue
        expected = law.generalized_force(acts, q_e, v_e, u_e, act=u_e)
        rows.append(_against_referee(model, m.tree, found[engine], acts=acts,
                                     expected=expected))
        if smooth and own and engine in smooth and engine in own:
            rows.append(_forward_row(model, m.tree, found[engine], forward=answer.forward,
                                     expected=expected, smooth=smooth[engine],
                                     own=own[engine]))
    names = list(found)
    for other in names[1:]:
        rows.append(_pair(model, tree_a=loaded[names[0]].tree, a=found[names[0]],
                          tree_b=loaded[other].tree, b=found[other], differing=differing))
    return rows


def _unsupported(m: ModelEngine) -> str:
    try:
        m.actuation(np.zeros((0, m.tree.nq)), np.zeros((0, m.tree.nv)), np.zeros((0, 0)))
    except Exception as exc:
        return str(exc)
    return f"{m.engine} offers no actuator force"


def _scale(acts: law.JointActuators, f: Forces) -> float:
    """The size round-off is relative to: the largest |g| (|gain · a| + |bias terms|)."""
    length = np.abs(acts.gear * f.q[:, acts.q_index])
    speed = np.abs(acts.gear * f.v[:, acts.dof])
    terms = (np.abs(acts.gain) @ np.ones(3)) * np.abs(f.controls) * (1 + length + speed) + \
        np.abs(acts.bias[:, 0]) + np.abs(acts.bias[:, 1]) * length + np.abs(acts.bias[:, 2]) * speed
    return max(float(np.max(np.abs(acts.gear) * terms, initial=0.0)), 1e-300)


def _against_referee(model: str, tree: ModelTree, f: Forces, *, acts: law.JointActuators,
                     expected: np.ndarray) -> CheckRow:
    """The engine's force against ``expected``, the referee's law (``acts``) on its
    reading."""
    engine = tree.engine
    scale = max(_scale(acts, f), f.floor)
    off = np.abs(f.tau - expected)
    tolerance = ROUNDOFF_FACTOR * max(EPS, tree.eps)
    worst = int(np.argmax(off.max(axis=1))) if off.size else -1
    error = float(off.max(initial=0.0)) / scale
    ok = error <= tolerance
    clamped = _clamped(acts, f)
    return _row(model, subject=FORCE, field=COMPUTED, a=REFEREE, b=engine,
                 verdict=Verdict.PASSED if ok else Verdict.FAILED, error=error,
                 tolerance=tolerance, worst=worst,
                 basis=f"the referee's actuator law on {engine}'s own reading; round-off "
                       f"{ROUNDOFF_FACTOR} eps of the largest term"
                       + (" (or of the net force it subtracted)" if f.floor else "")
                       + f"; {clamped}",
                 note="" if ok else f"{engine} computes a force its reading does not give "
                 f"(state {worst}: {off[worst].max():.3g}): {UNKNOWN}")


FORWARD = "forward dynamics with the control"
SINGULAR = ("not compared: M on {engine}'s reading is singular at a sampled state (a joint "
            "whose motion no mass resists, or two joints along one direction), so no forward "
            "dynamics are defined")


def _forward_row(model: str, tree: ModelTree, f: Forces, *, forward: np.ndarray,
                 expected: np.ndarray, smooth: Dynamics, own: Dynamics) -> CheckRow:
    """What the engine's control adds to its forward dynamics, v̇(u) − v̇(τ = 0) (both its
    own, in the canonical layout: accelerations map by T⁻¹, where v_e = T v), against the
    referee's M⁻¹ τ(u) on its own reading (``expected``: the referee's τ(u) in the engine's
    layout; forces map by Tᵀ). Round-off: the dynamics' bound, c ε × depth × κ(M), relative
    to the larger of the increment and v̇ itself."""
    t = np.array([s.t for s in f.maps])
    tdot_v = np.array([s.tdot_v for s in f.maps])
    with_u = np.linalg.solve(t, (forward - tdot_v)[..., None])[..., 0]
    tau = (np.swapaxes(t, 1, 2) @ expected[..., None])[..., 0]
    try:
        increment = np.linalg.solve(own.mass_matrix, tau[..., None])[..., 0]
    except np.linalg.LinAlgError:  # the model's own fault, which its dynamics row names
        return _row(model, subject=FORWARD, field=COMPUTED, a=REFEREE, b=tree.engine,
                    verdict=Verdict.SKIPPED, note=SINGULAR.format(engine=tree.engine))
    found = with_u - smooth.forward
    scale = max(float(np.abs(increment).max(initial=0.0)),
                float(np.abs(smooth.forward).max(initial=0.0)), 1e-300)
    kappa = condition(own.mass_matrix)
    tolerance = ROUNDOFF_FACTOR * max(EPS, tree.eps) * depth(tree) * kappa
    off = np.abs(found - increment)
    error = float(off.max(initial=0.0)) / scale
    worst = int(np.argmax(off.max(axis=1))) if off.size else -1
    ok = error <= tolerance
    engine = tree.engine
    return _row(model, subject=FORWARD, field=COMPUTED, a=REFEREE, b=engine,
                 verdict=Verdict.PASSED if ok else Verdict.FAILED, error=error,
                 tolerance=tolerance, worst=worst,
                 basis=f"{engine}'s v̇(u) − v̇(τ = 0) against the referee's M⁻¹ τ(u) on its "
                       f"own reading; round-off {ROUNDOFF_FACTOR} eps x tree depth "
                       f"{depth(tree)} x cond(M) {kappa:.3g}, of max(|M⁻¹ τ|, |v̇|)",
                 note="" if ok else f"{engine}'s forward dynamics do not take the force its "
                 f"actuators report (state {worst}): {UNKNOWN}")


def _clamped(acts: law.JointActuators, f: Forces) -> str:
    """How many sampled controls a bound held (what the rows exercised)."""
    u = f.controls
    ctrl = int(np.sum((u < acts.ctrl_low) | (u > acts.ctrl_high)))
    raw = law.scalar_forces(acts, f.q, f.v, u, act=u)
    force = int(np.sum(np.isclose(raw, acts.force_low) | np.isclose(raw, acts.force_high)))
    return (f"{ctrl} controls clamped to their range, {force} forces held at their bound, of "
            f"{u.size}")


ALONE = ("; the joint actuators' force alone (the actuators outside the neutral form, which "
         "one engine alone holds, left out)")


def _pair(model: str, *, tree_a: ModelTree, a: Forces, tree_b: ModelTree, b: Forces,
          differing: dict[str, list[str]]) -> CheckRow:
    """Two engines' forces on the hinges and slides both hold (by joint name): of their joint
    actuators alone where only one holds actuators outside the neutral form (a tendon's, a
    site's: named once in the section, never a difference of this row)."""
    cols_a, cols_b = [], []
    for joint in tree_a.joints:
        if joint.layout.nv == 1 and any(j.name == joint.name for j in tree_b.joints):
            cols_a.append(joint.layout.v_start)
            cols_b.append(tree_b.joint(joint.name).layout.v_start)
    both = not all(x.modelled for x in tree_a.actuators) and \
        not all(x.modelled for x in tree_b.actuators)
    tau_a = a.tau if both or a.joint_tau is None else a.joint_tau
    tau_b = b.tau if both or b.joint_tau is None else b.joint_tau
    alone = tau_a is not a.tau or tau_b is not b.tau
    off = np.abs(tau_a[:, cols_a] - tau_b[:, cols_b])
    scale = max(float(np.abs(tau_a).max(initial=0.0)), float(np.abs(tau_b).max(initial=0.0)),
                a.floor, b.floor, 1e-300)
    tolerance = ROUNDOFF_FACTOR * max(EPS, tree_a.eps, tree_b.eps)
    error = float(off.max(initial=0.0)) / scale
    ok = error <= tolerance
    read = differing.get(tree_b.engine, [])
    note = ""
    if not ok:
        note = (f"{tree_b.engine} reads the controls differently ({', '.join(read)}: the "
                "actuation reading rows); the force differs by that reading, measured here"
                if read else UNKNOWN)
    worst = int(np.argmax(off.max(axis=1))) if off.size else -1
    return _row(model, subject=FORCE, field=COMPUTED, a=tree_a.engine, b=tree_b.engine,
                verdict=Verdict.PASSED if ok else Verdict.FAILED, error=error,
                tolerance=tolerance, worst=worst, note=note,
                basis=f"the same controls as each reads them{ALONE if alone else ''}; round-off "
                      f"{ROUNDOFF_FACTOR} eps of the largest force")


def _derivative_rows(model: str, *, canon: Canonical, holding: ModelTree, batch: States,
                     loaded: dict[str, ModelEngine], inside: np.ndarray,
                     own: dict[str, Dynamics]) -> list[CheckRow]:
    """Every engine's own ∂v̇/∂u where it offers one, against the referee on its reading, at
    the first :data:`INPUT_STATES` states and controls ``inside`` their ranges (for
    ``holding``'s actuators)."""
    from dyncheck.check import input_jacobian

    out = []
    k = len(inside)
    for engine, m in loaded.items():
        acts = joint_actuators(m.tree)
        if Offer.CONTROL_DERIVATIVES not in m.offers or not m.tree.actuators or \
                acts is None or engine not in own:
            continue
        maps, q_e, v_e, _ = layout.engine_states(canon, m.tree, batch.q[:k],
                                                       batch.v[:k], batch.a[:k])
        u_e = controls_for(holding, m.tree, inside)
        try:
            found = m.control_derivatives(q_e, v_e, u_e)
        except Exception as exc:  # a failing engine costs its own rows
            out.append(_row(model, subject=input_jacobian.CONTROL_DERIVATIVE, field=COMPUTED,
                            a=REFEREE, b=engine, verdict=Verdict.FAILED,
                            note=f"{type(exc).__name__}: {exc}"))
            continue
        out.append(input_jacobian.derivative_row(
            model, tree=m.tree, acts=acts, maps=maps, q=q_e, v=v_e, u=u_e,
            mass=own[engine].mass_matrix[:k], found=found))
    return out


INPUT_STATES = 8
"""The states at which the step's Jacobian in the controls is compared (its differences cost
2 nu steps a state, twice)."""


PART = ("not compared: {engine} holds part of the model (the description rows say which "
        "joints), and a force on the joints it lacks has nowhere to act")
UNDEFINED = ("not compared: the model's dynamics are not defined as read (the referee's "
             "{fields} on {engine}'s reading are not finite: its dynamics row says why)")


def section(model: str, *, canon: Canonical, canonical: ModelTree, batch: States,
            loaded: dict[str, ModelEngine], seed: int, smooth: dict[str, Dynamics],
            parts: Mapping[str, object], own: dict[str, Dynamics]) -> tuple[
                list[CheckRow], list[str]]:
    """The actuation section (:func:`rows`) of the engines whose dynamics were computed
    (``smooth``) on the whole model; one skipped row for each that holds part of it, and one
    for the model where its dynamics are not defined as read (the referee's on the
    canonical reading not finite: a singular M)."""
    first = next(iter(loaded))
    bad = [f for f in (QUANTITIES[Quantity.MASS_MATRIX], QUANTITIES[Quantity.FORWARD_DYNAMICS])
           if first in own and not np.all(np.isfinite(getattr(own[first], f)))]
    if bad:
        return [_row(model, subject="model", field=FORCE, a=REFEREE, b="",
                     verdict=Verdict.SKIPPED, note=UNDEFINED.format(
                         fields=", ".join(bad), engine=first))], []
    whole = {e: m for e, m in loaded.items() if e in smooth and parts.get(e) is None}
    out = [_row(model, subject="model", field=FORCE, a=e, b="", verdict=Verdict.SKIPPED,
                note=PART.format(engine=e))
           for e in loaded if e in smooth and parts.get(e) is not None]
    if not whole:
        return out, []
    found, said = rows(model, canon=canon, canonical=canonical, batch=batch, loaded=whole,
                       seed=seed, smooth=smooth, own=own)
    return out + found, said


def rows(model: str, *, canon: Canonical, canonical: ModelTree, batch: States,
         loaded: dict[str, ModelEngine], seed: int, smooth: dict[str, Dynamics] | None = None,
         own: dict[str, Dynamics] | None = None) -> tuple[list[CheckRow], list[str]]:
    """The actuation section: every engine's reading of the actuators against the canonical
    one, every engine's force against the referee and the canonical engine, and every
    engine's own step Jacobian in the controls against the chain rule; and the notes
    that say what was left out."""

    own = own or {}
    out: list[CheckRow] = []
    notes: list[str] = []
    offering = [m for m in loaded.values() if Offer.ACTUATION in m.offers]
    holding = next((m.tree for m in loaded.values() if m.tree.actuators), None)
    if holding is None:  # (only an engine whose dynamics failed held them: its row says so)
        return out, notes
    unmodelled = [a.what for a in holding.actuators if not a.modelled]
    if unmodelled:
        notes.append(f"actuators outside the neutral form, compared by no other engine and "
                     f"not by the referee (MuJoCo-only): {', '.join(unmodelled)}")
    differing: dict[str, list[str]] = {}
    for m in offering[1:]:  # each reading against the first engine's that has actuators
        found = reading_rows(model, offering[0].tree, m.tree)
        out.extend(found)
        differing[m.engine] = sorted({r.field for r in found if r.verdict is Verdict.FAILED})
    if offering:
        notes.append(f"actuators: each engine's reading compared with {offering[0].engine}'s; "
                     f"controls sampled for {holding.engine}'s actuators (see "
                     "dyncheck/check/actuation.py), each engine's matched to them by joint")
    u = sample_controls(holding.actuators, len(batch.q), seed)
    out.extend(force_rows(model, canon=canon, canonical=holding, batch=batch, loaded=loaded,
                          u=u, differing=differing, smooth=smooth, own=own))
    k = min(INPUT_STATES, len(batch.q))
    inside = sample_controls(holding.actuators, k, seed, spread=0.8)
    out.extend(_derivative_rows(model, canon=canon, holding=holding, batch=batch,
                                loaded=loaded, inside=inside, own=own))
    out.extend(_input_jacobian_rows(model, canon=canon, holding=holding, batch=batch,
                                    loaded=loaded, inside=inside, own=own))
    return out, notes


def _input_jacobian_rows(model: str, *, canon: Canonical, holding: ModelTree, batch: States,
                         loaded: dict[str, ModelEngine], inside: np.ndarray,
                         own: dict[str, Dynamics]) -> list[CheckRow]:
    """Every engine's own step Jacobian in the controls where it offers one (MuJoCo's by
    finite differences, MJX's by JAX), against the chain rule through the referee on its
    reading (``own``) at the first :data:`INPUT_STATES` states, controls ``inside`` their
    ranges; compared in the canonical layout, which a MuJoCo-family engine's is."""
    from dyncheck.check import input_jacobian

    out = []
    k = len(inside)
    q, v = batch.q[:k], batch.v[:k]
    subject = "step Jacobian in the controls"
    for engine, m in loaded.items():
        acts = joint_actuators(m.tree)
        if Offer.INPUT_JACOBIAN not in m.offers or acts is None or not m.tree.actuators \
                or engine not in own:
            continue
        maps, q_e, _, _ = layout.engine_states(canon, m.tree, q, v, batch.a[:k])
        if not (np.array_equal(q_e, q) and all(np.array_equal(s.t, np.eye(len(s.t)))
                                               for s in maps)):
            out.append(_row(model, subject=subject, field=COMPUTED, a=REFEREE, b=engine,
                            verdict=Verdict.SKIPPED, note=f"not compared: {engine}'s "
                            "layout is not the canonical reading's, and dyncheck maps no "
                            "step Jacobian between charts"))
            continue
        mass, bias = own[engine].mass_matrix[:k], own[engine].bias[:k]
        if not (np.all(np.isfinite(mass)) and np.all(np.isfinite(bias))
                and np.all(np.linalg.eigvalsh(mass) > 0)):
            out.append(_row(model, subject=subject, field=COMPUTED, a=REFEREE, b=engine,
                            verdict=Verdict.SKIPPED, note="not compared: the referee's M is "
                            "not positive definite or h not finite on this reading (the "
                            "dynamics rows say why)"))
            continue
        u = controls_for(holding, m.tree, inside)
        try:
            jacobians = m.input_jacobians(q, v, u)
        except Exception as exc:  # a failing engine costs its own rows
            out.append(_row(model, subject=subject, field=COMPUTED, a=REFEREE, b=engine,
                            verdict=Verdict.FAILED, note=f"{type(exc).__name__}: {exc}"))
            continue
        damping = _damping(canon, m.tree) if m.tree.hint("model", EULER_DAMPING) else None
        out.extend(input_jacobian.rows(model, canon=canon, tree=m.tree, acts=acts, mass=mass,
                                       bias=bias, q=q, v=v, u=u, found=found, damping=damping)
                   for found in jacobians)
    return out


def _damping(canon: Canonical, tree: ModelTree) -> np.ndarray:
    """The joints' damping per degree of freedom, in the canonical layout."""
    out = np.zeros(canon.nv)
    for name, start in zip(canon.names, canon.v_start, strict=True):
        held = tree.joint(name).damping
        out[start:start + len(held)] = held
    return out
