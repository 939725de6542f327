"""Newton's joint drives: read back into the neutral form (:mod:`dyncheck.adapters.actuators`)
as its Featherstone solver (the one dyncheck steps) applies them, and their generalized force
measured by that solver.

Newton's MJCF importer makes a ``<position>`` a drive of its joint (mode POSITION: target
stiffness kp, damping kv) and a ``<velocity>`` one of mode VELOCITY (damping kv). Its
Featherstone solver applies a drive as τ = ke (q_target − q) + kd (q̇_target − q̇), with no
gear and no force bound (its ``joint_effort_limit`` is for other solvers), and a ``<motor>``
or ``<general>`` actuator not at all: the importer keeps those as MuJoCo attributes for its
MuJoCo solver's ``ctrl``. A file's control maps to a POSITION drive's target angle, to a
VELOCITY drive's target speed.

The force is the solver's own: its net joint force ``joint_tau`` after one step with the
drives, minus the same with their stiffness and damping set to 0 (gravity, Coriolis and
passive forces cancel), in float32.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dyncheck.adapters.actuators import Actuation, Actuator, Transmission
from dyncheck.adapters.proof import Proof

MOTORS = (
    "newton's MJCF importer keeps the file's {count} actuators that are no <position> or "
    "<velocity> (<motor>, <general>) as MuJoCo attributes for its MuJoCo solver's ctrl; its "
    "Featherstone solver, which dyncheck steps, does not apply them (fix: drive the joint "
    "with control.joint_f, or step it with SolverMuJoCo)"
)
GEAR = (
    "newton's MJCF importer makes a servo's drive stiffness and damping the file's kp and kv "
    "as written, without the gear (MuJoCo's servo on a gear g acts on its joint as g² kp, "
    "g² kv, with the control divided by g) (fix: set the drive's ke and kd to g² kp and "
    "g² kv and its target to u / g)"
)
BOUNDS = (
    "newton's Featherstone solver bounds neither a drive's target nor its force (the file's "
    "ctrlrange and forcerange are kept for its MuJoCo solver; joint_effort_limit is not "
    "applied by SolverFeatherstone; measured: a control ten times beyond the control range "
    "gives ten times the force of a unit control, beyond the force range too)"
)


def drives(model: Any, newton: Any) -> list[tuple[int, int]]:
    """(joint, mode) of every driven hinge or slide, in joint order: a drive whose stiffness
    and damping are both 0 (what Newton's URDF importer gives every joint) does nothing and
    is none."""
    mode = model.joint_target_mode.numpy()
    ke, kd = model.joint_target_ke.numpy(), model.joint_target_kd.numpy()
    starts, dofs = model.joint_qd_start.numpy(), model.joint_dof_count
    modes = newton.JointTargetMode
    out = []
    for j in range(model.joint_count):
        dof = int(starts[j])
        end = int(starts[j + 1]) if j + 1 < len(starts) else dofs
        kind = int(mode[dof]) if end - dof == 1 else int(modes.NONE)
        if kind == int(modes.EFFORT) or (kind != int(modes.NONE) and (ke[dof] or kd[dof])):
            out.append((j, kind))
    return out


def read(model: Any, newton: Any, names: list[str]) -> tuple[Actuator, ...]:
    """Each drive as the Featherstone solver applies it (``names``: the tree's name of each
    joint, by Newton's index)."""
    ke, kd = model.joint_target_ke.numpy(), model.joint_target_kd.numpy()
    starts = model.joint_qd_start.numpy()
    modes = newton.JointTargetMode
    out = []
    for j, mode in drives(model, newton):
        dof = int(starts[j])
        stiffness, damping = float(ke[dof]), float(kd[dof])
        if mode == int(modes.VELOCITY):
            gain, bias = (damping, 0.0, 0.0), (0.0, 0.0, -damping)
        elif mode == int(modes.EFFORT):
            gain, bias = (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        else:  # POSITION, POSITION_VELOCITY: the control is the target angle
            gain, bias = (stiffness, 0.0, 0.0), (0.0, -stiffness, -damping)
        out.append(Actuator(
            name=f"{names[j]} drive", joint=names[j], transmission=Transmission.JOINT,
            gear=1.0, gain=gain, bias=bias, ctrl_range=None, force_range=None,
            what=f"drive of {names[j]!r} ({modes(mode).name}, ke={stiffness:g}, "
                 f"kd={damping:g})"))
    return tuple(out)


def hints(model: Any, actuators: tuple[Actuator, ...]) -> tuple[tuple[str, str, str], ...]:
    """Why Newton's drives read otherwise than the file's actuators, each premise checked on
    Newton's own model (its MuJoCo attributes: the file's actuators as imported)."""
    try:  # (Newton's namespace of the MuJoCo attributes its importer keeps)
        count = len(model.mujoco.actuator_label)
    except (AttributeError, TypeError):  # a URDF: none
        count = 0
    out = [(a.name, field, why) for a in actuators
           for field, why in (("gear", GEAR), ("limits", BOUNDS), ("control range", BOUNDS),
                              ("force range", BOUNDS))]
    if count > len(actuators):
        out.append(("model", "actuator", MOTORS.format(count=count - len(actuators))))
    return tuple(out)


def actuation(model: Any, newton: Any, actuators: list[tuple[int, int]], *, q: np.ndarray,
              v: np.ndarray, u: np.ndarray) -> Actuation:
    """The drives' force (float64 from Newton's float32) and the accelerations with them at
    each state and control, by its Featherstone solver (see the module's docstring)."""
    solver = newton.solvers.SolverFeatherstone(model)
    now, after, control = model.state(), model.state(), model.control()
    q_start, v_start = model.joint_q_start.numpy(), model.joint_qd_start.numpy()
    ke, kd = model.joint_target_ke.numpy().copy(), model.joint_target_kd.numpy().copy()
    n, nv = len(q), model.joint_dof_count
    tau, forward, floor = np.empty((n, nv)), np.empty((n, nv)), np.empty(n)
    velocity, effort = int(newton.JointTargetMode.VELOCITY), int(newton.JointTargetMode.EFFORT)
    try:
        for s in range(n):
            target_q = np.zeros(model.joint_coord_count, np.float32)
            target_qd, force = np.zeros(nv, np.float32), np.zeros(nv, np.float32)
            for k, (j, mode) in enumerate(actuators):
                into = target_qd if mode == velocity else force if mode == effort else target_q
                into[v_start[j] if into is not target_q else q_start[j]] = u[s, k]
            control.joint_target_q.assign(target_q)
            control.joint_target_qd.assign(target_qd)
            results = []
            for drive in (True, False):
                model.joint_target_ke.assign(ke if drive else np.zeros_like(ke))
                model.joint_target_kd.assign(kd if drive else np.zeros_like(kd))
                control.joint_f.assign(force if drive else np.zeros_like(force))
                now.joint_q.assign(q[s].astype(np.float32))
                now.joint_qd.assign(v[s].astype(np.float32))
                newton.eval_fk(model, now.joint_q, now.joint_qd, now)
                now.clear_forces()
                solver.step(now, after, control, None, 1e-3)
                results.append((solver.joint_tau.numpy().astype(float),
                                solver.joint_qdd.numpy().astype(float)))
            tau[s] = results[0][0] - results[1][0]
            forward[s], floor[s] = results[0][1], float(np.abs(results[1][0]).max())
    finally:
        model.joint_target_ke.assign(ke)
        model.joint_target_kd.assign(kd)
    return Actuation(tau=tau, forward=forward, floor=floor)


PROOFS = {
    "MOTORS": Proof.FIX,
    "GEAR": Proof.FIX,
    "BOUNDS": Proof.MEASURED,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
