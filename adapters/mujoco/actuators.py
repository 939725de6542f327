"""MuJoCo's actuators: read back into the neutral form (:mod:`dyncheck.adapters.actuators`),
their generalized force and the forward dynamics at a control, and the Jacobian of one step
in the controls (``mjd_transitionFD``'s B).

The check's model runs with actuation disabled (smooth dynamics only); these use a copy of it
with actuation enabled and constraints, springs and dampers still off, so that B is the
step's dependence on the controls through the actuators alone. An actuator with activation
dynamics is evaluated with its activation state equal to its control.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from dyncheck.adapters.actuators import (
    Activation,
    Actuation,
    Actuator,
    InputJacobian,
    Transmission,
)
from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format
from dyncheck.vocabulary import Integrator

UNREAD_TRANSMISSIONS = (
    "MuJoCo's URDF compiler makes no actuator of a URDF's <transmission> ({count} in the "
    "file): MuJoCo holds none (fix: add <actuator> elements to an MJCF of the robot, e.g. the "
    "one MuJoCo writes from the URDF with mj_saveLastXML)"
)

_DYNAMICS = {
    int(mujoco.mjtDyn.mjDYN_NONE): Activation.NONE,
    int(mujoco.mjtDyn.mjDYN_INTEGRATOR): Activation.INTEGRATOR,
    int(mujoco.mjtDyn.mjDYN_FILTER): Activation.FILTER,
    int(mujoco.mjtDyn.mjDYN_FILTEREXACT): Activation.FILTER_EXACT,
}
_JOINTED = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
_AFFINE_GAIN = (int(mujoco.mjtGain.mjGAIN_FIXED), int(mujoco.mjtGain.mjGAIN_AFFINE))
_AFFINE_BIAS = (int(mujoco.mjtBias.mjBIAS_NONE), int(mujoco.mjtBias.mjBIAS_AFFINE))
STEPS = ((Integrator.EULER, mujoco.mjtIntegrator.mjINT_EULER),
         (Integrator.IMPLICITFAST, mujoco.mjtIntegrator.mjINT_IMPLICITFAST))
"""The integrators whose B is compared (RK4's is not: ``mjd_transitionFD`` refuses it)."""


def _kind(gain: tuple[float, ...], bias: tuple[float, ...]) -> str:
    """The MJCF shortcut an actuator's parameters are (``general`` where none is)."""
    if gain[1:] == (0.0, 0.0) and bias == (0.0, 0.0, 0.0):
        return "motor" if gain[0] == 1.0 else "general"
    if gain[1:] == (0.0, 0.0) and bias[0] == 0.0 and bias[1] == -gain[0]:
        return "position"
    if gain[1:] == (0.0, 0.0) and bias[:2] == (0.0, 0.0) and bias[2] == -gain[0]:
        return "velocity"
    return "general"


def _unmodelled(m: mujoco.MjModel, k: int) -> str:
    """Why actuator k is outside the neutral form (empty where it is not)."""
    trn, joint = int(m.actuator_trntype[k]), int(m.actuator_trnid[k, 0])
    if trn != int(mujoco.mjtTrn.mjTRN_JOINT) or int(m.jnt_type[joint]) not in _JOINTED:
        return "its transmission is not a hinge's or a slide's"
    if int(m.actuator_gaintype[k]) not in _AFFINE_GAIN or \
            int(m.actuator_biastype[k]) not in _AFFINE_BIAS:
        return "its gain or bias is not affine (muscle, user or another law)"
    if int(m.actuator_dyntype[k]) not in _DYNAMICS or m.actuator_actearly[k]:
        return "its activation dynamics are not none, integrator or filter (or act early)"
    for extra in ("actuator_delay", "actuator_damping", "actuator_armature"):
        if hasattr(m, extra) and np.any(np.asarray(getattr(m, extra))[k] != 0):
            return f"its {extra.removeprefix('actuator_')} is not zero"
    return ""


def read(m: mujoco.MjModel, joint_names: list[str]) -> tuple[Actuator, ...]:
    """Every actuator of ``m`` in the neutral form (``joint_names``: the tree's name of each
    joint, by MuJoCo's id)."""
    out = []
    for k in range(m.nu):
        gain = tuple(float(x) for x in m.actuator_gainprm[k, :3])
        bias = tuple(float(x) for x in m.actuator_biasprm[k, :3])
        if int(m.actuator_gaintype[k]) == int(mujoco.mjtGain.mjGAIN_FIXED):
            gain = (gain[0], 0.0, 0.0)
        if int(m.actuator_biastype[k]) == int(mujoco.mjtBias.mjBIAS_NONE):
            bias = (0.0, 0.0, 0.0)
        why = _unmodelled(m, k)
        jointed = int(m.actuator_trntype[k]) == int(mujoco.mjtTrn.mjTRN_JOINT)
        activation = _DYNAMICS.get(int(m.actuator_dyntype[k]), Activation.OTHER)
        name = m.actuator(k).name or f"actuator {k}"
        out.append(Actuator(
            name=name,
            joint=joint_names[int(m.actuator_trnid[k, 0])] if jointed else "",
            transmission=Transmission.OTHER if why else Transmission.JOINT,
            gear=float(m.actuator_gear[k, 0]), gain=gain, bias=bias,  # type: ignore[arg-type]
            ctrl_range=_range(m.actuator_ctrllimited[k], m.actuator_ctrlrange[k]),
            force_range=_range(m.actuator_forcelimited[k], m.actuator_forcerange[k]),
            activation=activation if not why or activation is Activation.NONE
            else Activation.OTHER,
            time_constant=float(m.actuator_dynprm[k, 0])
            if activation in (Activation.FILTER, Activation.FILTER_EXACT) else 0.0,
            act_range=_range(m.actuator_actlimited[k], m.actuator_actrange[k]),
            joint_range=_range(m.jnt_actfrclimited[m.actuator_trnid[k, 0]],
                               m.jnt_actfrcrange[m.actuator_trnid[k, 0]]) if jointed else None,
            what=f"<{_kind(gain, bias)}> {name!r}" + (f" ({why})" if why else "")))
    return tuple(out)


def file_hints(source: ModelFile) -> tuple[tuple[str, str, str], ...]:
    """Why MuJoCo holds no actuator the file states (a URDF's transmissions, counted on the
    file)."""
    if source.format is not Format.URDF:
        return ()
    count = len(parsing.root(source.text).findall("transmission"))
    return (("model", "actuator", UNREAD_TRANSMISSIONS.format(count=count)),) if count else ()


def _range(limited: object, bounds: np.ndarray) -> tuple[float, float] | None:
    return (float(bounds[0]), float(bounds[1])) if limited else None


def with_actuation(m: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of the check's model with actuation enabled (constraints, springs and dampers
    off as in the check's)."""
    actuated = copy.copy(m)
    actuated.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
    return actuated


def activations(m: mujoco.MjModel, u: np.ndarray) -> np.ndarray:
    """The activation states (n, na) the check sets at controls u (n, nu): each stateful
    actuator's, its control's value."""
    act = np.zeros((len(u), m.na))
    for k in range(m.nu):
        if m.actuator_actadr[k] >= 0:
            start = m.actuator_actadr[k]
            act[:, start : start + m.actuator_actnum[k]] = u[:, k : k + 1]
    return act


def _joint_actuators_alone(m: mujoco.MjModel, d: mujoco.MjData,
                           modelled: list[bool]) -> np.ndarray:
    """The generalized force of the ``modelled`` actuators (joint transmissions on hinges and
    slides) alone: gear × ``actuator_force`` at each one's degree of freedom, each joint's
    ``actuatorfrcrange`` applied to the sum, as MuJoCo applies it to the sum of all."""
    out = np.zeros(m.nv)
    for k, kept in enumerate(modelled):
        if kept and int(m.actuator_trntype[k]) == int(mujoco.mjtTrn.mjTRN_JOINT):
            joint = int(m.actuator_trnid[k, 0])
            out[m.jnt_dofadr[joint]] += m.actuator_gear[k, 0] * d.actuator_force[k]
    for joint in range(m.njnt):
        if m.jnt_actfrclimited[joint] and int(m.jnt_type[joint]) in (
                int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            dof = m.jnt_dofadr[joint]
            out[dof] = np.clip(out[dof], *m.jnt_actfrcrange[joint])
    return out


class Actuated:
    """MuJoCo with :func:`with_actuation`'s copy of the check's model."""

    def __init__(self, m: mujoco.MjModel) -> None:
        self.model = with_actuation(m)
        self.data = mujoco.MjData(self.model)
        self.modelled = [not _unmodelled(m, k) for k in range(m.nu)]
        """Which actuators the neutral form holds (a joint's; not a tendon's or a site's)."""

    def _set(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> None:
        d = self.data
        d.qpos[:], d.qvel[:], d.ctrl[:] = q, v, u
        d.qfrc_applied[:] = 0.0
        d.act[:] = activations(self.model, u[None])[0]

    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """``qfrc_actuator`` and ``qacc`` after ``mj_forward`` at each state and control;
        where some actuator is not :attr:`modelled` (a tendon's, a site's), the force of the
        others alone too: gear × ``actuator_force`` at each one's joint, each joint's
        ``actuatorfrcrange`` applied to the sum (:attr:`Actuation.joint_tau`)."""
        m, n, nv = self.model, len(q), self.model.nv
        tau, forward = np.empty((n, nv)), np.empty((n, nv))
        alone = None if all(self.modelled) else np.zeros((n, nv))
        for i in range(n):
            self._set(q[i], v[i], u[i])
            mujoco.mj_forward(m, self.data)
            tau[i], forward[i] = self.data.qfrc_actuator, self.data.qacc
            if alone is not None:
                alone[i] = _joint_actuators_alone(m, self.data, self.modelled)
        return Actuation(tau=tau, forward=forward, joint_tau=alone)

    def input_jacobians(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                        fd_step: float) -> tuple[InputJacobian, ...]:
        """B = ∂x₊/∂u of one step, x = (δq, v, act), by ``mjd_transitionFD`` (centered
        differences in ``ctrl``, MuJoCo's chart) at steps ``fd_step`` and twice that, for
        the semi-implicit Euler and implicitfast integrators."""
        m, d = self.model, self.data
        n, size = len(q), 2 * m.nv + m.na
        found = np.zeros((size, m.nu))
        integrator = m.opt.integrator
        out = []
        try:
            for name, kind in STEPS:
                m.opt.integrator = kind
                fine, coarse = np.zeros((n, size, m.nu)), np.zeros((n, size, m.nu))
                for i in range(n):
                    for into, step in ((fine, fd_step), (coarse, 2 * fd_step)):
                        self._set(q[i], v[i], u[i])
                        mujoco.mj_forward(m, d)
                        mujoco.mjd_transitionFD(m, d, step, True, None, found, None, None)
                        into[i] = found
                out.append(InputJacobian(matrix=fine, coarse=coarse,
                                         time_step=float(m.opt.timestep), fd_step=fd_step,
                                         integrator=name))
        finally:
            m.opt.integrator = integrator
        return tuple(out)


class MujocoActuation:
    """What :class:`~.model.MujocoModel` computes of its actuators (a
    mixin over its ``model``, MuJoCo's finite-difference step ``fd_step``)."""

    model: mujoco.MjModel
    fd_step: float
    _actuated: Actuated | None = None

    def _on(self) -> Actuated:
        if self._actuated is None:
            self._actuated = Actuated(self.model)
        return self._actuated

    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """MuJoCo's ``qfrc_actuator`` and ``qacc`` at each state and control, and its joint
        actuators' force alone where it holds others (:meth:`Actuated.actuation`)."""
        return self._on().actuation(q, v, u)

    def input_jacobians(self, q: np.ndarray, v: np.ndarray,
                        u: np.ndarray) -> tuple[InputJacobian, ...]:
        """MuJoCo's B of one Euler and one implicitfast step (:meth:`Actuated.input_jacobians`)."""
        return self._on().input_jacobians(q, v, u, self.fd_step)


PROOFS = {
    "UNREAD_TRANSMISSIONS": Proof.MEASURED,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
