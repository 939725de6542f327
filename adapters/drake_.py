"""Drake behind the canonical form: a continuous-time ``MultibodyPlant`` built by Drake's own
MJCF parser from the very file MuJoCo loads.

Drake's names: M = ``CalcMassMatrix``; ``CalcBiasTerm`` is C(q, v) v *without* gravity and
``CalcGravityGeneralizedForces`` returns τ_g, the generalized force *of* gravity, so the
canonical h = C v − τ_g (the sign convention to mind); forward dynamics is the plant's
``generalized_acceleration`` output with τ on the applied-generalized-force input; inverse
dynamics ``CalcInverseDynamics`` with gravity added by ``CalcForceElementsContribution``;
``CalcKineticEnergy``, ``CalcPotentialEnergy``. The external field enters through the
applied-spatial-force input (``ExternallyAppliedSpatialForce`` at the centre of mass).

Integrators (Drake's own, fixed step, by ``ResetIntegratorFromFlags``): ``euler`` is
``semi_explicit_euler`` (v first, then q with the new v: MuJoCo's Euler), ``rk2``
``runge_kutta2`` (order 2), ``rk3`` ``runge_kutta3`` in fixed-step mode (order 3; it is
error-controlled by default). Drake has no classic RK4. :meth:`DrakeAdapter.simulate_controlled`
runs ``runge_kutta3`` error-controlled (Drake's Simulator default) at a target accuracy.
The parser's warnings (what it ignores) are kept in :attr:`DrakeAdapter.parser_warnings`.

Couplings (cords): Drake's MJCF parser ignores ``<tendon>`` and the tendon ``<equality>``
(its own warning), and a continuous-time plant enforces no constraint (Drake's coupler
constraint exists only for a discrete plant solved by SAP, and couples two joints, not the
three of exercise 17). So the cord is closed here, with Drake's own M and h, by the Lagrange
multiplier of the linear constraint C v = 0 (C constant, from the engine-neutral model, as for
``pinocchio-mjcf``): the KKT system

    [M  −Cᵀ] [v̇]   [τ − h]
    [C   0 ] [f ] = [  0  ],

f = −tension; in simulation Cᵀ f enters the plant's applied-generalized-force input, recomputed
from the state at every stage of Drake's integrators.

State (measured, ``dyncheck.adapters.layout``): a ball joint becomes a ``BallRpyJoint`` —
q = (roll, pitch, yaw), v = ω in *world* axes; a free joint a ``QuaternionFloatingJoint`` —
q = (w, x, y, z, p), v = (ω, v) both in world axes. Drake integrates the quaternion's
components (q̇ = ½ q ⊗ ω), so its norm drifts; the comparison layer renormalizes.

Why one module of ~460 lines: one engine behind the adapter interface (the recipe's one
module per engine): loading, the canonical quantities, the cord constraints as a KKT
system, and Drake's own integrators.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput

from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.adapters.drake_model import parser_warnings
from dyncheck.adapters.drake_registration import REGISTRATIONS
from dyncheck.adapters.linalg import kkt
from dyncheck.adapters.mjcf import to_mjcf
from dyncheck.adapters.model_tree import Axes, Layout, Orientation, StateLayout
from dyncheck.cases.multibody import Joint, Multibody
from dyncheck.errors import EngineError
from dyncheck.vocabulary import Integrator

_INTEGRATORS: dict[str, str] = {
    Integrator.EULER: "semi_explicit_euler",
    Integrator.RK2: "runge_kutta2",
    Integrator.RK3: "runge_kutta3",
}
"""dyncheck's name → Drake's scheme name for ``ResetIntegratorFromFlags``."""


class _Field(LeafSystem):
    """Reads the plant's state, outputs the field as externally applied spatial forces —
    evaluated at every stage of every step."""

    def __init__(self, adapter: DrakeAdapter) -> None:
        super().__init__()
        self._a = adapter
        n = adapter.plant.num_positions() + adapter.plant.num_velocities()
        self._state = self.DeclareVectorInputPort("state", n)
        self.DeclareAbstractOutputPort(
            "forces", lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]), self._calc
        )
        self._ctx = adapter.plant.CreateDefaultContext()

    def _calc(self, context, output) -> None:
        x = self._state.Eval(context)
        self._a.plant.SetPositionsAndVelocities(self._ctx, x)
        output.set_value(self._a._field_forces(self._ctx))


@dataclass(frozen=True)
class Steps:
    """A Drake run's step counts: steps taken, and steps shrunk by error control."""

    taken: int
    shrunk: int


