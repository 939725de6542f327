"""The actuators' readings compared, field by field, in the neutral form of
:mod:`dyncheck.adapters.actuators`: does each engine read the file's actuators as the
canonical engine does, each difference with the engine's known cause where its premise holds
(its tree's hint) or "cause unknown"."""

from __future__ import annotations

import numpy as np

from dyncheck.adapters.actuators import Activation, Actuator
from dyncheck.adapters.model_tree import ModelTree
from dyncheck.check.proofs import Remeasured, proved, unmeasured
from dyncheck.check.rows import CheckRow, Section
from dyncheck.labels import NO_ACTUATORS_READ
from dyncheck.precision import ROUNDOFF_FACTOR
from dyncheck.vocabulary import Verdict

FIELD_RTOL = 1e-9
"""Two readings of a field agree to this, relative (the file's digits, parsed twice)."""
UNKNOWN = "cause unknown"


def section_row(model: str, *, subject: str, field: str, a: str, b: str, verdict: Verdict,
         note: str, value_a: str = "", value_b: str = "", error: float = 0.0,
         tolerance: float = 0.0, basis: str = "", worst: int = -1,
         convention: str = "") -> CheckRow:
    return CheckRow(model=model, section=Section.ACTUATION, subject=subject, field=field,
                    impl_a=a, impl_b=b, value_a=value_a, value_b=value_b, error=error,
                    tolerance=tolerance, basis=basis, verdict=verdict, note=note,
                    convention=convention, worst_state=worst)


def motor_like(actuator: Actuator) -> bool:
    """A fixed gain and no bias or activation: its force is gain × control, so its bounds
    act as one interval of force (:func:`limits`)."""
    return actuator.gain[1:] == (0.0, 0.0) and actuator.bias == (0.0, 0.0, 0.0) and \
        actuator.activation is Activation.NONE


def _interval(low: float, high: float, *bounds: tuple[float, float] | None) -> object:
    """[low, high] ∩ each bound; None where nothing bounds it."""
    for bound in bounds:
        if bound is not None:
            low, high = max(low, bound[0]), min(high, bound[1])
    return None if not (np.isfinite(low) or np.isfinite(high)) else (float(low), float(high))


def limits(actuator: Actuator) -> object:
    """A motor-like actuator's bounds as they act (:func:`motor_like`): the force interval
    the ranges leave, gain × control range ∩ force range ∩ the joint's range."""
    low, high = -np.inf, np.inf
    if actuator.ctrl_range is not None:
        ends = sorted(actuator.gain[0] * np.array(actuator.ctrl_range))
        low, high = ends[0], ends[1]
    return _interval(low, high, actuator.force_range, actuator.joint_range)


def force_bound(actuator: Actuator) -> object:
    """The force the actuator may apply to its joint: gear × its force range ∩ its joint's
    (the sum's) range; None where unbounded."""
    low, high = -np.inf, np.inf
    if actuator.force_range is not None:
        ends = sorted(actuator.gear * np.array(actuator.force_range))
        low, high = ends[0], ends[1]
    return _interval(low, high, actuator.joint_range)


def shown_value(value: object) -> str:
    """A field's value as a row shows it."""
    if value is None:
        return "unlimited"
    if isinstance(value, tuple):
        return "(" + ", ".join(shown_value(x) for x in value) + ")"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def same(a: object, b: object, *, rtol: float) -> bool:
    """Whether two field values agree to ``rtol`` of their size (exactly for a name)."""
    if a is None or b is None or isinstance(a, str) or isinstance(b, str):
        return a == b
    if isinstance(a, tuple) and isinstance(b, tuple) and any(
            x is None or isinstance(x, tuple) for x in (*a, *b)):  # ranges of ranges
        return len(a) == len(b) and all(same(x, y, rtol=rtol) for x, y in zip(a, b, strict=True))
    x, y = np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))
    scale = max(float(np.abs(x).max(initial=0.0)), float(np.abs(y).max(initial=0.0)), 1e-300)
    finite = np.isfinite(x) & np.isfinite(y)
    return bool(x.shape == y.shape and np.array_equal(np.isfinite(x), np.isfinite(y))
                and np.all(np.abs(x - y)[finite] <= rtol * scale)
                and np.array_equal(x[~finite], y[~finite]))


def compared_fields(actuator: Actuator, *, motor: bool) -> dict[str, object]:
    """The fields two readings compare: gear, gain, bias, the bounds (a motor-like
    actuator's as they act; another's control range and the force it may apply), the
    activation. ``motor``: whether the canonical reading's is motor-like
    (:func:`motor_like`): both readings' bounds are compared as it decides."""
    bounds: dict[str, object] = {"limits": limits(actuator)} if motor else {
        "control range": actuator.ctrl_range, "force range": force_bound(actuator)}
    return {"gear": actuator.gear, "gain": actuator.gain, "bias": actuator.bias, **bounds,
            "activation": actuator.activation.value, "time constant": actuator.time_constant}


def match(mine: tuple[Actuator, ...], theirs: tuple[Actuator, ...]) -> dict[int, int]:
    """My actuator's place → theirs: by joint where every joint has at most one actuator on
    both sides (engines name unnamed actuators their own way), else by name."""
    def by_joint(acts: tuple[Actuator, ...]) -> dict[str, int]:
        joints = [a.joint for a in acts if a.joint]
        return {a.joint: k for k, a in enumerate(acts) if a.joint} \
            if len(joints) == len(set(joints)) else {}
    a, b = by_joint(mine), by_joint(theirs)
    if a and b and len(a) == len([x for x in mine if x.joint]):
        return {k: b[j] for j, k in a.items() if j in b}
    names = {x.name: k for k, x in enumerate(theirs)}
    return {k: names[x.name] for k, x in enumerate(mine) if x.name in names}


