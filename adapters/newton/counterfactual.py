"""Newton's actuator causes proved on its own Featherstone solver (#77): each fix its hints
name applied to the model, the force measured again (:class:`~dyncheck.adapters.model_tree.
FixedReading`), and where no fix exists in Newton, the cause measured.

- :data:`~.actuators.GEAR`: the drive's stiffness and damping set to g² kp, g² kv and its
  target to u / g (MuJoCo's servo on a gear g, written at the joint); the force per unit of
  control, over the gain, is the gear it acts with.
- :data:`~.actuators.MOTORS`: each ``<motor>`` driven by ``control.joint_f`` = g u at its
  joint; the force per unit of control read back.
- :data:`~.actuators.BOUNDS`: a control ten times beyond the file's control range gives ten
  times the force of a unit control — beyond the force range too: neither is applied.

Each measurement is the difference of two solver steps at the model's reference state (the
controls 0 and the one measured), so the state's own forces cancel (:func:`~.actuators.
actuation`). Newton's MuJoCo attributes (the file's actuators as its importer keeps them)
give what the file states.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from dyncheck.adapters.actuators import Actuator, Transmission
from dyncheck.adapters.model_tree import FixedReading, ModelTree, geared
from dyncheck.adapters.newton.actuators import BOUNDS, actuation, drives

RTOL = 1e-4
"""Float32 forces of a few steps: a ratio read to 1e-4 (its ε is 1.2e-7)."""
BEYOND = 10.0
"""How far beyond its control range (× its largest bound) a control is given."""


@dataclass(frozen=True, kw_only=True)
class Stated:
    """One of the file's actuators on a joint, as Newton's importer keeps it."""

    name: str
    joint: int
    gear: float
    ctrl: tuple[float, float] | None
    force: tuple[float, float] | None
    """Its force range times its gear (MuJoCo's bound at the joint); None: unbounded."""


def stated(model: Any) -> list[Stated]:
    """The file's actuators with a joint transmission (none for a URDF)."""
    try:
        attrs = model.mujoco
        labels = list(attrs.actuator_label)
    except (AttributeError, TypeError):
        return []
    kinds, ids = attrs.actuator_trntype.numpy(), attrs.actuator_trnid.numpy()
    starts = model.joint_qd_start.numpy()
    # (its trnid holds the joint's degree of freedom, measured: a motor on the hinge after a
    # free joint names dof 6; the hinge owning it)
    owner = {int(starts[j]): j for j in range(model.joint_count)
             if int(starts[j + 1]) - int(starts[j]) == 1}
    gears, ctrl = attrs.actuator_gear.numpy(), attrs.actuator_ctrlrange.numpy()
    has_ctrl, force = attrs.actuator_has_ctrlrange.numpy(), attrs.actuator_forcerange.numpy()
    has_force = attrs.actuator_has_forcerange.numpy()
    limited = attrs.actuator_forcelimited.numpy()  # 0 false, 1 true, 2 auto (where stated)
    out = []
    for k, label in enumerate(labels):
        if int(kinds[k]) != 0 or int(ids[k][0]) not in owner:  # a hinge's or a slide's only
            continue
        g = float(gears[k][0])
        bounded = int(limited[k]) == 1 or (int(limited[k]) == 2 and bool(has_force[k]))
        ends = sorted((g * float(force[k][0]), g * float(force[k][1])))
        out.append(Stated(name=str(label), joint=owner[int(ids[k][0])], gear=g,
                          ctrl=(float(ctrl[k][0]), float(ctrl[k][1])) if has_ctrl[k] else None,
                          force=(ends[0], ends[1]) if bounded else None))
    return out


def _per_unit(model: Any, newton: Any, pairs: list[tuple[int, int]],
              controls: list[float]) -> list[float]:
    """For each (joint, mode) of ``pairs``: the force at its joint with its control of
    ``controls`` (the others 0) less that with every control 0, by the Featherstone solver
    at the reference state — one solver for all (a row of controls per pair)."""
    n = len(pairs) + 1
    q = np.stack([model.joint_q.numpy().astype(float)] * n)
    u = np.zeros((n, len(pairs)))
    u[np.arange(1, n), np.arange(len(pairs))] = controls
    found = actuation(model, newton, pairs, q=q, v=np.zeros((n, model.joint_dof_count)), u=u)
    starts = model.joint_qd_start.numpy()
    return [float(found.tau[k + 1, int(starts[j])] - found.tau[0, int(starts[j])])
            for k, (j, _) in enumerate(pairs)]


def gear_fixed(model: Any, newton: Any, tree: ModelTree,
               names: list[str]) -> tuple[FixedReading, ...]:
    """The fix :data:`~.actuators.GEAR` names, measured: each drive whose file actuator has
    a gear g ≠ 1 given stiffness and damping × g² and the control ÷ g; the force per unit
    of control over the drive's gain (its stiffness, or its damping for a velocity servo)
    is the gear it then acts with (the model's gains restored after)."""
    by_joint = {s.joint: s for s in stated(model)}
    targets = [(j, mode) for j, mode in drives(model, newton)
               if j in by_joint and by_joint[j].gear != 1.0]
    if not targets:
        return ()
    ke, kd = model.joint_target_ke.numpy().copy(), model.joint_target_kd.numpy().copy()
    starts = model.joint_qd_start.numpy()
    scaled_ke, scaled_kd = ke.copy(), kd.copy()
    for j, _ in targets:
        g, dof = by_joint[j].gear, int(starts[j])
        scaled_ke[dof], scaled_kd[dof] = g * g * ke[dof], g * g * kd[dof]
    velocity = int(newton.JointTargetMode.VELOCITY)
    try:
        model.joint_target_ke.assign(scaled_ke)
        model.joint_target_kd.assign(scaled_kd)
        forces = _per_unit(model, newton, targets, [1.0 / by_joint[j].gear for j, _ in targets])
    finally:
        model.joint_target_ke.assign(ke)
        model.joint_target_kd.assign(kd)
    acting = {}
    for (j, mode), force in zip(targets, forces, strict=True):
        dof = int(starts[j])
        gain = float(kd[dof] if mode == velocity else ke[dof])  # (the file's kp, or kv)
        acting[f"{names[j]} drive"] = (by_joint[j].gear, force / gain if gain else 0.0)
    return geared(tree, acting, lambda g: f"the drive's ke and kd set to {g:g}² × kp and kv "
                                          f"and its target to u / {g:g}")


def motors_fixed(model: Any, newton: Any, tree: ModelTree,
                 names: list[str]) -> tuple[FixedReading, ...]:
    """The fix :data:`~.actuators.MOTORS` names, measured: each file actuator on a joint
    that no drive carries given as ``control.joint_f`` = g u at its joint; it joins the
    fixed reading where the solver applies it (its force per unit of control read back)."""
    driven = {j for j, _ in drives(model, newton)}
    effort = int(newton.JointTargetMode.EFFORT)
    free = [s for s in stated(model) if s.joint not in driven]
    if not free:
        return ()
    forces = _per_unit(model, newton, [(s.joint, effort) for s in free],
                       [s.gear for s in free])  # (joint_f = g u at u = 1)
    added = [Actuator(
        name=s.name, joint=names[s.joint], transmission=Transmission.JOINT, gear=force,
        gain=(1.0, 0.0, 0.0), bias=(0.0, 0.0, 0.0), ctrl_range=s.ctrl, force_range=None,
        what=f"control.joint_f = {s.gear:g} u on {names[s.joint]!r}")
        for s, force in zip(free, forces, strict=True)
        if abs(force) > RTOL * abs(s.gear)]  # (one not applied: no actuator, cause unknown)
    if not added:
        return ()
    return (FixedReading(subject="model", fields=("actuator",),
                         tree=replace(tree, actuators=(*tree.actuators, *added)),
                         fix="each <motor> applied as control.joint_f = gear × u at its joint"),)


def proved(model: Any, newton: Any, tree: ModelTree, names: list[str]) -> ModelTree:
    """``tree`` with its actuator causes proved on Newton's solver: the fixes' readings in
    ``fixed``, :data:`~.actuators.BOUNDS` in ``measured`` where measured. A proof that fails
    costs only itself: its causes stay suspected and a note on the page says why."""
    try:
        fixed = gear_fixed(model, newton, tree, names) + motors_fixed(model, newton, tree, names)
        measured = bounds_measured(model, newton)
    except Exception as exc:  # (the engine's or ours: said on the page, never a crash)
        return replace(tree, notes=(*tree.notes, f"newton: its actuator causes could not be "
                                    f"measured on its solver ({type(exc).__name__}: {exc})"))
    return replace(tree, fixed=(*tree.fixed, *fixed), measured=tree.measured | measured)


def bounds_measured(model: Any, newton: Any) -> frozenset[str]:
    """:data:`~.actuators.BOUNDS` where measured: every drive whose file actuator states a
    control or force range gives, at a control :data:`BEYOND` × its largest bound, that
    many times the force of a unit control (the control not clamped), and a force beyond
    the stated force bound (the force not clamped)."""
    by_joint = {s.joint: s for s in stated(model)}
    bounded = [(j, mode) for j, mode in drives(model, newton)
               if j in by_joint and (by_joint[j].ctrl or by_joint[j].force)]
    if not bounded:
        return frozenset()
    big = [BEYOND * max((abs(x) for x in by_joint[j].ctrl or (1.0,)), default=1.0) or BEYOND
           for j, _ in bounded]
    unit = _per_unit(model, newton, bounded, [1.0] * len(bounded))
    far = _per_unit(model, newton, bounded, big)
    for (j, _), b, one, at in zip(bounded, big, unit, far, strict=True):
        force = by_joint[j].force
        linear = at != 0.0 and abs(at - b * one) <= RTOL * abs(at)
        if not (linear and (force is None or not force[0] <= at <= force[1])):
            return frozenset()
    return frozenset({BOUNDS})