class _Cords(LeafSystem):
    """Reads the plant's state, outputs the cords' generalized force Cᵀ f of the KKT solve
    (τ = 0) as the plant's applied generalized force — at every stage of every step."""

    def __init__(self, adapter: DrakeAdapter) -> None:
        super().__init__()
        self._a = adapter
        plant = adapter.plant
        self._state = self.DeclareVectorInputPort(
            "state", plant.num_positions() + plant.num_velocities()
        )
        self.DeclareVectorOutputPort("force", plant.num_velocities(), self._calc)
        self._ctx = plant.CreateDefaultContext()
        self._zero = np.zeros(plant.num_velocities())

    def _calc(self, context, output) -> None:
        self._a.plant.SetPositionsAndVelocities(self._ctx, self._state.Eval(context))
        f = self._a._closed(self._ctx, self._zero)[1]
        output.SetFromVector(self._a._C.T @ f)


class DrakeAdapter(Adapter):
    name: ClassVar[str] = "drake"
    state_layout: ClassVar[StateLayout] = StateLayout(
        ball=Layout.ball(quat=Orientation.RPY, angular_axes=Axes.PARENT),
        free=Layout.free(quat_first=True, angular_first=True, angular_axes=Axes.WORLD))
    """Its MJCF parser makes a ball joint a ``BallRpyJoint`` (ω in world axes) and a free
    joint a ``QuaternionFloatingJoint``, q = (w, x, y, z, p), v = (ω, v) in world axes."""
    package: ClassVar[str] = "drake"
    error_controlled: ClassVar[bool] = True
    integrators: ClassVar[tuple[str, ...]] = REGISTRATIONS["drake"].integrators

    def __init__(self, model: Multibody) -> None:
        super().__init__(model)
        self.xml = to_mjcf(model)
        self.plant, self.parser_warnings = self.parse_xml(self.xml)
        self.context = self.plant.CreateDefaultContext()
        self._bodies = [self.plant.GetBodyByName(b.name) for b in model.bodies]
        # the field's constants, read once (:meth:`_field_forces` runs at every stage): each
        # body's mass, centre of mass in its frame, Drake body and frame; the world frame
        self._world = self.plant.world_frame()
        self._field_bodies = [
            (b.mass, np.asarray(b.com, float), body, body.body_frame())
            for b, body in zip(model.bodies, self._bodies, strict=True)
        ]
        # engine coordinates in the spec's joint order; Drake orders its own
        joints = [self._joint(b.name, j) for b in model.bodies for j in b.joints]
        self._iq = np.concatenate(
            [np.arange(j.position_start(), j.position_start() + j.num_positions()) for j in joints]
        )
        self._iv = np.concatenate(
            [np.arange(j.velocity_start(), j.velocity_start() + j.num_velocities()) for j in joints]
        )
        self._ivv = np.ix_(self._iv, self._iv)  # the mass matrix's rows and columns (per state)
        self._native = np.array_equal(self._iq, np.arange(self.plant.num_positions())) and (
            np.array_equal(self._iv, np.arange(self.plant.num_velocities()))
        )
        """Drake's coordinates are the spec's, in its order: states pass as they are (a batch's
        per-state cost is its numpy calls around the engine's)."""
        self._tau_port = self.plant.get_applied_generalized_force_input_port()
        self._force_port = self.plant.get_applied_spatial_force_input_port()
        self._acc_port = self.plant.get_generalized_acceleration_output_port()
        self._force_port.FixValue(self.context, [])  # the field, if any, is set per state
        self._C = None  # the cords' rows in Drake's velocity order
        if model.couplings:
            self._C = np.zeros((len(model.couplings), self.plant.num_velocities()))
            self._C[:, self._iv] = model.coupling_matrix()

    def _joint(self, body: str, joint: Joint):
        """Drake's joint for a spec joint; a free joint is the body's floating joint, which
        Drake's parser names after the body, not after the MJCF freejoint."""
        if joint.type != "free":
            return self.plant.GetJointByName(joint.name)
        plant = self.plant
        for index in plant.GetJointIndices():
            candidate = plant.get_joint(index)
            if candidate.child_body().name() == body and candidate.num_velocities() == 6:
                return candidate
        raise EngineError(f"drake: no floating joint for body {body!r}")

    @staticmethod
    def parse_xml(xml: str, time_step: float = 0.0) -> tuple[MultibodyPlant, list[str]]:
        plant = MultibodyPlant(time_step)
        with parser_warnings() as warnings:
            Parser(plant).AddModelsFromString(xml, "xml")
        plant.Finalize()
        return plant, warnings

    @staticmethod
    def version() -> str:
        from importlib.metadata import version

        return version("drake")

    def loaded_bodies(self) -> list[LoadedBody]:
        out = []
        for spec, body in zip(self.spec.bodies, self._bodies, strict=True):
            m = body.default_mass()
            c = np.asarray(body.default_com())
            I_o = body.default_rotational_inertia().CopyToFullMatrix3()  # about the origin
            I_c = I_o - m * (c @ c * np.eye(3) - np.outer(c, c))  # parallel-axis theorem
            out.append(LoadedBody(spec.name, float(m), I_c))
        return out

    def loaded_gravity(self) -> np.ndarray:
        return np.asarray(self.plant.gravity_field().gravity_vector())

    # --- state and the field ---------------------------------------------------------------

    def _set(self, q: np.ndarray, v: np.ndarray | None = None) -> None:
        qd = np.zeros(self.plant.num_positions())
        vd = np.zeros(self.plant.num_velocities())
        qd[self._iq] = q
        if v is not None:
            vd[self._iv] = v
        self.plant.SetPositions(self.context, qd)
        self.plant.SetVelocities(self.context, vd)

    def _field_forces(self, context) -> list[ExternallyAppliedSpatialForce]:
        out = []
        if not self.spec.central_mu:
            return out
        points, world = self.plant.CalcPointsPositions, self._world
        for mass, com, body, frame in self._field_bodies:
            p = points(context, frame, com, world)[:, 0]
            f = ExternallyAppliedSpatialForce()
            f.body_index = body.index()
            f.p_BoBq_B = com
            f.F_Bq_W = SpatialForce(np.zeros(3), self.spec.central_force(mass, p))
            out.append(f)
        return out

    def _field_generalized(self) -> np.ndarray:
        """Jᵀ F of the field at the current state, spec joint order."""
        tau = np.zeros(self.plant.num_velocities())
        if not self.spec.central_mu:
            return tau[self._iv]
        world = self.plant.world_frame()
        for f, body in zip(self._field_forces(self.context), self._bodies, strict=True):
            J = self.plant.CalcJacobianTranslationalVelocity(
                self.context, JacobianWrtVariable.kV, body.body_frame(), f.p_BoBq_B, world, world
            )
            tau += J.T @ f.F_Bq_W.translational()
        return tau[self._iv]

    # --- the cords ---------------------------------------------------------------------------

    def _closed(self, context, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """v̇ and the multipliers f of the KKT solve at the context's state (Drake's full
        velocity order): Drake's M and h, the cords' constant C."""
        return kkt(
            self.plant.CalcMassMatrix(context),
            tau
            - self.plant.CalcBiasTerm(context)
            + self.plant.CalcGravityGeneralizedForces(context),
            self._C,
        )

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty((len(q), self._C.shape[0]))
        t = np.zeros(self.plant.num_velocities())
        for k in range(len(q)):
            self._set(q[k], v[k])
            t[self._iv] = tau[k]
            out[k] = self._closed(self.context, t)[1]
        return self._check("constraint force", out)

    # --- the canonical form ----------------------------------------------------------------

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((len(q), len(self._iv), len(self._iv)))
        for k in range(len(q)):
            self._set(q[k])
            out[k] = self.plant.CalcMassMatrix(self.context)[self._ivv]
        return self._check("mass matrix", out)

    def _h(self) -> np.ndarray:
        ctx = self.context
        return self.plant.CalcBiasTerm(ctx) - self.plant.CalcGravityGeneralizedForces(ctx)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.empty_like(q, dtype=float)
        for k in range(len(q)):
            self._set(q[k], v[k])
            out[k] = self._h()[self._iv]
        return self._check("bias forces", out)

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty_like(q, dtype=float)
        for k in range(len(q)):
            self._set(q[k], v[k])
            t = np.zeros(self.plant.num_velocities())
            t[self._iv] = tau[k]
            if self._C is not None:
                out[k] = self._closed(self.context, t)[0][self._iv]
                continue
            self._tau_port.FixValue(self.context, t)
            self._force_port.FixValue(self.context, self._field_forces(self.context))
            out[k] = self._acc_port.Eval(self.context)[self._iv]
        return self._check("forward dynamics", out)

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        out = np.empty_like(q, dtype=float)
        forces = MultibodyForces(self.plant)
        for k in range(len(q)):
            self._set(q[k], v[k])
            forces.SetZero()
            self.plant.CalcForceElementsContribution(self.context, forces)  # gravity
            vdot = np.zeros(self.plant.num_velocities())
            vdot[self._iv] = a[k]
            tau = self.plant.CalcInverseDynamics(self.context, vdot, forces)[self._iv]
            out[k] = tau - self._field_generalized()
        return self._check("inverse dynamics", out)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.empty(len(q))
        for k in range(len(q)):
            self._set(q[k], v[k])
            out[k] = self.plant.CalcKineticEnergy(self.context)
        return self._check("kinetic energy", out)

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        out = np.empty(len(q))
        for k in range(len(q)):
            self._set(q[k])
            out[k] = self.plant.CalcPotentialEnergy(self.context)
        return self._check("potential energy", out)

    def evaluate_all(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """One pass over the states: the state is set once per state for all six quantities."""
        plant, ctx = self.plant, self.context
        n, nv = v.shape
        iv = self._iv
        M = np.empty((n, nv, nv))
        bias, fwd, inv = np.empty((n, nv)), np.empty((n, nv)), np.empty((n, nv))
        kin, pot = np.empty(n), np.empty(n)
        forces = MultibodyForces(plant)
        t_full = np.zeros(plant.num_velocities())
        vdot = np.zeros(plant.num_velocities())
        field = bool(self.spec.central_mu)
        coupled = self._C is not None
        force = np.empty((n, self._C.shape[0])) if coupled else None
        native = self._native
        gravity = np.empty((n, nv))  # h = bias term − gravity (:meth:`_h`), subtracted at once
        # the plant's methods and ports bound once (a state costs ~20 µs; the lookups ~1 µs)
        set_q, set_v, calc_m = plant.SetPositions, plant.SetVelocities, plant.CalcMassMatrix
        calc_c, calc_g = plant.CalcBiasTerm, plant.CalcGravityGeneralizedForces
        fix_tau, eval_acc = self._tau_port.FixValue, self._acc_port.Eval
        elements, calc_inverse = plant.CalcForceElementsContribution, plant.CalcInverseDynamics
        calc_kin, calc_pot = plant.CalcKineticEnergy, plant.CalcPotentialEnergy
        for k in range(n):
            if native:
                set_q(ctx, q[k])
                set_v(ctx, v[k])
                M[k] = calc_m(ctx)
                bias[k], gravity[k] = calc_c(ctx), calc_g(ctx)
                t_full = tau[k]
            else:
                self._set(q[k], v[k])
                M[k] = calc_m(ctx)[self._ivv]
                bias[k], gravity[k] = calc_c(ctx)[iv], calc_g(ctx)[iv]
                t_full[iv] = tau[k]
            if coupled:
                acc, force[k] = self._closed(ctx, t_full)
                fwd[k] = acc if native else acc[iv]
            else:
                fix_tau(ctx, t_full)
                if field:
                    self._force_port.FixValue(ctx, self._field_forces(ctx))
                vdot_now = np.asarray(eval_acc(ctx))
                fwd[k] = vdot_now if native else vdot_now[iv]
            forces.SetZero()
            elements(ctx, forces)
            if native:
                inv[k] = calc_inverse(ctx, a[k], forces)
            else:
                vdot[iv] = a[k]
                inv[k] = calc_inverse(ctx, vdot, forces)[iv]
            if field:
                inv[k] -= self._field_generalized()
            kin[k] = calc_kin(ctx)
            pot[k] = calc_pot(ctx)
        bias -= gravity
        return self._outputs(M, bias, fwd, inv, kin, pot, force)

    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        steps = round(duration / dt)
        traj, _ = self._run(q0, v0, steps, dt, _INTEGRATORS[integrator], dt)
        return traj

    def simulate_controlled(
        self,
        q0: np.ndarray,
        v0: np.ndarray,
        duration: float,
        grid: float,
        accuracy: float,
        scheme: str = "runge_kutta3",
        caching: bool = True,
    ) -> tuple[Trajectory, Steps]:
        """An error-controlled run at ``accuracy``, sampled every ``grid`` seconds, and its
        step counts. Default: ``runge_kutta3``, the Simulator's default integrator (a
        3rd-order solution propagated, the embedded 2nd-order midpoint as error estimate);
        ``caching=False`` disables the context's cache (which must not change results)."""
        return self._run(
            q0, v0, round(duration / grid), grid, scheme, None, accuracy, caching=caching
        )

    def _run(
        self,
        q0: np.ndarray,
        v0: np.ndarray,
        samples: int,
        period: float,
        scheme: str,
        dt: float | None,
        accuracy: float | None = None,
        caching: bool = True,
    ) -> tuple[Trajectory, Steps]:
        """A Drake simulation from (q0, v0), logged every ``period`` for ``samples`` periods:
        fixed step ``dt``, or error-controlled at ``accuracy`` (``dt`` None; steps then end at
        the logging times, so none is longer than ``period``)."""
        builder = DiagramBuilder()
        plant = builder.AddSystem(self.parse_xml(self.xml)[0])
        if self.spec.central_mu:
            field = builder.AddSystem(_Field(self))
            builder.Connect(plant.get_state_output_port(), field.get_input_port(0))
            builder.Connect(field.get_output_port(0), plant.get_applied_spatial_force_input_port())
        if self._C is not None:
            cord = builder.AddSystem(_Cords(self))
            builder.Connect(plant.get_state_output_port(), cord.get_input_port(0))
            builder.Connect(
                cord.get_output_port(0), plant.get_applied_generalized_force_input_port()
            )
        logger = LogVectorOutput(plant.get_state_output_port(), builder, publish_period=period)
        diagram = builder.Build()
        simulator = Simulator(diagram)
        root = simulator.get_mutable_context()
        if not caching:
            root.DisableCaching()
        ctx = plant.GetMyMutableContextFromRoot(root)
        qd = np.zeros(plant.num_positions())
        vd = np.zeros(plant.num_velocities())
        qd[self._iq], vd[self._iv] = q0, v0
        plant.SetPositions(ctx, qd)
        plant.SetVelocities(ctx, vd)
        integ = ResetIntegratorFromFlags(simulator, scheme, dt or period)
        if accuracy is not None:
            integ.set_target_accuracy(accuracy)
        elif scheme == "runge_kutta3":  # error-controlled by default: pin it to the step
            integ.set_fixed_step_mode(True)
            integ.set_maximum_step_size(dt)
        simulator.Initialize()
        simulator.AdvanceTo(samples * period)
        x = logger.FindLog(root).data().T  # one sample per period
        if x.shape[0] != samples + 1:
            raise EngineError(f"drake logged {x.shape[0]} states for {samples} periods")
        nq = plant.num_positions()
        qs, vs = x[:, :nq][:, self._iq], x[:, nq:][:, self._iv]
        t = np.arange(samples + 1) * period
        steps = Steps(
            integ.get_num_steps_taken(), integ.get_num_step_shrinkages_from_error_control()
        )
        return Trajectory(t, self._check("simulate", qs), vs), steps

    def raw_calls(self, qe: np.ndarray, ve: np.ndarray, te: np.ndarray,
                  ae: np.ndarray) -> Callable[[], None] | None:
        from pydrake.multibody.tree import MultibodyForces

        plant, ctx = self.plant, self.context
        tau_port = plant.get_applied_generalized_force_input_port()
        acc_port = plant.get_generalized_acceleration_output_port()
        forces = MultibodyForces(plant)

        def loop() -> None:
            for k in range(len(qe)):
                plant.SetPositions(ctx, qe[k])
                plant.SetVelocities(ctx, ve[k])
                plant.CalcMassMatrix(ctx)
                plant.CalcBiasTerm(ctx)
                plant.CalcGravityGeneralizedForces(ctx)
                tau_port.FixValue(ctx, te[k])
                acc_port.Eval(ctx)
                forces.SetZero()
                plant.CalcForceElementsContribution(ctx, forces)
                plant.CalcInverseDynamics(ctx, ae[k], forces)
                plant.CalcKineticEnergy(ctx)
                plant.CalcPotentialEnergy(ctx)

        return loop

