"""Drake's joint actuators: read back into the neutral form (:mod:`dyncheck.adapters.actuators`)
as they act, their generalized force and the forward dynamics at a control, and why they
differ from the file's where Drake is known to read them otherwise (each premise checked on
the plant or the file).

A Drake joint actuator's input is its joint's effort itself: τ = clamp(u, ±effort limit),
its gear ratio only scaling the rotor inertia it reflects (M's armature). One with PD gains
(what Drake's MJCF parser makes of ``<position>``) adds −kp (q − q_d) − kd (v − v_d) to its
input before the clamp, q_d and v_d from the plant's desired-state port. The control of the
file's actuator is mapped as the parser means it: a motor's control is Drake's input, a
position servo's control is its target q_d (v_d = 0, no feed-forward).
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any, TypeVar

import numpy as np

from dyncheck.adapters.actuators import Actuation, Actuator, Transmission
from dyncheck.adapters.drake.defaults import class_gain_hints
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.formats.mjcf_copy import class_defaults, placed
from dyncheck.adapters.model_tree import FixedReading, ModelTree, geared
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format

GEAR = (
    "Drake applies a joint actuator's input to its joint as it is: its gear ratio ({gear:g}, "
    "read from the file) scales only the rotor inertia it reflects, where MuJoCo "
    "multiplies the actuator's force by its gear (fix: scale the control by the gear in "
    "Drake, or write gear 1 and fold the gear into the gains and ranges)"
)
DAMPING = (
    "Drake's MJCF parser reads a <position> servo's damping from an attribute 'kd', which "
    "MJCF does not have, so the file's kv is lost (its PD gains hold d = {d:g}) (fix: after "
    "parsing, JointActuator.set_controller_gains(PdControllerGains(p=kp, d=kv)))"
)
EFFORT = (
    "Drake's MJCF parser makes one symmetric effort limit (here {limit:g}) of a <motor>'s or "
    "<position>'s ctrlrange and forcerange, ignoring a joint's actuatorfrcrange: on a "
    "position servo, whose ctrlrange bounds the target position, that bounds its torque "
    "(fix: set the effort limit after parsing, JointActuator.set_effort_limit, to the force "
    "bound the file states)"
)
CONTROL_RANGE = (
    "Drake's joint actuator holds no control range: a servo's target (its desired-state "
    "input) is not bounded, the file's ctrlrange going into its effort limit instead (fix: "
    "bound the target where it is set)"
)
PD_DROPPED = (
    "Drake's scalar conversion to AutoDiffXd (MultibodyPlant.ToAutoDiffXd) drops the PD "
    "gains of its joint actuators ({count} of {total} servos have none in the converted "
    "plant, measured), so its derivatives in a servo's target are 0 (fix: set the gains on "
    "the converted plant, JointActuator.set_controller_gains; dyncheck explain "
    "drake-autodiff-pd-gains)"
)
READ_TAGS = ("<motor>", "<position>")
"""The actuator elements Drake's MJCF parser reads (as ``<tag>`` in the file's list)."""
IGNORED = (
    "Drake's MJCF parser reads only <motor> and <position> actuators and ignores {tags} with "
    "a warning (fix: write them as <motor> or <position>, or add the actuator in Drake)"
)


def read(plant: Any) -> tuple[Actuator, ...]:
    """Every joint actuator of ``plant`` in the neutral form, as it acts (gear 1)."""
    out = []
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        limit = float(actuator.effort_limit())
        kp = kd = 0.0
        if actuator.has_controller():
            gains = actuator.get_controller_gains()
            kp, kd = float(gains.p), float(gains.d)
        servo = actuator.has_controller()
        out.append(Actuator(
            name=actuator.name(), joint=actuator.joint().name(),
            transmission=Transmission.JOINT if actuator.joint().num_velocities() == 1
            else Transmission.OTHER,
            gear=1.0, gain=(kp, 0.0, 0.0) if servo else (1.0, 0.0, 0.0),
            bias=(0.0, -kp, -kd) if servo else (0.0, 0.0, 0.0), ctrl_range=None,
            force_range=(-limit, limit) if np.isfinite(limit) else None,
            what=f"JointActuator {actuator.name()!r}"
            + (f" with PD gains p={kp:g}, d={kd:g}" if servo else "")
            + f", gear ratio {actuator.default_gear_ratio():g}"))
    return tuple(out)


def hints(plant: Any, source: ModelFile, tags: dict[str, list[str]]) -> tuple[
        tuple[tuple[str, str, str], ...], frozenset[str]]:
    """(actuator, field, why) for what Drake is known to read otherwise, each premise
    checked on the plant (``tags``: the file's actuator elements per joint); actuator
    ``model``: of the file's actuators Drake holds none of, and what its automatic
    differentiation drops; and the hints measured (:attr:`ModelTree.measured`: the
    converted plant's gains, the class defaults' fix verified on a copy)."""
    out, measured = [], []
    servos = [i for i in plant.GetJointActuatorIndices()
              if plant.get_joint_actuator(i).has_controller()]
    if servos:
        converted = plant.ToAutoDiffXd()
        dropped = sum(not converted.get_joint_actuator(i).has_controller() for i in servos)
        if dropped:
            measured.append(PD_DROPPED.format(count=dropped, total=len(servos)))
            out.append(("model", "control derivatives", measured[-1]))
    root = inline(source.path) if source.format is Format.MJCF else None
    stated_kv = root is not None and _states_kv(root)
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        name, gear = actuator.name(), float(actuator.default_gear_ratio())
        if gear != 1.0:
            out.append((name, "gear", GEAR.format(gear=gear)))
        if actuator.has_controller() and stated_kv:  # (its premise: a kv to lose, #77)
            out.append((name, "bias", DAMPING.format(d=actuator.get_controller_gains().d)))
        if source.format is Format.MJCF:
            servo = actuator.has_controller()
            out.append((name, "force range" if servo else "limits",
                        EFFORT.format(limit=actuator.effort_limit())))
            if servo:  # (a field its API does not hold: measured)
                measured.append(CONTROL_RANGE)
                out.append((name, "control range", CONTROL_RANGE))
    ignored = sorted({t.split(" ")[0] for found in tags.values() for t in found
                      if not t.startswith(READ_TAGS)})
    if ignored:
        out.append(("model", "actuator", IGNORED.format(tags=", ".join(ignored))))
    classes = class_gain_hints(plant, source, root) if root is not None else ()
    return (*out, *classes), frozenset((*measured, *(w for _, _, w in classes)))


T = TypeVar("T")


@functools.cache
def multi_dof_refusal() -> str:
    """Drake's own words refusing a ``JointActuator`` on a ball joint, measured on a plant
    built for it (one body on a ``BallRpyJoint``); empty where Drake takes one."""
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import BallRpyJoint, SpatialInertia

    plant = MultibodyPlant(0.0)
    body = plant.AddRigidBody("probe", SpatialInertia.SolidSphereWithMass(1.0, 0.1))
    ball = plant.AddJoint(BallRpyJoint("probe_ball", plant.world_frame(), body.body_frame()))
    try:
        plant.AddJointActuator("probe_actuator", ball)
    except RuntimeError as exc:
        words = " ".join(str(exc).split())
        return words.split(" -- ", 1)[-1].split(". ", 1)[0]
    return ""


def file_kv(root: ET.Element) -> dict[str, float]:
    """Each ``<position>``'s kv as MuJoCo's compiler gives it (``root``: the file, its
    includes inlined): its own, else its class's, else 0 (:func:`per_actuator`)."""
    return per_actuator(root, ("position",), ("kv",),
                        lambda attrs, _: float(attrs.get("kv") or 0.0))


def per_actuator(root: ET.Element, tags: Sequence[str], keys: Sequence[str],
                 value: Callable[[Mapping[str, str], ET.Element], T]) -> dict[str, T]:
    """``value`` of each actuator of ``tags`` in ``root`` (the file, its includes inlined),
    from its attributes ``keys`` as MuJoCo's compiler resolves them (its own, else its
    class's); by its name, and by its joint's (``joint NAME``) where the joint has no other
    (an unnamed actuator)."""
    classes = {tag: class_defaults(root, tag, tuple(keys)) for tag in tags}
    out: dict[str, T] = {}
    by_joint: dict[str, list[T]] = {}
    for block in root.findall("actuator"):
        for element in (e for e in block if e.tag in tags):
            attrs = {**classes[element.tag].get(element.get("class", "main"), {}),
                     **{k: v for k, v in element.attrib.items() if k in keys}}
            got = value(attrs, element)
            if element.get("name"):
                out[element.get("name", "")] = got
            if element.get("joint"):
                by_joint.setdefault(element.get("joint", ""), []).append(got)
    return {**{f"joint {j}": v[0] for j, v in by_joint.items() if len(v) == 1}, **out}


def damping_fixed(plant: Any, root: ET.Element, tree: ModelTree) -> tuple[FixedReading, ...]:
    """The fix :data:`DAMPING` names, measured: each servo whose damping Drake holds other
    than the file's kv given PdControllerGains(p = its kp, d = kv) after parsing, and the
    actuators read back (the plant's gains restored after)."""
    stated = file_kv(root)
    kv = {a.name(): stated.get(a.name(), stated.get(f"joint {a.joint().name()}"))
          for a in map(plant.get_joint_actuator, plant.GetJointActuatorIndices())}
    targets = [plant.get_joint_actuator(i) for i in plant.GetJointActuatorIndices()]
    targets = [a for a in targets if a.has_controller() and kv[a.name()] is not None
               and float(a.get_controller_gains().d) != kv[a.name()]]
    if not targets:
        return ()
    from pydrake.multibody.tree import PdControllerGains

    saved = [a.get_controller_gains() for a in targets]
    try:
        for a, gains in zip(targets, saved, strict=True):
            a.set_controller_gains(PdControllerGains(p=gains.p, d=kv[a.name()]))
        fixed = replace(tree, actuators=read(plant))
    finally:
        for a, gains in zip(targets, saved, strict=True):
            a.set_controller_gains(gains)
    return tuple(FixedReading(
        subject=a.name(), fields=("bias",), tree=fixed,
        fix=f"JointActuator.set_controller_gains(PdControllerGains(p={float(g.p):g}, "
            f"d={kv[a.name()]:g})) after parsing") for a, g in zip(targets, saved, strict=True))


def gear_fixed(plant: Any, tree: ModelTree) -> tuple[FixedReading, ...]:
    """The fix :data:`GEAR` names, measured: each motor (no PD gains) whose gear ratio is
    not 1 given the file's control u scaled by its gear at Drake's actuation input, and the
    force Drake then applies to its joint (its net actuation output, the effort limit
    applied; u within half of it) read back per unit of u: the gear it acts with."""
    indices = list(plant.GetJointActuatorIndices())
    targets = [k for k, i in enumerate(indices)
               if float(plant.get_joint_actuator(i).default_gear_ratio()) != 1.0
               and not plant.get_joint_actuator(i).has_controller()]
    if not targets:
        return ()
    context = plant.CreateDefaultContext()
    for instance_port, members in _desired_ports(plant, indices).values():
        instance_port.FixValue(context, np.zeros(2 * len(members)))  # (the servos: off)
    matrix, net = plant.MakeActuationMatrix(), plant.get_net_actuation_output_port()
    acting: dict[str, tuple[float, float]] = {}
    for k in targets:
        actuator = plant.get_joint_actuator(indices[k])
        gear, limit = float(actuator.default_gear_ratio()), float(actuator.effort_limit())
        u = min(1.0, 0.5 * limit / abs(gear)) if np.isfinite(limit) else 1.0
        given = np.zeros(len(indices))
        given[k] = gear * u
        plant.get_actuation_input_port().FixValue(context, given)
        tau = matrix @ net.Eval(context)
        acting[actuator.name()] = (gear, float(tau[actuator.joint().velocity_start()]) / u)
    return geared(tree, acting,
                  lambda g: f"the control scaled by the gear ({g:g}) at Drake's actuation input")


def file_force_bounds(root: ET.Element) -> dict[str, tuple[float, float] | None]:
    """Each ``<motor>``'s and ``<position>``'s bound on the force it applies to its joint as
    MuJoCo's compiler gives it (``root``: the file, its includes inlined): gear × its
    forcerange (its own, else its class's; limited where ``forcelimited`` says so, else
    where stated) ∩ its joint's ``actuatorfrcrange``; None where unbounded
    (:func:`per_actuator`)."""
    joint_bounds = {p.element.get("name"): _bound(p.attrs.get("actuatorfrcrange"),
                                                  p.attrs.get("actuatorfrclimited"))
                    for p in placed(root, "joint", ("actuatorfrcrange", "actuatorfrclimited"))}

    def bound_of(attrs: Mapping[str, str], element: ET.Element) -> tuple[float, float] | None:
        gear = float((attrs.get("gear") or "1").split()[0])
        own = _bound(attrs.get("forcerange"), attrs.get("forcelimited"))
        bound = None if own is None else (min(gear * own[0], gear * own[1]),
                                          max(gear * own[0], gear * own[1]))
        held = joint_bounds.get(element.get("joint", ""))
        if held is not None:
            bound = held if bound is None else (max(bound[0], held[0]), min(bound[1], held[1]))
        return bound

    return per_actuator(root, READ_TAGS_BY_ELEMENT, ("forcerange", "forcelimited", "gear"),
                        bound_of)


READ_TAGS_BY_ELEMENT = ("motor", "position")
"""The actuator elements Drake's MJCF parser reads, by tag (:data:`READ_TAGS`)."""


def _bound(stated: str | None, limited: str | None) -> tuple[float, float] | None:
    """A range as MuJoCo's compiler takes it: limited where ``limited`` is "true", or where
    it is "auto" or absent and the range is stated (``autolimits``, MuJoCo's default)."""
    if not stated or limited == "false":
        return None
    low, high = (float(x) for x in stated.split()[:2])
    return None if low == high == 0.0 else (low, high)


def effort_fixed(plant: Any, root: ET.Element, tree: ModelTree) -> tuple[FixedReading, ...]:
    """The fix :data:`EFFORT` names, measured: each actuator on a gear of 1 given the effort
    limit of the force bound the file states (:func:`file_force_bounds`: the largest
    magnitude, Drake's limit being symmetric; infinite where the file bounds none), and the
    actuators read back (the plant's limits restored after)."""
    stated = file_force_bounds(root)
    targets = []
    for index in plant.GetJointActuatorIndices():
        a = plant.get_joint_actuator(index)
        key = a.name() if a.name() in stated else f"joint {a.joint().name()}"
        if key in stated and float(a.default_gear_ratio()) == 1.0:
            bound = stated[key]
            targets.append((a, np.inf if bound is None else max(abs(bound[0]), abs(bound[1]))))
    targets = [(a, limit) for a, limit in targets if float(a.effort_limit()) != limit]
    if not targets:
        return ()
    saved = [float(a.effort_limit()) for a, _ in targets]
    try:
        for a, limit in targets:
            a.set_effort_limit(limit)
        fixed = replace(tree, actuators=read(plant))
    finally:
        for (a, _), limit in zip(targets, saved, strict=True):
            a.set_effort_limit(limit)
    return tuple(FixedReading(
        subject=a.name(), fields=("limits", "force range"), tree=fixed,
        fix=f"JointActuator.set_effort_limit({limit:g}) after parsing") for a, limit in targets)


def _states_kv(root: ET.Element) -> bool:
    """Whether the file (``root``: its includes inlined) gives any ``<position>`` a nonzero
    ``kv``, directly or through a default class: the premise of :data:`DAMPING`."""
    return any(float(e.get("kv", "0") or 0) != 0.0 for e in root.iter("position"))


def actuation(plant: Any, context: Any, *, q: np.ndarray, v: np.ndarray,
              u: np.ndarray) -> Actuation:
    """In a ``context`` of its own (its fixed desired state arms the PD controllers, which
    the smooth dynamics' context leaves unconnected, so off): Drake's generalized actuator
    force B · (its net actuation output) and its generalized acceleration at each state and
    control (:func:`read`'s order): a motor's control its
    input, a servo's its target position (see the module's docstring)."""
    indices = list(plant.GetJointActuatorIndices())
    servo = np.array([plant.get_joint_actuator(i).has_controller() for i in indices], bool)
    matrix = plant.MakeActuationMatrix()
    port = plant.get_actuation_input_port()
    desired = _desired_ports(plant, indices)
    net = plant.get_net_actuation_output_port()
    acc = plant.get_generalized_acceleration_output_port()
    n, nv = len(q), plant.num_velocities()
    tau, forward = np.empty((n, nv)), np.empty((n, nv))
    for s in range(n):
        plant.SetPositions(context, q[s])
        plant.SetVelocities(context, v[s])
        port.FixValue(context, np.where(servo, 0.0, u[s]))
        for instance_port, members in desired.values():
            target = np.zeros(2 * len(members))
            target[: len(members)] = u[s, members]
            instance_port.FixValue(context, target)
        tau[s] = matrix @ net.Eval(context)
        forward[s] = acc.Eval(context)
    return Actuation(tau=tau, forward=forward)


def control_derivatives(plant: Any, ad: Any, context: Any, *, q: np.ndarray, v: np.ndarray,
                        u: np.ndarray) -> np.ndarray:
    """∂v̇/∂u (n, nv, nu) by Drake's forward-mode automatic differentiation of its
    generalized acceleration, the controls seeded (``ad``: ``plant`` as ``AutoDiffXd``, in a
    ``context`` of its own, see :func:`actuation`; which actuator is a servo, whose control
    is its target, is ``plant``'s fact: :data:`PD_DROPPED`)."""
    from pydrake.autodiffutils import AutoDiffXd, ExtractGradient, InitializeAutoDiff

    indices = list(ad.GetJointActuatorIndices())
    servo = np.array([plant.get_joint_actuator(i).has_controller() for i in indices], bool)
    port, desired = ad.get_actuation_input_port(), _desired_ports(ad, indices)
    acc = ad.get_generalized_acceleration_output_port()
    out = np.empty((len(q), ad.num_velocities(), len(indices)))
    for s in range(len(q)):
        seeded = InitializeAutoDiff(np.asarray(u[s], float))[:, 0]  # type: ignore[arg-type]
        zero = AutoDiffXd(0.0, np.zeros(len(indices)))  # type: ignore[arg-type]  # (its stub)
        ad.SetPositions(context, [AutoDiffXd(x) for x in q[s]])
        ad.SetVelocities(context, [AutoDiffXd(x) for x in v[s]])
        port.FixValue(context, [zero if pd else seeded[k] for k, pd in enumerate(servo)])
        for instance_port, members in desired.values():
            target = [seeded[k] for k in members] + [zero] * len(members)
            instance_port.FixValue(context, target)
        out[s] = ExtractGradient(acc.Eval(context))
    return out


def _desired_ports(plant: Any, indices: list[Any]) -> dict[int, tuple[Any, list[int]]]:
    """Model instance → its desired-state port and the places (in ``indices``) of its
    actuators, in actuator order (the port's order: q_d of each, then v_d of each)."""
    out: dict[int, tuple[Any, list[int]]] = {}
    for place, index in enumerate(indices):
        instance = plant.get_joint_actuator(index).model_instance()
        key = int(instance)
        if key not in out:
            out[key] = (plant.get_desired_state_input_port(instance), [])
        out[key][1].append(place)
    return out


PROOFS = {
    "GEAR": Proof.FIX,
    "DAMPING": Proof.FIX,
    "EFFORT": Proof.FIX,
    "CONTROL_RANGE": Proof.MEASURED,
    "PD_DROPPED": Proof.MEASURED,
    "IGNORED": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
