"""An engine's actuators as the engine-neutral tree holds them: the control law on a joint, in
MuJoCo's general form, which every engine's reading is mapped into.

An actuator on a hinge or slide joint (a *joint transmission*) of gear g turns a control u
into a generalized force on that joint,

    τ = g · clamp(f, forcerange),   f = gain · a + bias,
    gain = g₀ + g₁ L + g₂ L̇,       bias = b₀ + b₁ L + b₂ L̇,    L = g q,  L̇ = g v,

(the sum of a joint's actuators' τ then held in the joint's own range, where it has one),
with a = clamp(u, ctrlrange) where it has no activation dynamics, and otherwise its
activation state (integrator: ȧ = u; filter: ȧ = (u − a)/t). A motor is gain (1, 0, 0),
bias 0; a position servo gain (kp, 0, 0), bias (0, −kp, −kv); a velocity servo gain
(kv, 0, 0), bias (0, 0, −kv). An engine that holds its actuators otherwise (Drake's joint
actuator, whose input is the joint's effort and whose PD controller's target is a joint
position) is read back into this form as it acts, so that two readings compare field by field.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np


class Activation(StrEnum):
    """An actuator's activation dynamics (MuJoCo's ``dyntype``)."""

    NONE = "none"
    INTEGRATOR = "integrator"
    FILTER = "filter"
    FILTER_EXACT = "filterexact"
    OTHER = "other"
    """Muscle or user dynamics: MuJoCo-only, not modelled here."""


class Transmission(StrEnum):
    """What the actuator drives."""

    JOINT = "joint"
    """A hinge or slide joint, scaled by the gear."""
    OTHER = "other"
    """A tendon, a site, a slider-crank, a body, a ball or free joint, a muscle's or a user's
    force law: MuJoCo-only, stated once per model and not modelled here."""


EULER_DAMPING = "euler's implicit damping"
"""The hint an engine's tree carries where its Euler step applies the joints' damping
implicitly, (M + h D), though the model's dampers are disabled (the premise checked: some
joint is damped): the step Jacobian in the controls is then predicted with it."""

Range = tuple[float, float] | None
"""(lower, upper) where limited; None where not."""


@dataclass(frozen=True, kw_only=True)
class Actuator:
    """One actuator as an engine holds it (see the module's docstring); ``joint`` is empty
    where the transmission is not a joint's."""

    name: str
    joint: str
    transmission: Transmission
    gear: float
    gain: tuple[float, float, float]
    bias: tuple[float, float, float]
    ctrl_range: Range
    force_range: Range
    activation: Activation = Activation.NONE
    time_constant: float = 0.0
    """A filter's t (s); 0 otherwise."""
    act_range: Range = None
    joint_range: Range = None
    """Its joint's bound on the sum of the forces of every actuator on it (MuJoCo's
    ``actuatorfrcrange``; its URDF compiler makes one of a joint's ``<limit effort>``)."""
    what: str = ""
    """How the engine names it (``<position> 'elbow'``, Drake's ``JointActuator 'motor0'``)."""

    @property
    def modelled(self) -> bool:
        """Whether the neutral control law above describes it (a joint transmission whose
        activation is none, an integrator or a filter)."""
        return (self.transmission is Transmission.JOINT
                and self.activation is not Activation.OTHER)


@dataclass(frozen=True, kw_only=True)
class Actuation:
    """An engine's answer at a batch of states and controls, in its own layout: the
    generalized force of its actuators τ (n, nv) and its forward dynamics with that force,
    v̇ = M⁻¹ (τ − h) (n, nv)."""

    tau: np.ndarray
    forward: np.ndarray
    floor: np.ndarray | None = None
    """Per state, the size of what the engine subtracted to find τ (Newton: its net joint
    force without the drives), which its round-off is relative to; None: nothing."""
    joint_tau: np.ndarray | None = None
    """Where the engine also holds actuators outside the neutral form (a tendon's, a site's,
    a muscle's: MuJoCo), the force of its joint actuators alone (n, nv), each joint's
    ``actuatorfrcrange`` applied to their sum: what an engine holding only those applies;
    None: ``tau`` is that."""


@dataclass(frozen=True, kw_only=True)
class InputJacobian:
    """An engine's Jacobian of one integrator step in its controls, ∂x₊/∂u with
    x = (δq, v, act) in its chart (n, 2 nv + na, nu), by finite differences of step
    ``fd_step`` and, for their error, of twice that step (``coarse``); or, where ``fd_step``
    is 0, by automatic differentiation (exact to round-off: ``coarse`` is ``matrix``)."""

    matrix: np.ndarray
    coarse: np.ndarray
    time_step: float
    fd_step: float
    integrator: str

    @property
    def differentiated(self) -> bool:
        """Whether it is automatic differentiation's (no truncation error)."""
        return self.fd_step == 0.0
