"""What an engine's loader offers beyond its dynamics (:class:`Offer`, the class fact
:attr:`~.base.ModelEngine.offers`), and the field of forces on bodies some offers take."""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

import numpy as np


class Offer(StrEnum):
    """What an engine computes beyond its dynamics (:attr:`ModelEngine.offers`)."""

    DERIVATIVES = "derivatives"
    """``derivatives(q, v, a)``: ∂v̇/∂(q, v, τ) and ∂τ/∂(q, v), its own (analytic, automatic
    or finite differences)."""
    TRANSITION = "transition"
    """``transition(q, v, a)``: the Jacobians of one step of each of its integrators."""
    FORWARD = "forward"
    """``forward(q, v, τ)``: its own forward dynamics at τ (Pinocchio's ABA), which a run
    compares, rather than M⁻¹ (τ − h) from its M and h."""
    STEPPING = "simulate"
    """``simulate(q0, v0, dt, steps, integrator=)``: trajectories by its own stepping, with
    each of its registration's integrators."""
    SOLVING = "solve"
    """``solve(q0, v0, t_eval, rtol=)``: a trajectory by scipy's error-controlled DOP853 on its
    own forward dynamics (an engine with no integrator of its own)."""
    CONTROLLED_STEPPING = "simulate_controlled"
    """``simulate_controlled(q0, v0, period, samples, accuracy=)``: a trajectory by its own
    error-controlled integrator at a target accuracy, and its step counts."""
    ACTUATION = "actuation"
    """``actuation(q, v, u)``: the generalized force of its actuators at controls u and its
    forward dynamics with it (its tree's ``actuators`` say what it read)."""
    CONTROL_DERIVATIVES = "control_derivatives"
    """``control_derivatives(q, v, u)``: ∂v̇/∂u of its forward dynamics with its actuators,
    its own (automatic differentiation)."""
    INPUT_JACOBIAN = "input_jacobians"
    """``input_jacobians(q, v, u)``: the Jacobians of one step of its integrators in the
    controls, ∂x₊/∂u."""
    COUPLINGS = "couplings"
    """``couple(couplings)``: a book case's couplings (linear equalities between joints) as
    the engine's own constraints, which its forward dynamics and stepping then hold, and
    ``constraint_forces(q, v, τ)`` their multipliers."""
    CLOSURES = "closed"
    """``closed(q, v, τ)``: its own rows and constrained forward dynamics on the constraints
    its tree's ``closures`` hold (:class:`~.closures.ClosedReading`)."""
    CLOSED_DERIVATIVES = "closed_derivatives"
    """``closed_derivatives(q, v, τ)``: ∂v̇/∂(q, v) of its constrained forward dynamics, its
    own (finite differences at its step and twice it: (S, 2, nv, 2 nv))."""
    BODY_FORCES = "body_forces"
    """``body_forces(q, v, field)``: the generalized force of forces at bodies' centres of
    mass (a :data:`Field`), its own (its Jacobians or its solver's sum); and
    ``simulate(..., field=)`` applying them at every step through its stepping API."""


Field = Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]]
"""Forces on bodies: each body's centre of mass in world axes, by the body's name, to the
force (world axes, at that centre) on it — a book case's external field, evaluated at the
positions the engine itself computes."""
