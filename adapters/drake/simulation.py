"""What a Drake plant (:class:`~.model.DrakeModel`) offers beyond its dynamics: its own
integrators in a ``Simulator``, a field of forces on bodies, and couplings between joints.

Integrators (Drake's own, by ``ResetIntegratorFromFlags``): ``euler`` is
``semi_explicit_euler`` (v first, then q with the new v: MuJoCo's Euler), ``rk2``
``runge_kutta2`` (order 2), ``rk3`` ``runge_kutta3`` in fixed-step mode (order 3; it is
error-controlled by default); Drake has no classic RK4. Error-controlled, ``runge_kutta3``
is the Simulator's default (a 3rd-order solution propagated, the embedded 2nd-order midpoint
as error estimate), run at a target accuracy with steps ending at the logging times.

A field (forces at bodies' centres of mass, world axes) enters through the plant's
applied-spatial-force input (``ExternallyAppliedSpatialForce`` at the centre of mass), and its
generalized force is Σ Jᵀ F of the translational Jacobians at the centres of mass.

Couplings (a book case's cords): Drake's MJCF parser ignores ``<tendon>`` and the tendon
``<equality>`` (its own warning), and a continuous-time plant enforces no constraint (Drake's
coupler constraint exists only for a discrete plant solved by SAP, and couples two joints, not
three). So a coupling C v = 0 (C constant) is closed with Drake's own M and h by the Lagrange
multiplier of the KKT system

    [M  −Cᵀ] [v̇]   [τ − h]
    [C   0 ] [f ] = [  0  ],

f = −tension; in a simulation Cᵀ f enters the plant's applied-generalized-force input,
recomputed from the state at every stage of Drake's integrators.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.multibody.tree import BodyIndex, Frame, JacobianWrtVariable, RigidBody
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import BasicVector, Context, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput

from dyncheck.adapters.base import Field, Steps
from dyncheck.adapters.linalg import kkt
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import EngineError
from dyncheck.vocabulary import Integrator

INTEGRATORS: dict[str, str] = {
    Integrator.EULER: "semi_explicit_euler",
    Integrator.RK2: "runge_kutta2",
    Integrator.RK3: "runge_kutta3",
}
"""dyncheck's name → Drake's scheme name for ``ResetIntegratorFromFlags``."""
CONTROLLED = "runge_kutta3"
"""The Simulator's default integrator, error-controlled."""

_Body = tuple[str, RigidBody, Frame, np.ndarray]
"""A body's name, Drake body, body frame and centre of mass in that frame."""


def bodies(plant: MultibodyPlant) -> list[_Body]:
    """Every body of the plant but the world, with what a field needs of it."""
    out = []
    for index in range(1, plant.num_bodies()):
        body = plant.get_body(BodyIndex(index))
        out.append((body.name(), body, body.body_frame(), np.asarray(body.default_com())))
    return out


def spatial_forces(plant: MultibodyPlant, context: Context, field: Field,
                   held: Sequence[_Body]) -> list[ExternallyAppliedSpatialForce]:
    """The field at the context's state, as forces at the bodies' centres of mass."""
    world = plant.world_frame()
    where = {name: plant.CalcPointsPositions(context, frame, com, world)[:, 0]
             for name, _, frame, com in held}
    pushed = field(where)
    out = []
    for name, body, _, com in held:
        if name in pushed:
            force = ExternallyAppliedSpatialForce()
            force.body_index = body.index()
            force.p_BoBq_B = com
            force.F_Bq_W = SpatialForce(np.zeros(3), np.asarray(pushed[name], float))
            out.append(force)
    return out


def generalized(plant: MultibodyPlant, context: Context, field: Field,
                held: Sequence[_Body]) -> np.ndarray:
    """Σ Jᵀ F of the field at the context's state (Drake's velocity order)."""
    tau = np.zeros(plant.num_velocities())
    world = plant.world_frame()
    frames = {body.index(): frame for _, body, frame, _ in held}
    for force in spatial_forces(plant, context, field, held):
        jacobian = plant.CalcJacobianTranslationalVelocity(
            context, JacobianWrtVariable.kV, frames[force.body_index], force.p_BoBq_B, world,
            world)
        tau += jacobian.T @ force.F_Bq_W.translational()
    return tau


def coupling_matrix(plant: MultibodyPlant, couplings: Sequence[Coupling]) -> np.ndarray:
    """The couplings' rows C in Drake's velocity order (its joints named as in the file)."""
    rows = np.zeros((len(couplings), plant.num_velocities()))
    for k, coupling in enumerate(couplings):
        for name, coefficient in coupling.coefs:
            rows[k, plant.GetJointByName(name).velocity_start()] += coefficient
    return rows


