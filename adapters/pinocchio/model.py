"""A user's model in Pinocchio, through Pinocchio's own parsers (``buildModelFromMJCF``,
``buildModelFromXML`` for URDF text; ``--floating`` gives the URDF root a
``JointModelFreeFlyer``, as Pinocchio's users do).

M = ``crba`` (armature included; upper triangle mirrored), h = ``rnea(q, v, 0)``, forward
dynamics ``aba`` at τ = 0, inverse ``rnea``, ``computeKineticEnergy``,
``computePotentialEnergy``. Whether the kinetic energy counts a coordinate's rotor energy
½ a q̇² is measured at load (:func:`_rotor_in_kinetic`): Pinocchio 4.1 adds it from each
joint's ``joint_v``, which ``JointModelRevoluteUnaligned`` leaves at zero. A composite joint
(the MJCF parser's for a body with several joints) is read back component by component.
Pinocchio applies no damping: its ``model.damping`` is read back as a field only. State
layout: quaternions (x, y, z, w); a free joint v = (linear, angular), both in local axes; an
unbounded revolute joint q = (cos θ, sin θ).

In a book case's run (``dyncheck run``) the same loader answers forward dynamics at τ
(``aba``), the cords (constrained ``forwardDynamics`` with their constant Jacobian), a field
(Pinocchio's external forces) and trajectories (:mod:`.simulation`: MuJoCo's
integrators' definitions and scipy's DOP853 on its forward dynamics).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import ClassVar

import numpy as np
import pinocchio as pin

from dyncheck.adapters.base import Field, ModelEngine, Offer
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.formats.edits import fixed_copy
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.formats.mjcf_copy import utf8_file
from dyncheck.adapters.model_tree import (
    Axes,
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
from dyncheck.adapters.pinocchio import closures, counterfactual, mimic, mjcf
from dyncheck.adapters.pinocchio.simulation import Stepping
from dyncheck.adapters.registration import Format
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import EngineError, Unsupported
from dyncheck.vocabulary import Integrator

ENGINE = "pinocchio"
_HINGE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")
_HINGE_UNBOUNDED = (
    "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned",
)
_SLIDE = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")


def _type(shortname: str) -> JointType:
    if shortname in _HINGE or shortname in _HINGE_UNBOUNDED:
        return JointType.HINGE
    if shortname in _SLIDE:
        return JointType.SLIDE
    if shortname == "JointModelSpherical":
        return JointType.BALL
    if shortname == "JointModelFreeFlyer":
        return JointType.FREE
    raise Unsupported(f"pinocchio joint type {shortname} is not checked")


def _load(source: ModelFile) -> pin.Model:
    try:
        if source.format is Format.MJCF:
            with utf8_file(source.path) as file:
                return pin.buildModelFromMJCF(str(file))
        if source.floating:
            return pin.buildModelFromXML(source.text, pin.JointModelFreeFlyer())
        return pin.buildModelFromXML(source.text)
    except Exception as exc:
        text = str(exc).strip()
        # Pinocchio's C++ exceptions: "From file: … in function: … message:\n<the reason>"
        text = text.split("message:", 1)[1] if "message:" in text else text
        message = " ".join(text.split()) or type(exc).__name__
        if source.format is Format.MJCF:
            message = counterfactual.refusal(source, message)
        raise EngineError(f"pinocchio refused {source.path}: {message}") from None


def _rotor_in_kinetic(m: pin.Model, q0: np.ndarray) -> dict[int, bool]:
    """For each velocity index with armature: whether ``computeKineticEnergy`` counts its
    rotor energy, measured at ``q0`` with that coordinate alone moving at unit speed (the
    engine's T minus its bodies' energy ½ Σ vᵢ·Iᵢ vᵢ is ½ a or 0)."""
    d = m.createData()
    out = {}
    for index in np.flatnonzero(m.armature):
        v = np.zeros(m.nv)
        v[index] = 1.0
        total = pin.computeKineticEnergy(m, d, q0, v)
        bodies = 0.5 * sum(float(d.v[k].vector @ (m.inertias[k].matrix() @ d.v[k].vector))
                           for k in range(1, m.njoints))
        rotor = 0.5 * float(m.armature[index])
        out[int(index)] = abs(total - bodies - rotor) < abs(total - bodies)
    return out


def _axis(kind: JointType, d: pin.Data, i: int, v_offset: int) -> np.ndarray:
    """A hinge's or slide's unit axis in world axes: its column of joint ``i``'s motion
    subspace S (a composite joint's columns are its components', all in its last frame)."""
    if kind not in (JointType.HINGE, JointType.SLIDE):
        return np.zeros(3)
    column = np.asarray(d.joints[i].S).reshape(6, -1)[:, v_offset]
    local = column[3:] if kind is JointType.HINGE else column[:3]
    return np.asarray(d.oMi[i].rotation @ local, float)


def _components(m: pin.Model, d: pin.Data, i: int) -> list[tuple]:
    """Joint ``i`` as (name, shortname, world pose of the joint frame, q start, v start, nq,
    nv) for each of its components: itself, or a composite joint's components in order
    (Pinocchio's MJCF parser makes one of a body's several joints), named
    ``<composite>[k]`` — the model check matches them to another engine's joints by body
    and order."""
    jm = m.joints[i]
    if jm.shortname() != "JointModelComposite":
        return [(m.names[i], jm.shortname(), d.oMi[i], jm.idx_q, jm.idx_v, jm.nq, jm.nv)]
    composite, data = jm.extract(), d.joints[i].extract()
    out, q_at, v_at = [], jm.idx_q, jm.idx_v
    for k, part in enumerate(composite.joints):
        pose = d.oMi[i] * data.iMlast[k].inverse() * composite.jointPlacements[k]
        out.append((f"{m.names[i]}[{k}]", part.shortname(), pose, q_at, v_at, part.nq,
                    part.nv))
        q_at, v_at = q_at + part.nq, v_at + part.nv
    return out


def _held_bodies(m: pin.Model) -> dict[str, int]:
    """Each moving body's name → the joint that carries it: the first body frame of each
    joint (a body welded to another shares its joint, whose inertia holds both)."""
    out: dict[int, str] = {}
    for frame in m.frames:
        if frame.type == pin.FrameType.BODY and frame.parentJoint > 0:
            out.setdefault(int(frame.parentJoint), frame.name)
    return {name: j for j, name in out.items()}


def _stated_inertias(m: pin.Model, inertias: Mapping[str, np.ndarray]) -> None:
    """Each named body's rotational inertia about its centre of mass set as given (body axes),
    its mass and centre kept: what a format floors (MJCF's point masses) held exactly."""
    frames = [f for f in m.frames if f.type == pin.FrameType.BODY]
    for name, tensor in inertias.items():
        frame = next((f for f in frames if f.name == name), None)
        if frame is None or frame.parentJoint == 0:
            raise Unsupported(f"pinocchio: no moving body {name!r} to give an inertia")
        if sum(f.parentJoint == frame.parentJoint for f in frames) > 1:
            raise Unsupported(f"pinocchio: body {name!r} shares its joint with a welded body")
        held = m.inertias[frame.parentJoint]
        rotation = frame.placement.rotation
        m.inertias[frame.parentJoint] = pin.Inertia(
            held.mass, held.lever, rotation @ np.asarray(tensor, float) @ rotation.T)


ABOUT_ORIGIN = ("forward_q", "forward_v", "forward_tau")
"""Pinocchio's ``computeABADerivatives`` runs in world axes: its M⁻¹ and ∂v̇/∂q, ∂v̇/∂v lose
digits as (X/ℓ)² far from the origin (measured on a double pendulum, ℓ = 2 m: M⁻¹ against
the inverse of ``crba``'s M, 3e-15 at the origin, 5.6e-10 at 1 km, 7.7e-4 at 1000 km)."""


class PinocchioModel(ModelEngine):
    """A Pinocchio model and its neutral tree. Options (the run's, :mod:`dyncheck.case_engine`):
    ``gravity`` as the model's (its MJCF parser reads none), ``inertias`` (body name → its
    rotational inertia about its centre of mass, body axes) in place of the file's: the
    book's point masses exact; ``fixes``: read a copy with each hint's fix applied
    (:attr:`ModelTree.fixed`).

    It has no time integrator: :mod:`.simulation` steps its forward dynamics by
    MuJoCo's integrators' definitions and scipy's DOP853."""

    engine = ENGINE
    offers = frozenset({Offer.DERIVATIVES, Offer.FORWARD, Offer.STEPPING, Offer.SOLVING,
                        Offer.COUPLINGS, Offer.BODY_FORCES, Offer.CLOSURES,
                        Offer.CLOSED_DERIVATIVES})
    definitions: ClassVar[Mapping[str, str]] = {Integrator.IMPLICITFAST: Integrator.EULER}
    """Its ``implicitfast`` is ``euler``: it applies no damping and has no actuators (D = 0,
    :mod:`.integrators`)."""

    def __init__(self, source: ModelFile, *, gravity: np.ndarray | None = None,
                 inertias: Mapping[str, np.ndarray] | None = None,
                 fixes: bool = True) -> None:
        self.model = _load(source)
        self._closures_read = True
        self._mimics, unread = self._mimic_joints(source)
        try:
            self._held = closures.from_file(source, self.model)
        except Unsupported as exc:
            self._held, self._closures_read = [], False
            unread += (f"{exc}; its constraints are not read",)
        if gravity is not None:
            self.model.gravity = pin.Motion(np.asarray(gravity, float), np.zeros(3))
        _stated_inertias(self.model, inertias or {})
        self.data = self.model.createData()
        self._rows: np.ndarray | None = None
        notes: tuple[str, ...] = ()
        held = frozenset(f.name for f in self.model.frames if f.type == pin.FrameType.BODY)
        root = inline(source.path) if source.format is Format.MJCF else None
        self._unheld = closures.unheld(root, self._held)
        found = mjcf.found(source, root, held)
        self._hints = mjcf.hints(found)
        if source.floating and source.format is Format.URDF:
            notes = ("pinocchio: JointModelFreeFlyer 'root_joint' at the URDF root",)
        notes += unread
        self.tree = self._tree(notes)
        if root is not None:  # each hint measured: its prediction, its fix on a copy (#77)
            edits = mjcf.fixes(found) if fixes else ()
            self.tree = replace(
                self.tree, wants_compiled=mjcf.wants_compiled(found),
                measured=counterfactual.predictions_met(self.tree, root),
                with_fixes=fixed_copy(source, root, [f.edit for f in edits]),
                fixed=counterfactual.fixed_readings(
                    source, root, edits, lambda copy, g: PinocchioModel(
                        copy, gravity=g, inertias=inertias, fixes=False).tree) if fixes else ())
        self.stepping = self._stepper()  # its v̇ in MuJoCo's layout, and its runs there

    def _mimic_joints(self, source: ModelFile) -> tuple[mimic.Mimics | None, tuple[str, ...]]:
        """A URDF's ``<mimic>`` joints as Pinocchio's parser builds them (:mod:`.mimic`), or
        the note of its refusal (its constraints then not read)."""
        if not source.closed_text:
            return None, ()
        try:
            return mimic.load(source.closed_text, self.model, floating=source.floating), ()
        except Unsupported as exc:
            self._closures_read = False
            return None, (f"{exc}; its constraints are not read",)

    def _stepper(self) -> Stepping:
        """Its stepping in MuJoCo's layout (:mod:`.simulation`)."""
        joints = sorted(self.tree.joints, key=lambda j: j.layout.q_start)
        held = [(name, j, np.array(self.model.inertias[j].lever))
                for name, j in _held_bodies(self.model).items()]
        return Stepping(self.model, self.data, [str(j.type) for j in joints], held=held,
                        rows=self._rows)

    def _steppable(self) -> Stepping:
        """Its stepping, refused where a joint's coordinates are not MuJoCo's in another
        order (an unbounded revolute joint's (cos θ, sin θ))."""
        unbounded = [j.name for j in self.tree.joints if j.layout.cos_sin]
        if unbounded:
            raise Unsupported(f"pinocchio: dyncheck steps no unbounded revolute joint "
                              f"(cos θ, sin θ): {', '.join(unbounded)}")
        return self.stepping

    def _tree(self, notes: tuple[str, ...]) -> ModelTree:
        m, d = self.model, self.data
        configurations = {c.key(): c.data() for c in m.referenceConfigurations}
        # MJCF: the file's pose (a joint's ``ref`` included) is Pinocchio's "qpos0".
        q0 = np.array(configurations.get("qpos0", pin.neutral(m)), float)
        for i in range(1, m.njoints):  # free bodies at the reference pose: origin, unrotated
            if m.joints[i].shortname() == "JointModelFreeFlyer":
                place = m.jointPlacements[i]
                q0[m.joints[i].idx_q : m.joints[i].idx_q + 7] = pin.SE3ToXYZQUAT(place.inverse())
        counted = _rotor_in_kinetic(m, q0)
        pin.forwardKinematics(m, d, q0)
        bodies = {f.parentJoint: f.name for f in reversed(list(m.frames))
                  if f.type == pin.FrameType.BODY}
        summed = Counter(f.parentJoint for f in m.frames if f.type == pin.FrameType.BODY)
        joints: list[TreeJoint] = []
        last_name: dict[int, str] = {}  # Pinocchio joint → the name of its last component
        for i in range(1, m.njoints):
            parent = int(m.parents[i])
            parent_name = last_name.get(parent)
            parts = _components(m, d, i)
            for k, (name, short, pose, q_at, v_at, nq, nv) in enumerate(parts):
                kind = _type(short)
                rotation, origin = pose.rotation, pose.translation
                last = k == len(parts) - 1
                inertia = m.inertias[i]
                dofs = slice(v_at, v_at + nv)
                lower, upper = m.lowerPositionLimit[q_at], m.upperPositionLimit[q_at]
                limited = (
                    kind in (JointType.HINGE, JointType.SLIDE) and nq == 1
                    and np.isfinite(lower) and np.isfinite(upper)
                    and abs(lower) < 1e10 and abs(upper) < 1e10  # Pinocchio's "no limit": ±max
                )
                joints.append(
                    TreeJoint(
                        name=name, type=kind, parent=parent_name,
                        body=bodies.get(i, m.names[i]),
                        axis=_axis(kind, d, i, v_at - m.joints[i].idx_v), anchor=origin.copy(),
                        frame=rotation.copy(),
                        mass=float(inertia.mass) if last else 0.0,
                        com=d.oMi[i].act(inertia.lever).copy() if last else np.zeros(3),
                        inertia=(d.oMi[i].rotation @ inertia.inertia @ d.oMi[i].rotation.T
                                 if last else np.zeros((3, 3))),
                        parts=max(summed[i], 1) if last else 1,
                        armature=tuple(float(x) for x in m.armature[dofs]),
                        damping=tuple(float(x) for x in m.damping[dofs]),
                        range=(float(lower), float(upper)) if limited else None,
                        layout=Layout(
                            q_start=q_at, v_start=v_at, nq=nq, nv=nv, quat=Orientation.XYZW,
                            linear_axes=Axes.LOCAL, angular_axes=Axes.LOCAL,
                            cos_sin=short in _HINGE_UNBOUNDED,
                            zero=float(q0[q_at]) if nq == 1 else 0.0,
                            placement=np.asarray(m.jointPlacements[i].homogeneous, float),
                        ),
                        rotor_in_kinetic=counted.get(v_at, True),
                    )
                )
                parent_name = name
            last_name[i] = parent_name or ""
        left_out = [j.name for j in joints if not j.rotor_in_kinetic]
        if left_out:
            notes = (*notes, "pinocchio: computeKineticEnergy leaves out the rotor energy "
                     "½ a q̇² of " + ", ".join(left_out) + " (measured; its M holds their "
                     "armature): Pinocchio 4.1 adds ½ a q̇² from each joint's joint_v, which "
                     "JointModelRevoluteUnaligned does not set")
        return ModelTree(
            engine=ENGINE, joints=tuple(joints), gravity=np.asarray(m.gravity.linear, float),
            nq=m.nq, nv=m.nv, notes=notes, hints=self._hints,
            closures=closures.read(self._held, d, {i: n for i, n in last_name.items() if n})
            + mimic.read(self._mimics), closures_read=self._closures_read,
            closures_unheld=self._unheld)

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        m, d = self.model, self.data
        n, nv = len(q), m.nv
        mass = np.empty((n, nv, nv))
        bias, forward, inverse = (np.empty((n, nv)) for _ in range(3))
        kinetic, potential = np.empty(n), np.empty(n)
        zero = np.zeros(nv)
        for i in range(n):
            upper = pin.crba(m, d, q[i])
            mass[i] = np.triu(upper) + np.triu(upper, 1).T
            bias[i] = pin.rnea(m, d, q[i], v[i], zero)
            forward[i] = pin.aba(m, d, q[i], v[i], zero)
            inverse[i] = pin.rnea(m, d, q[i], v[i], a[i])
            kinetic[i] = pin.computeKineticEnergy(m, d, q[i], v[i])
            potential[i] = pin.computePotentialEnergy(m, d, q[i])
        return Dynamics(
            mass_matrix=mass, bias=bias, forward=forward, inverse=inverse,
            kinetic=kinetic, potential=potential,
        )

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        """``computeABADerivatives`` at τ = 0 (∂v̇/∂q, ∂v̇/∂v, M⁻¹, upper triangle mirrored)
        and ``computeRNEADerivatives`` at v̇ = a (∂τ/∂q, ∂τ/∂v): analytic, in Pinocchio's
        tangent space (a hinge's or slide's: its coordinate). On a model with a composite
        joint (an MJCF body with several joints) Pinocchio 4.1's analytic derivatives differ
        from its own finite differences in the columns of the joint's coordinates past its
        first (measured, ``dyncheck explain pinocchio-composite-derivatives``): the defect is
        declared and its own finite differences of ``rnea`` and ``aba`` are handed with them
        (:func:`own_differences`)."""
        m, d = self.model, self.data
        composite = [m.names[i] for i in range(1, m.njoints)
                     if m.joints[i].shortname() == "JointModelComposite"]
        n, nv = len(q), m.nv
        out = {k: np.empty((n, nv, nv)) for k in
               ("forward_q", "forward_v", "forward_tau", "inverse_q", "inverse_v")}
        zero = np.zeros(nv)
        for i in range(n):
            pin.computeABADerivatives(m, d, q[i], v[i], zero)
            out["forward_q"][i], out["forward_v"][i] = d.ddq_dq, d.ddq_dv
            upper = np.asarray(d.Minv)
            out["forward_tau"][i] = np.triu(upper) + np.triu(upper, 1).T
            pin.computeRNEADerivatives(m, d, q[i], v[i], a[i])
            out["inverse_q"][i], out["inverse_v"][i] = d.dtau_dq, d.dtau_dv
        found = replace(_derivatives(out, method="analytic (computeABADerivatives, "
                                     "computeRNEADerivatives)"), about_origin=ABOUT_ORIGIN)
        if not composite:
            return found
        return replace(found, own_differences=own_differences(m, d, q, v, a, out["forward_tau"]),
                       defect=f"pinocchio {pin.__version__}'s analytic derivatives of a "
                       f"composite joint ({composite[0]!r}: a body with several joints) differ "
                       "from its own finite differences, an engine defect (`dyncheck explain "
                       "pinocchio-composite-derivatives`)")

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ at τ: ``aba``; with couplings their KKT solve (``forwardDynamics``)."""
        out = np.empty((len(q), self.model.nv))
        for i in range(len(q)):
            out[i] = self.stepping.accelerate(q[i], v[i], tau[i])
        return out

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """Its constrained dynamics on the file's constraints (:func:`.closures.closed`)."""
        if self._mimics is not None:
            return mimic.closed(self._mimics, self.model.nv, q, v, tau=tau)
        return closures.closed(self.model, self._held, q, v, tau=tau)

    def closed_derivatives(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Its own derivatives of its constrained dynamics (:func:`.closures.derivatives`)."""
        if self._mimics is not None:
            return mimic.derivatives(self._mimics, self.model.nv, q, v, tau=tau)
        return closures.derivatives(self.model, self._held, q, v, tau=tau)

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """The couplings as the constant Jacobian C of Pinocchio's constrained forward
        dynamics (its MJCF parser drops a tendon equality: ``dyncheck explain
        pinocchio-mjcf-equality``), its joints named as in the file."""
        rows = np.zeros((len(couplings), self.model.nv))
        names = {j.name: j for j in self.tree.joints}
        for k, coupling in enumerate(couplings):
            for name, coefficient in coupling.coefs:
                if name not in names:
                    raise Unsupported(f"pinocchio: no joint {name!r} to couple")
                rows[k, names[name].layout.v_start] += coefficient
        self._rows = rows
        self.stepping = self._stepper()

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``data.lambda_c`` of the constrained forward dynamics at τ."""
        return self.constrained(q, v, tau)[1]

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """v̇ and ``data.lambda_c`` of one constrained forward dynamics per state."""
        if self._rows is None:
            raise Unsupported("pinocchio: its model holds no coupling between joints")
        vdot, forces = np.empty((len(q), self.model.nv)), np.empty((len(q), len(self._rows)))
        for i in range(len(q)):
            vdot[i] = self.stepping.accelerate(q[i], v[i], tau[i])
            forces[i] = self.data.lambda_c
        return vdot, forces

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """Σ Jᵀ F of the field as Pinocchio's external forces give it: ``rnea`` without them
        minus ``rnea`` with them (τ = M v̇ + h − Σ Jᵀ F)."""
        m, d = self.model, self.data
        zero = np.zeros(m.nv)
        out = np.empty((len(q), m.nv))
        for i in range(len(q)):
            fext = self.stepping.external(q[i], field)
            free = pin.rnea(m, d, q[i], v[i], zero).copy()
            out[i] = free - pin.rnea(m, d, q[i], v[i], zero, fext)
        return out

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's definition of ``integrator`` on Pinocchio's forward dynamics
        (:meth:`.simulation.Stepping.simulate`)."""
        return self._steppable().simulate(q0, v0, dt, steps, integrator=integrator,
                                          field=field)

    def solve(self, q0: np.ndarray, v0: np.ndarray, t_eval: np.ndarray, *, rtol: float,
              field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """scipy's DOP853 on Pinocchio's forward dynamics
        (:meth:`.simulation.Stepping.solve`)."""
        return self._steppable().solve(q0, v0, t_eval, rtol=rtol, field=field,
                                       label=self.engine)


OWN_STEP = 1e-6
"""The step of Pinocchio's own finite differences (one-sided, as MuJoCo's ``mjd_inverseFD``:
the check predicts their error from it)."""


def own_differences(m: pin.Model, d: pin.Data, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                    inverse_mass: np.ndarray) -> Derivatives:
    """One-sided finite differences of Pinocchio's own ``rnea`` along each tangent direction
    (q moved by ``pin.integrate``), step :data:`OWN_STEP`: ∂τ/∂q and ∂τ/∂v at v̇ = a, and the
    forward ones as MuJoCo's ``mjd_inverseFD`` forms them, −M⁻¹ ∂τ/∂x at v̇ = aba(q, v, 0)
    (the check predicts their error from the step on that form); M⁻¹ its analytic one."""
    n, nv = len(q), m.nv
    out = {k: np.empty((n, nv, nv)) for k in ("forward_q", "forward_v", "inverse_q",
                                              "inverse_v")}
    h = OWN_STEP

    def rnea_differences(s: int, acc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        base = pin.rnea(m, d, q[s], v[s], acc).copy()
        in_q, in_v = np.empty((nv, nv)), np.empty((nv, nv))
        for k, e in enumerate(np.eye(nv) * h):
            in_q[:, k] = (pin.rnea(m, d, pin.integrate(m, q[s], e), v[s], acc) - base) / h
            in_v[:, k] = (pin.rnea(m, d, q[s], v[s] + e, acc) - base) / h
        return in_q, in_v

    for s in range(n):
        out["inverse_q"][s], out["inverse_v"][s] = rnea_differences(s, a[s])
        free = pin.aba(m, d, q[s], v[s], np.zeros(nv)).copy()
        at_q, at_v = rnea_differences(s, free)
        out["forward_q"][s] = -inverse_mass[s] @ at_q
        out["forward_v"][s] = -inverse_mass[s] @ at_v
    out["forward_tau"] = inverse_mass
    return _derivatives(out, method=f"finite differences of its own rnea (one-sided, step "
                        f"{h:g}; the forward ones through M⁻¹)", step=h)
