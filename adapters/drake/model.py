"""A user's model in Drake (optional extra ``drake``), through Drake's own parsers, in a
continuous-time ``MultibodyPlant``.

Drake keeps a URDF's fixed links as welded bodies (lumped here into the moving body they are
welded to) and leaves a URDF's root link floating unless welded: the root is welded to the
world, or with ``--floating`` given a ``QuaternionFloatingJoint`` named ``root_joint``. Drake
names the floating joint of an MJCF ``<freejoint>`` after its body. Joint damping is read back
as a field, then zeroed before ``Finalize`` (Drake applies it in every dynamics call; the check
compares damping-free dynamics in every engine). Drake has no joint armature: rotor inertia
belongs to its actuators, and its MJCF parser turns a joint's ``armature`` into the reflected
inertia (rotor inertia × gear²) of the actuator on that joint — read back here as the joint's
armature; a joint without an actuator keeps none (a hint names the fix).
M = ``CalcMassMatrix``, h = ``CalcBiasTerm`` −
``CalcGravityGeneralizedForces``, forward dynamics the plant's generalized-acceleration
output, inverse ``CalcInverseDynamics`` with gravity from ``CalcForceElementsContribution``.
State layout: a floating joint q = (w, x, y, z, p), v = (ω, v), both in world axes. A ball
joint is a ``BallRpyJoint``: q = (roll, pitch, yaw) of the child frame M in the parent-side
frame F, v = ω_FM in F (measured: the body's world angular velocity equals v when F is the
world).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from pydrake.autodiffutils import AutoDiffXd
from pydrake.multibody.tree import (
    MultibodyForces,
    MultibodyForces_,
)

from dyncheck.adapters.actuators import Actuation
from dyncheck.adapters.base import Field, ModelEngine, Offer, Steps
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.drake import actuators as drake_actuators
from dyncheck.adapters.drake import closures as drake_closures
from dyncheck.adapters.drake import counterfactual
from dyncheck.adapters.drake import simulation as drake_simulation
from dyncheck.adapters.drake.hints import (
    REFUSED_ACTUATOR,
    actuators,
    armature_hint,
    file_hints,
    ignored_frames,
)
from dyncheck.adapters.drake.parsing import ENGINE, plant_of
from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import equalities, inline
from dyncheck.adapters.inertia import lump
from dyncheck.adapters.model_tree import (
    Axes,
    DerivativeChart,
    Derivatives,
    Dynamics,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    TreeJoint,
)
from dyncheck.adapters.model_tree import (
    derivatives as _derivatives,
)
from dyncheck.adapters.registration import Format
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import EngineError, Unsupported

_TYPES = {
    "revolute": JointType.HINGE,
    "prismatic": JointType.SLIDE,
    "quaternion_floating": JointType.FREE,
    "ball_rpy": JointType.BALL,
}


class DrakeModel(ModelEngine):
    """A Drake plant and its neutral tree."""

    engine = ENGINE
    offers = frozenset({Offer.DERIVATIVES, Offer.ACTUATION, Offer.CONTROL_DERIVATIVES,
                        Offer.STEPPING, Offer.CONTROLLED_STEPPING, Offer.COUPLINGS,
                        Offer.BODY_FORCES, Offer.CLOSURES})
    steps_in_a_chart = True  # its integrators advance q = (roll, pitch, yaw) and (w, x, y, z, p)

    def __init__(self, source: ModelFile, *, fixes: bool = True) -> None:
        self._fixes = fixes  # (False: a copy read to measure a fix)
        self.plant, said, notes, self._damping = plant_of(source)
        self.parser_warnings = tuple(dict.fromkeys(said))
        self._source = source
        self._root = inline(source.path) if source.format is Format.MJCF else None
        self.context = self.plant.CreateDefaultContext()
        actuation = self.plant.get_actuation_input_port()
        if self.plant.num_actuated_dofs() > 0:
            actuation.FixValue(self.context, np.zeros(self.plant.num_actuated_dofs()))
        self._acc = self.plant.get_generalized_acceleration_output_port()
        self._ad: Any = None  # the AutoDiffXd plant, made on the first derivatives asked for
        self._actuated: Any = None  # the context of actuation (its PD controllers armed)
        self._rows: np.ndarray | None = None  # the couplings C v = 0 it holds (Drake's order)
        self._ad_actuated: Any = None  # the same for the AutoDiffXd plant
        self._held = drake_closures.Held(closures=())
        self.tree = self._closures(self._tree(notes))

    def _closures(self, tree: ModelTree) -> ModelTree:
        """Its tree with the constraints Drake's parsers hold (:mod:`.closures`: an MJCF's
        read on a discrete-time plant parsed with them, a URDF's ``<mimic>`` joints), or the
        note of why none are read."""
        source, mjcf = self._source, self._root
        if not (source.closed_text if mjcf is None else equalities(mjcf)):
            return tree
        try:
            discrete, said, _, _ = plant_of(source, kept=True)
            self._held = drake_closures.mimics(
                parsing.root(source.closed_text), held=discrete.num_constraints()) \
                if mjcf is None else drake_closures.read(
                    mjcf, held=discrete.num_constraints(), warnings=said, plant=self.plant,
                    context=self.context, owners={self.plant.get_body(body).name(): joint.name()
                                                  for body, joint in self._movers.items()})
        except (Unsupported, EngineError) as exc:
            return replace(tree, notes=(*tree.notes, f"{exc}; its constraints are not read"))
        return replace(tree, closures=self._held.closures, closures_read=True,
                       closures_unheld=self._held.unheld)

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """Its M and h closed by its constraints (:func:`.closures.closed`)."""
        return drake_closures.closed(self.plant, self.context, self._held, q=q, v=v, tau=tau)

    def _tree(self, notes: tuple[str, ...]) -> ModelTree:
        plant, ctx = self.plant, self.context
        q0 = plant.GetPositions(ctx).copy()
        moving = [plant.get_joint(i) for i in plant.GetJointIndices()
                  if plant.get_joint(i).num_velocities() > 0]
        for joint in moving:
            if joint.type_name() not in _TYPES:
                raise Unsupported(
                    f"drake holds joint {joint.name()!r} as a {joint.type_name()} joint, which "
                    "the model check does not map"
                )
        for joint in moving:  # free bodies at the reference pose: the origin, unrotated
            if _TYPES[joint.type_name()] is JointType.FREE:
                q0[joint.position_start() : joint.position_start() + 7] = (1, 0, 0, 0, 0, 0, 0)
        plant.SetPositions(ctx, q0)
        owner_of = {}  # body index → the moving joint whose child group holds it
        for joint in moving:
            for body in plant.GetBodiesWeldedTo(joint.child_body()):
                owner_of[body.index()] = joint
        self._movers = owner_of  # (its closures' bodies are joined to their joints by it)
        joints = []
        reflected = self._reflected
        for joint in moving:
            kind = _TYPES[joint.type_name()]
            group = plant.GetBodiesWeldedTo(joint.child_body())
            masses, coms, inertias, held = [], [], [], 0.0
            for body in group:
                m = body.default_mass()
                p = np.asarray(body.default_com())  # from the body origin, body axes
                pose = body.EvalPoseInWorld(ctx)
                rot = pose.rotation().matrix()
                i_origin = body.default_rotational_inertia().CopyToFullMatrix3()  # about Bo
                i_com = i_origin - m * (p @ p * np.eye(3) - np.outer(p, p))  # parallel axis
                held += abs(float(np.trace(i_origin)))
                masses.append(m)
                coms.append(pose.translation() + rot @ p)
                inertias.append(rot @ i_com @ rot.T)
            mass, com, inertia = lump(masses, coms, inertias)
            parent_joint = owner_of.get(joint.parent_body().index())
            child_pose = joint.frame_on_child().CalcPoseInWorld(ctx)
            if kind is JointType.HINGE:
                axis = joint.frame_on_parent().CalcPoseInWorld(ctx).rotation().matrix() @ \
                    joint.revolute_axis()
            elif kind is JointType.SLIDE:
                axis = joint.frame_on_parent().CalcPoseInWorld(ctx).rotation().matrix() @ \
                    joint.translation_axis()
            else:
                axis = np.zeros(3)
            lower, upper = joint.position_lower_limits(), joint.position_upper_limits()
            limited = kind is not JointType.FREE and np.isfinite(lower[0]) and \
                np.isfinite(upper[0])
            nv = joint.num_velocities()
            joints.append(
                TreeJoint(
                    name=joint.name(), type=kind,
                    parent=None if parent_joint is None else parent_joint.name(),
                    body=joint.child_body().name(), axis=np.asarray(axis, float),
                    anchor=np.asarray(child_pose.translation(), float),
                    frame=child_pose.rotation().matrix(), mass=mass, com=com, inertia=inertia,
                    parts=len(masses), inertia_derived_from=held,
                    armature=(reflected.get(joint.name(), 0.0),) if nv == 1 else (0.0,) * nv,
                    damping=self._damping.get(joint.name(), (0.0,) * nv),
                    range=(float(lower[0]), float(upper[0])) if limited else None,
                    layout=Layout(
                        q_start=joint.position_start(), v_start=joint.velocity_start(),
                        nq=joint.num_positions(), nv=nv,
                        quat=Orientation.RPY if kind is JointType.BALL else Orientation.WXYZ,
                        quat_first=True,
                        angular_first=True, linear_axes=Axes.WORLD,
                        angular_axes=Axes.PARENT if kind is JointType.BALL else Axes.WORLD,
                        zero=float(q0[joint.position_start()]) if nv == 1 else 0.0,
                    ),
                )
            )
        return self._finish(joints, notes, reflected)

    def _finish(self, joints: list[TreeJoint], notes: tuple[str, ...],
                reflected: dict[str, float]) -> ModelTree:
        """The tree of ``joints`` with its hints and actuators, and its hints' fixes measured
        (#77): the servos' kv set on the plant, and each armature hint's fix applied to a copy
        of the MJCF and read."""
        plant = self.plant
        driven = actuators(self._source) if self._source.format is Format.MJCF else {}
        read, measured = drake_actuators.hints(plant, self._source, driven)
        refusal = drake_actuators.multi_dof_refusal()
        armature = tuple((j.name, "armature", armature_hint(j, driven.get(j.name, []), refusal))
                         for j in joints if j.name not in reflected and self._source.format is
                         Format.MJCF)
        measured |= {w for _, _, w in armature if refusal and REFUSED_ACTUATOR.format(
            words=refusal) in w}  # (BALL_ARMATURE: the engine's own refusal)
        hints = armature + ignored_frames(notes) + file_hints(self._source) + read
        tree = ModelTree(engine=ENGINE, joints=tuple(joints),
                         gravity=np.asarray(plant.gravity_field().gravity_vector(), float),
                         nq=plant.num_positions(), nv=plant.num_velocities(), notes=notes,
                         hints=hints, measured=measured, actuators=drake_actuators.read(plant))
        if self._root is None:  # (a URDF)
            return tree
        return counterfactual.measured(
            self._source, self._root, plant, tree, reflected=reflected,
            driven=driven, read=(lambda copy: DrakeModel(copy, fixes=False).tree)
            if self._fixes else None)

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """The couplings closed with Drake's M and h (:mod:`.simulation`: Drake's
        continuous plant enforces no constraint)."""
        self._rows = drake_simulation.coupling_matrix(self.plant, couplings)

    def _at(self, q: np.ndarray, v: np.ndarray) -> Iterator[int]:
        """Each state's index, its plant context set to that state."""
        for i in range(len(q)):
            self.plant.SetPositions(self.context, q[i])
            self.plant.SetVelocities(self.context, v[i])
            yield i

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """v̇ and the multipliers of the couplings' KKT solve, state by state."""
        if self._rows is None:
            raise Unsupported("drake: its model holds no coupling between joints")
        vdot = np.empty((len(q), self.plant.num_velocities()))
        forces = np.empty((len(q), len(self._rows)))
        for i in self._at(q, v):
            vdot[i], forces[i] = drake_simulation.closed(self.plant, self.context, tau[i],
                                                         self._rows)
        return vdot, forces

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ at τ: with couplings, their KKT solve; else M⁻¹ (τ − h)."""
        if self._rows is None:
            return super().forward(q, v, tau)
        return self.constrained(q, v, tau)[0]

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self.constrained(q, v, tau)[1]

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """Σ Jᵀ F of the field at each state (Drake's translational Jacobians)."""
        held = drake_simulation.bodies(self.plant)
        out = np.empty((len(q), self.plant.num_velocities()))
        for i in self._at(q, v):
            out[i] = drake_simulation.generalized(self.plant, self.context, field, held)
        return out

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Drake's own fixed-step integrator (:data:`.simulation.INTEGRATORS`)."""
        q, v, _ = drake_simulation.simulate(
            self.plant, q0, v0, samples=steps, period=dt,
            scheme=drake_simulation.INTEGRATORS[integrator], dt=dt, field=field,
            rows=self._rows)
        return q, v

    def simulate_controlled(self, q0: np.ndarray, v0: np.ndarray, period: float, samples: int,
                            *, accuracy: float, scheme: str | None = None, caching: bool = True,
                            field: Field | None = None) -> tuple[np.ndarray, np.ndarray, Steps]:
        """Drake's error-controlled integration (default ``runge_kutta3``, the Simulator's)."""
        return drake_simulation.simulate(
            self.plant, q0, v0, samples=samples, period=period,
            scheme=scheme or drake_simulation.CONTROLLED, dt=None, accuracy=accuracy,
            caching=caching, field=field, rows=self._rows)

    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """Drake's actuator force and forward dynamics at controls u
        (:func:`drake_actuators.actuation`)."""
        if self._actuated is None:
            self._actuated = self.plant.CreateDefaultContext()
        return drake_actuators.actuation(self.plant, self._actuated, q=q, v=v, u=u)

    def control_derivatives(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Drake's ∂v̇/∂u by automatic differentiation (:mod:`.actuators`)."""
        if self._ad is None:
            self._ad = self.plant.ToAutoDiffXd()
            self._ad_context = self._ad.CreateDefaultContext()
        if self._ad_actuated is None:
            self._ad_actuated = self._ad.CreateDefaultContext()
        return drake_actuators.control_derivatives(self.plant, self._ad, self._ad_actuated, q=q,
                                                   v=v, u=u)

    @property
    def _reflected(self) -> dict[str, float]:
        """Each actuated joint's armature as Drake holds it: the sum of its actuators'
        reflected inertia, rotor inertia × gear ratio²."""
        out: dict[str, float] = {}
        for index in self.plant.GetJointActuatorIndices():
            actuator = self.plant.get_joint_actuator(index)
            name = actuator.joint().name()
            out[name] = out.get(name, 0.0) + float(actuator.default_reflected_inertia())
        return out

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        plant, ctx = self.plant, self.context
        n, nv = len(q), plant.num_velocities()
        mass = np.empty((n, nv, nv))
        bias, forward, inverse = (np.empty((n, nv)) for _ in range(3))
        kinetic, potential = np.empty(n), np.empty(n)
        forces = MultibodyForces(plant)
        for i in self._at(q, v):
            mass[i] = plant.CalcMassMatrix(ctx)
            bias[i] = plant.CalcBiasTerm(ctx) - plant.CalcGravityGeneralizedForces(ctx)
            forward[i] = self._acc.Eval(ctx)
            forces.SetZero()
            plant.CalcForceElementsContribution(ctx, forces)
            inverse[i] = plant.CalcInverseDynamics(ctx, a[i], forces)
            kinetic[i] = plant.CalcKineticEnergy(ctx)
            potential[i] = plant.CalcPotentialEnergy(ctx)
        return Dynamics(mass_matrix=mass, bias=bias, forward=forward, inverse=inverse,
                          kinetic=kinetic, potential=potential)

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        """Forward-mode automatic differentiation (``ToAutoDiffXd``, q and v seeded) of
        ``CalcInverseDynamics`` with gravity (``CalcForceElementsContribution``) at v̇ = a
        for ∂τ/∂q, ∂τ/∂v, and at v̇ = its forward acceleration for the forward derivatives
        through ∂v̇/∂x = −M⁻¹ ∂τ/∂x; ∂v̇/∂τ = M⁻¹ of ``CalcMassMatrix``. With respect to
        Drake's q itself (a quaternion's four entries, roll-pitch-yaw: the chart
        :attr:`DerivativeChart.COORDINATES`)."""
        from pydrake.autodiffutils import ExtractGradient, InitializeAutoDiff

        plant = self.plant
        if self._ad is None:
            self._ad = plant.ToAutoDiffXd()
            self._ad_context = self._ad.CreateDefaultContext()
        ad, ctx = self._ad, self._ad_context
        n, nq, nv = len(q), plant.num_positions(), plant.num_velocities()
        out = {k: np.empty((n, nv, nq if k.endswith("_q") else nv)) for k in
               ("forward_q", "forward_v", "forward_tau", "inverse_q", "inverse_v")}
        forces = MultibodyForces_[AutoDiffXd](ad)
        dynamics = self.dynamics(q, v, np.asarray(a))
        for i in range(n):
            state = np.concatenate([q[i], v[i]]).astype(float)
            seeded = InitializeAutoDiff(state)  # type: ignore[arg-type]  # pydrake's stub
            ad.SetPositions(ctx, seeded[:nq, 0])
            ad.SetVelocities(ctx, seeded[nq:, 0])
            inverse_mass = np.linalg.inv(dynamics.mass_matrix[i])
            for acceleration, key in ((dynamics.forward[i], "forward"), (a[i], "inverse")):
                forces.SetZero()
                ad.CalcForceElementsContribution(ctx, forces)
                tau = ad.CalcInverseDynamics(ctx, np.array([AutoDiffXd(x) for x in
                                                            acceleration]), forces)
                gradient = ExtractGradient(tau)
                d_q, d_v = gradient[:, :nq], gradient[:, nq:]
                if key == "inverse":
                    out["inverse_q"][i], out["inverse_v"][i] = d_q, d_v
                else:
                    out["forward_q"][i] = -inverse_mass @ d_q
                    out["forward_v"][i] = -inverse_mass @ d_v
            out["forward_tau"][i] = inverse_mass
        return _derivatives(out, method="automatic differentiation (AutoDiffXd)",
                            chart=DerivativeChart.COORDINATES)