def _hint(tree: ModelTree, actuator: str, field: str) -> str:
    """Why ``tree``'s engine holds ``actuator`` (or none) otherwise, where it proved it."""
    return unmeasured(tree, actuator, field) or UNKNOWN


def _absent_cause(other: ModelTree, mine: Actuator) -> str:
    """Why ``other`` holds no actuator matching the canonical engine's ``mine``, proved by
    its fix where it has one: the fixed reading holds one on the same joint (by name where
    ``mine`` drives no joint)."""
    def measure(tree: ModelTree) -> Remeasured:
        held = any(x.joint == mine.joint if mine.joint else x.name == mine.name
                   for x in tree.actuators)
        where = f"on {mine.joint!r}" if mine.joint else f"named {mine.name!r}"
        return Remeasured(closed=held, left=0.0 if held else 1.0,
                          outcome=f"holds an actuator {where}" if held
                          else f"still holds no actuator {where}")
    return proved(other, "model", "actuator", measure=measure) or UNKNOWN


def _field_cause(other: ModelTree, actuator: str, field: str, *, expected: object,
                 canonical: str, motor: bool) -> str:
    """Why ``other`` reads ``field`` of ``actuator`` otherwise than ``expected`` (the
    canonical engine's value), proved by its fix where it has one: the field of the fixed
    reading's actuator against ``expected``."""
    def measure(tree: ModelTree) -> Remeasured:
        fixed = next((x for x in tree.actuators if x.name == actuator), None)
        if fixed is None:
            return Remeasured(closed=False, left=1.0, outcome=f"holds no {actuator!r}")
        value = compared_fields(fixed, motor=motor)[field]  # (measured by the engine's
        # arithmetic where the fix is a counterfactual on it: to its round-off)
        closed = same(expected, value, rtol=max(FIELD_RTOL, ROUNDOFF_FACTOR * tree.eps))
        return Remeasured(closed=closed, left=0.0 if closed else 1.0, outcome=(
            f"reads the {field} of {actuator!r} as {canonical} does ({shown_value(value)})"
            if closed else f"reads the {field} of {actuator!r} as {shown_value(value)}"))
    return proved(other, actuator, field, measure=measure) or UNKNOWN


def reading_rows(model: str, canonical: ModelTree, other: ModelTree) -> list[CheckRow]:
    """Each actuator of ``other`` against the canonical reading: one passed row where every
    field agrees, else a failed row per differing field with the engine's known reason
    (its hint, premise checked) or "cause unknown"; an actuator one side lacks, a row — but
    none for one outside the neutral form (a tendon's, a muscle's: MuJoCo-only, named once
    in the section's note), and where the canonical engine holds none at all, one row:
    explained where its reason is known (MuJoCo's URDF compiler makes no actuator: the
    format gives it none to read)."""
    a, b = canonical.engine, other.engine
    why = unmeasured(canonical, "model", "actuator")
    if not canonical.actuators and other.actuators:  # once, not once per actuator
        known = canonical.hint("model", "actuator") in canonical.measured
        return [section_row(model, subject="model", field="actuators", a=a, b=b, value_a="none",
                     value_b=f"{len(other.actuators)} ({other.actuators[0].what}, …)",
                     verdict=Verdict.EXPLAINED if known else Verdict.FAILED,
                     note=why or UNKNOWN, convention=NO_ACTUATORS_READ if known else "")]
    pairs = match(canonical.actuators, other.actuators)
    rows = []
    for k, mine in enumerate(canonical.actuators):
        if not mine.modelled:  # MuJoCo-only (a tendon's, a muscle's): stated once per model
            continue
        if k not in pairs:
            rows.append(section_row(model, subject=mine.name, field="actuator", a=a, b=b,
                             value_a=mine.what, value_b="absent", verdict=Verdict.FAILED,
                             note=_absent_cause(other, mine)))
            continue
        theirs = other.actuators[pairs[k]]
        motor = motor_like(mine)
        ours, found = compared_fields(mine, motor=motor), compared_fields(theirs, motor=motor)
        differ = [f for f in ours if not same(ours[f], found[f], rtol=FIELD_RTOL)]
        if not differ:
            rows.append(section_row(model, subject=mine.name, field="reading", a=a, b=b,
                             value_a=mine.what, value_b=theirs.what, verdict=Verdict.PASSED,
                             note=f"gear, gain, bias, bounds and activation alike ({b}'s "
                                  f"{theirs.what})"))
        for f in differ:
            rows.append(section_row(model, subject=mine.name, field=f, a=a, b=b,
                             value_a=shown_value(ours[f]), value_b=shown_value(found[f]),
                             verdict=Verdict.FAILED,
                             note=_field_cause(other, theirs.name, f, expected=ours[f],
                                               canonical=a, motor=motor)))
    held = set(pairs.values())
    for k, theirs in enumerate(other.actuators):
        if k not in held and theirs.modelled:
            rows.append(section_row(model, subject=theirs.name, field="actuator", a=a, b=b,
                             value_a="absent", value_b=theirs.what, verdict=Verdict.FAILED,
                             note=why or _hint(other, theirs.name, "actuator")))
    return rows