def closed(plant: MultibodyPlant, context: Context, tau: np.ndarray,
           rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """v̇ and the multipliers f of the KKT solve at the context's state: Drake's M and h, the
    couplings' constant C."""
    return kkt(plant.CalcMassMatrix(context),
               tau - plant.CalcBiasTerm(context) + plant.CalcGravityGeneralizedForces(context),
               rows)


class _Field(LeafSystem):
    """Reads the plant's state, outputs the field as externally applied spatial forces —
    evaluated at every stage of every step."""

    def __init__(self, plant: MultibodyPlant, field: Field) -> None:
        super().__init__()
        self._plant, self._field, self._held = plant, field, bodies(plant)
        n = plant.num_positions() + plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self.DeclareAbstractOutputPort(
            "forces", lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]), self._calc)
        self._ctx = plant.CreateDefaultContext()

    def _calc(self, context: Context, output: AbstractValue) -> None:
        self._plant.SetPositionsAndVelocities(self._ctx, self._state.Eval(context))
        output.set_value(spatial_forces(self._plant, self._ctx, self._field, self._held))


class _Couplings(LeafSystem):
    """Reads the plant's state, outputs the couplings' generalized force Cᵀ f of the KKT solve
    (τ = 0) as the plant's applied generalized force — at every stage of every step."""

    def __init__(self, plant: MultibodyPlant, rows: np.ndarray) -> None:
        super().__init__()
        self._plant, self._rows = plant, rows
        self._state = self.DeclareVectorInputPort(
            "state", plant.num_positions() + plant.num_velocities())
        self.DeclareVectorOutputPort("force", plant.num_velocities(), self._calc)
        self._ctx = plant.CreateDefaultContext()
        self._zero = np.zeros(plant.num_velocities())

    def _calc(self, context: Context, output: BasicVector) -> None:
        self._plant.SetPositionsAndVelocities(self._ctx, self._state.Eval(context))
        force = closed(self._plant, self._ctx, self._zero, self._rows)[1]
        output.SetFromVector(self._rows.T @ force)


def simulate(plant: MultibodyPlant, q0: np.ndarray, v0: np.ndarray, *, samples: int,
             period: float, scheme: str, dt: float | None, accuracy: float | None = None,
             caching: bool = True, field: Field | None = None,
             rows: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, Steps]:
    """A Drake simulation of a copy of ``plant`` from (q0, v0), logged every ``period`` for
    ``samples`` periods: fixed step ``dt``, or error-controlled at ``accuracy`` (``dt`` None;
    steps then end at the logging times, so none is longer than ``period``); the field and
    the couplings (``rows``) evaluated on ``plant`` itself. q and v at the logging times."""
    builder = DiagramBuilder()
    copy = cast(MultibodyPlant, plant.Clone())
    builder.AddSystem(copy)
    if field is not None:
        forces = builder.AddSystem(_Field(plant, field))
        builder.Connect(copy.get_state_output_port(), forces.get_input_port(0))
        builder.Connect(forces.get_output_port(0), copy.get_applied_spatial_force_input_port())
    if rows is not None:
        cords = builder.AddSystem(_Couplings(plant, rows))
        builder.Connect(copy.get_state_output_port(), cords.get_input_port(0))
        builder.Connect(cords.get_output_port(0),
                        copy.get_applied_generalized_force_input_port())
    logger = LogVectorOutput(copy.get_state_output_port(), builder, publish_period=period)
    simulator = Simulator(builder.Build())
    root = simulator.get_mutable_context()
    if not caching:
        root.DisableCaching()
    ctx = copy.GetMyMutableContextFromRoot(root)
    if copy.num_actuated_dofs() > 0:  # its actuators at zero control: the dynamics alone
        copy.get_actuation_input_port().FixValue(ctx, np.zeros(copy.num_actuated_dofs()))
    copy.SetPositions(ctx, np.asarray(q0, float))
    copy.SetVelocities(ctx, np.asarray(v0, float))
    integrator = ResetIntegratorFromFlags(simulator, scheme, dt or period)
    if accuracy is not None:
        integrator.set_target_accuracy(accuracy)
    elif scheme == CONTROLLED:  # error-controlled by default: pin it to the step
        integrator.set_fixed_step_mode(True)
        integrator.set_maximum_step_size(dt or period)
    simulator.Initialize()
    simulator.AdvanceTo(samples * period)
    x = np.asarray(logger.FindLog(root).data()).T  # one sample per period
    if x.shape[0] != samples + 1:
        raise EngineError(f"drake logged {x.shape[0]} states for {samples} periods")
    nq = copy.num_positions()
    steps = Steps(taken=integrator.get_num_steps_taken(),
                  shrunk=integrator.get_num_step_shrinkages_from_error_control())
    return x[:, :nq], x[:, nq:], steps
