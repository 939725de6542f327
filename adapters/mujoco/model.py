"""A user's model in MuJoCo, through MuJoCo's own parsers (MJCF, or its URDF compiler).

Smooth dynamics only: constraints (contacts, limits, equalities), actuation and passive forces
(springs, dampers) are disabled in ``opt.disableflags``, and so are sensors (outputs, which
feed nothing back; MJX's inverse dynamics fails on a touch sensor when constraints are off —
mujoco-mjx 3.17.0, ``sensor_acc`` indexes the empty ``efc_force``, found on dm_control's
finger, hopper and humanoid); damping and armature are read back as model fields.
M = ``mj_fullM`` (armature included), h = ``qfrc_bias``, forward dynamics ``qacc`` at zero
applied force, inverse ``mj_inverse``, energies ``mjENBL_ENERGY``.
State layout: a quaternion (w, x, y, z); a free joint q = (p, quat), v = (linear in world
axes, angular in local axes); a ball joint v = angular velocity in local axes.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from dyncheck.adapters.base import ModelEngine, Offer
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.formats.mjcf_copy import utf8_file
from dyncheck.adapters.inertia import lump
from dyncheck.adapters.model_tree import (
    NQ,
    NV,
    Axes,
    Derivatives,
    Dynamics,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    Transition,
    TreeJoint,
)
from dyncheck.adapters.model_tree import (
    derivatives as _derivatives,
)
from dyncheck.adapters.mujoco import actuators, closures, compiled
from dyncheck.adapters.mujoco.actuators import MujocoActuation
from dyncheck.adapters.mujoco.api import (
    GYROSCOPIC_IMPLICIT,
    HAS_TENDON_ARMATURE,
    RK4_ON_GROUP,
    full_inertia,
    mujoco_warnings,
)
from dyncheck.adapters.mujoco.dynamics import SMOOTH_ONLY, evaluate, smooth, step_differences
from dyncheck.adapters.mujoco.meshes import TEXT_MESHES, mesh_rounding
from dyncheck.adapters.mujoco.simulation import MujocoRun
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format
from dyncheck.errors import EngineError
from dyncheck.vocabulary import Integrator

ENGINE = "mujoco"
_TYPES = {
    mujoco.mjtJoint.mjJNT_HINGE: JointType.HINGE,
    mujoco.mjtJoint.mjJNT_SLIDE: JointType.SLIDE,
    mujoco.mjtJoint.mjJNT_BALL: JointType.BALL,
    mujoco.mjtJoint.mjJNT_FREE: JointType.FREE,
}
GRAVITY_OFF = (
    "the file switches gravity off with <flag gravity=\"disable\"/>, which MuJoCo applies and "
    "the other engines' parsers ignore (they apply <option gravity>): to switch it off in "
    "every engine, set <option gravity=\"0 0 0\"/>"
)
FLOATING_NAME = "root_joint"
FD_STEP = 1e-6
"""The step of MuJoCo's finite differences (``mjd_inverseFD``) here: one-sided, so its error
is ≈ step/2 × |∂²τ| + 2 × (τ's round-off) / step — the check predicts both."""
"""The free joint added to a URDF's root link with ``--floating`` (Pinocchio's name)."""


def _compile(source: ModelFile, *, exact_meshes: bool = False
             ) -> tuple[mujoco.MjModel, tuple[str, ...], Inertias]:
    with mujoco_warnings() as said:  # to the page, never to MUJOCO_LOG.TXT in the user's cwd
        model, notes, inertias = _compile_quietly(source, exact_meshes=exact_meshes)
    return model, (*notes, *(f"mujoco warning: {m}" for m in said)), inertias


def _compile_quietly(source: ModelFile, *, exact_meshes: bool = False
                     ) -> tuple[mujoco.MjModel, tuple[str, ...], Inertias]:
    """MuJoCo's compiled model of ``source`` (``exact_meshes``: every mesh of the default
    ``inertia="legacy"`` or of ``"convex"`` computed ``"exact"`` instead), its notes, and
    where its inertias come from (:class:`Inertias`, read from the same parse)."""
    notes: list[str] = []
    try:
        if source.format is Format.MJCF:
            with utf8_file(source.path) as file:
                spec = mujoco.MjSpec.from_file(str(file))
        else:
            spec = mujoco.MjSpec.from_string(source.text)
        if source.floating and source.format is Format.URDF:
            root = spec.worldbody.first_body()
            root.add_freejoint(name=FLOATING_NAME)
            notes.append(f"mujoco: free joint {FLOATING_NAME!r} added to root link {root.name!r}")
        if exact_meshes:
            for mesh in spec.meshes:
                if mesh.inertia in (mujoco.mjtMeshInertia.mjMESH_INERTIA_LEGACY,
                                    mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX):
                    mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
        with warnings.catch_warnings(record=True) as caught:  # to the page, not stderr
            warnings.simplefilter("always")
            model = spec.compile()
        notes += [f"mujoco compiler warning: {' '.join(str(w.message).split())}"
                  for w in caught]
    except Exception as exc:  # MuJoCo raises ValueError with its compiler's message
        raise EngineError(
            f"mujoco refused {source.path}: {' '.join(str(exc).split())}"
        ) from None
    mode = spec.compiler.inertiafromgeom
    from_geoms = frozenset(
        i for i, body in enumerate(spec.bodies) if i > 0 and (
            mode == mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
            or (mode == mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_AUTO
                and not body.explicitinertial)))
    text = frozenset(k for k, mesh in enumerate(spec.meshes)
                     if mesh.file.lower().endswith(TEXT_MESHES))
    inexact = frozenset(k for k, mesh in enumerate(spec.meshes) if mesh.inertia in (
        mujoco.mjtMeshInertia.mjMESH_INERTIA_LEGACY, mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX))
    return model, tuple(notes), Inertias(from_geoms=from_geoms, text_meshes=text,
                                         inexact_meshes=inexact)


@dataclass(frozen=True, kw_only=True)
class Inertias:
    """Where a compiled model's inertias come from: the bodies (ids) that take theirs from
    their geoms (``inertiafromgeom``: "true", or "auto" and no ``<inertial>``), the meshes
    (ids) written as text (:data:`TEXT_MESHES`), and those whose volume is not computed
    exactly (``inertia="legacy"``, MuJoCo's default, or ``"convex"``)."""

    from_geoms: frozenset[int]
    text_meshes: frozenset[int]
    inexact_meshes: frozenset[int]

    def meshes_weigh(self, m: mujoco.MjModel, meshes: frozenset[int]) -> bool:
        """Whether a mesh of ``meshes`` is a geom of a body that takes its inertia from
        its geoms."""
        return any(int(m.geom_dataid[g]) in meshes and int(m.geom_bodyid[g]) in self.from_geoms
                   for g in np.flatnonzero(m.geom_type == mujoco.mjtGeom.mjGEOM_MESH))


def _joint_body_groups(m: mujoco.MjModel) -> dict[int, list[int]]:
    """Each body with joints → itself and the joint-less bodies rigidly attached below it."""
    owner = {0: -1}
    groups: dict[int, list[int]] = {}
    for b in range(1, m.nbody):
        parent = int(m.body_parentid[b])
        owner[b] = b if m.body_jntnum[b] > 0 else owner[parent]
        if owner[b] >= 0:
            groups.setdefault(owner[b], []).append(b)
    return groups


def _layouts(m: mujoco.MjModel) -> list[Layout]:
    out = []
    for j in range(m.njnt):
        kind = _TYPES[int(m.jnt_type[j])]
        out.append(
            Layout(
                q_start=int(m.jnt_qposadr[j]), v_start=int(m.jnt_dofadr[j]),
                nq=NQ[kind], nv=NV[kind], quat=Orientation.WXYZ, linear_axes=Axes.WORLD,
                angular_axes=Axes.LOCAL, zero=float(m.qpos0[m.jnt_qposadr[j]]),
            )
        )
    return out


TOTAL_MASS = (
    "MuJoCo scales every body's mass and inertia so that the total is {total} "
    "(<compiler settotalmass>); a parser that ignores the attribute reads the unscaled values "
    "(fix: write the scaled masses and inertias in the file)"
)


def _total_mass_hints(source: ModelFile) -> tuple[tuple[str, str, str], ...]:
    """Why masses and inertias read differently where ``settotalmass`` rescales them."""
    if source.format is not Format.MJCF:
        return ()
    total = next((c.get("settotalmass") for c in inline(source.path).iter("compiler")
                  if c.get("settotalmass") and float(c.get("settotalmass", "-1")) > 0), None)
    if total is None:
        return ()
    why = TOTAL_MASS.format(total=total)
    return tuple(("model", f, why) for f in ("mass", "inertia", "com"))


class MujocoModel(MujocoActuation, MujocoRun, ModelEngine):
    """A compiled model and its neutral tree; in a run, its couplings, a field and its
    stepping (:mod:`.simulation`; ``solimp=`` sets every equality's)."""

    engine = ENGINE
    fd_step = FD_STEP
    offers = frozenset({Offer.DERIVATIVES, Offer.TRANSITION, Offer.ACTUATION,
                        Offer.INPUT_JACOBIAN, Offer.FORWARD, Offer.STEPPING, Offer.COUPLINGS,
                        Offer.BODY_FORCES, Offer.CLOSURES, Offer.CLOSED_DERIVATIVES})
    gyroscopic_implicit = GYROSCOPIC_IMPLICIT
    rk4_group_order = 4 if RK4_ON_GROUP else 2
    couplings_with_field = True  # tendon equalities and a field in one model

    def __init__(self, source: ModelFile, *, exact_meshes: bool = False,
                 solimp: tuple[float, ...] | None = None) -> None:
        self.model, notes, self._inertias = _compile(source, exact_meshes=exact_meshes)
        m = self.model
        self._closed = _compile(replace(source, text=source.closed_text))[0] \
            if source.closed_text else m  # (a URDF's <mimic>: MuJoCo's joint equalities)
        if solimp is not None:
            m.eq_solimp[:] = solimp
            self._closed.eq_solimp[:] = solimp
        self._gravity = m.opt.gravity.copy()
        if m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY:
            self._gravity[:] = 0.0
            notes += ("mujoco: <flag gravity=\"disable\"/>: no gravity in MuJoCo's dynamics "
                      f"(<option gravity> {' '.join(f'{g:g}' for g in m.opt.gravity)} unused)",)
            self._hints: tuple[tuple[str, str, str], ...] = (("model", "gravity", GRAVITY_OFF),)
        else:
            self._hints = ()
        unread = actuators.file_hints(source)  # (shown only where MuJoCo holds none: measured)
        self._measured = frozenset(w for _, _, w in (*self._hints, *unread))
        scaled = _total_mass_hints(source)
        self._hints += scaled + unread
        m.opt.disableflags |= int(SMOOTH_ONLY)
        self._timestep = float(m.opt.timestep)  # the file's (a run's study steps at others)
        m.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        self._closed.opt.disableflags = m.opt.disableflags  # (the same smooth dynamics)
        self.data = mujoco.MjData(m)
        if np.any(m.body_gravcomp != 0):
            notes += ("mujoco: gravity compensation (gravcomp) left out of the dynamics",)
        if HAS_TENDON_ARMATURE and m.ntendon and np.any(m.tendon_armature != 0):
            armed = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_TENDON, i) or f"tendon {i}"
                     for i in np.flatnonzero(m.tendon_armature)]
            notes += (TENDON_ARMATURE.format(tendons=", ".join(repr(t) for t in armed[:4])
                                             + (" …" if len(armed) > 4 else "")),)
            m.tendon_armature[:] = 0.0
            self._closed.tendon_armature[:] = 0.0
        self.tree = self._tree(notes)
        if source.format is Format.MJCF:  # what a copy states for another engine (#77)
            self.tree = compiled.stated(self.tree, m, scaled=bool(scaled))
        if not exact_meshes and self._inertias.meshes_weigh(m, self._inertias.inexact_meshes):
            self.tree = replace(self.tree, exact_meshes=self._exact_meshes(source))

    def _exact_meshes(self, source: ModelFile) -> ModelTree | None:
        """The tree with every mesh's inertia ``"exact"`` where that changes a body's mass or
        inertia (a non-convex mesh under MuJoCo's default ``"legacy"``, or ``"convex"``: its
        hull); None where it changes none, or the meshes are not watertight (MuJoCo then
        refuses ``"exact"``)."""
        try:
            exact = MujocoModel(source, exact_meshes=True)
        except EngineError:
            return None
        same = np.array_equal(exact.model.body_mass, self.model.body_mass) and \
            np.array_equal(exact.model.body_inertia, self.model.body_inertia)
        return None if same else exact.tree

    def _tree(self, notes: tuple[str, ...]) -> ModelTree:
        m, d = self.model, self.data
        d.qpos[:] = m.qpos0
        for j in range(m.njnt):  # free bodies at the reference pose: the origin, unrotated
            if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
                d.qpos[m.jnt_qposadr[j] : m.jnt_qposadr[j] + 7] = (0, 0, 0, 1, 0, 0, 0)
        mujoco.mj_kinematics(m, d)
        groups = _joint_body_groups(m)
        layouts = _layouts(m)
        last_joint: dict[int, int] = {}  # body → its last joint
        joints = []
        for j in range(m.njnt):
            b = int(m.jnt_bodyid[j])
            kind = _TYPES[int(m.jnt_type[j])]
            first = int(m.body_jntadr[b])
            if j > first:
                parent: int | None = j - 1
            else:
                a = int(m.body_parentid[b])
                while a > 0 and a not in last_joint:
                    a = int(m.body_parentid[a])
                parent = last_joint.get(a)
            last_joint[b] = j
            is_last = j == first + int(m.body_jntnum[b]) - 1
            members = groups[b] if is_last else []
            if is_last:
                mass, com, inertia = lump(
                    [float(m.body_mass[i]) for i in members],
                    [d.xipos[i].copy() for i in members],
                    [
                        d.ximat[i].reshape(3, 3) @ np.diag(m.body_inertia[i])
                        @ d.ximat[i].reshape(3, 3).T
                        for i in members
                    ],
                )
            else:
                mass, com, inertia = 0.0, np.zeros(3), np.zeros((3, 3))
            dofs = slice(int(m.jnt_dofadr[j]), int(m.jnt_dofadr[j]) + NV[kind])
            axis = d.xaxis[j].copy() if kind in (JointType.HINGE, JointType.SLIDE) else np.zeros(3)
            limited = bool(m.jnt_limited[j]) and kind in (JointType.HINGE, JointType.SLIDE)
            joints.append(
                TreeJoint(
                    name=_joint_name(m, j),
                    type=kind,
                    parent=None if parent is None else _joint_name(m, parent),
                    body=m.body(b).name,
                    axis=axis,
                    anchor=d.xanchor[j].copy() if kind is not JointType.FREE else d.xpos[b].copy(),
                    frame=d.xmat[b].reshape(3, 3).copy(),
                    mass=mass, com=com, inertia=inertia, parts=max(len(members), 1),
                    armature=tuple(float(x) for x in m.dof_armature[dofs]),
                    damping=tuple(float(x) for x in m.dof_damping[dofs]),
                    range=(float(m.jnt_range[j, 0]), float(m.jnt_range[j, 1])) if limited else None,
                    layout=layouts[j],
                )
            )
        held, unheld = closures.read(self._closed, d, [_joint_name(m, j) for j in range(m.njnt)])
        rounding = mesh_rounding(m, self._inertias.from_geoms, self._inertias.text_meshes)
        by_joint = {j.name: max(rounding.get(b, 0.0) for b in groups[int(m.jnt_bodyid[k])])
                    for k, j in enumerate(joints)}
        return ModelTree(
            engine=ENGINE, joints=tuple(joints), gravity=self._gravity.copy(),
            nq=m.nq, nv=m.nv, notes=notes + unheld, hints=self._hints, measured=self._measured,
            closures=held, closures_read=True,
            actuators=actuators.read(m, [_joint_name(m, j) for j in range(m.njnt)]),
            mesh_rounding={name: bound for name, bound in by_joint.items() if bound > 0},
        )

    def reference_q(self) -> np.ndarray:
        return self.model.qpos0.copy()

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """Its equalities' rows and its forward dynamics with them on (:func:`.closures.
        closed`)."""
        return closures.closed(self._closed, q, v, tau)

    def closed_derivatives(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """:func:`.closures.closed_derivatives` at :data:`FD_STEP` and twice it."""
        return closures.closed_derivatives(self._closed, q, v, tau, step=FD_STEP)

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        e = evaluate(self.model, self.data, q=q, v=v, tau=np.zeros_like(v), a=a)
        return Dynamics(mass_matrix=e.mass, bias=e.bias, forward=e.forward, inverse=e.inverse,
                        kinetic=e.kinetic, potential=e.potential)

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        """``mjd_inverseFD`` (one-sided differences of ``mj_inverse``, step
        :data:`FD_STEP`, q nudged by ``mj_integratePos``: MuJoCo's chart) at v̇ = a for
        ∂τ/∂q, ∂τ/∂v; MuJoCo has no derivative of its forward dynamics, so those are the
        same differences at v̇ = its forward acceleration at τ = 0, through the identity
        ∂v̇/∂x = −M⁻¹ ∂τ/∂x (τ = ID(q, v, FD(q, v, τ)) differentiated), and ∂v̇/∂τ = M⁻¹."""
        m = self.model
        n, nv = len(q), m.nv
        out = {k: np.empty((n, nv, nv)) for k in
               ("forward_q", "forward_v", "forward_tau", "inverse_q", "inverse_v")}
        dq, dv = np.empty((nv, nv)), np.empty((nv, nv))
        mass = np.empty((nv, nv))
        with smooth(m, self._timestep):  # (a run's couplings left off)
            m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER  # mjd_inverseFD refuses RK4
            self._differences(q, v, a, out, dq, dv, mass)  # (mj_inverse's differences do
            # not depend on it)
        return _derivatives(out, method=f"finite differences (mjd_inverseFD, one-sided, "
                            f"step {FD_STEP:g})", step=FD_STEP)

    def _differences(self, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                     out: dict[str, np.ndarray], dq: np.ndarray, dv: np.ndarray,
                     mass: np.ndarray) -> None:
        m, d = self.model, self.data
        for i in range(len(q)):
            d.qpos[:], d.qvel[:] = q[i], v[i]
            d.qfrc_applied[:] = 0.0
            mujoco.mj_forward(m, d)
            full_inertia(m, d, mass)
            inverse_mass = np.linalg.inv(mass)
            for acceleration, key in ((d.qacc.copy(), "forward"), (a[i], "inverse")):
                d.qacc[:] = acceleration
                mujoco.mjd_inverseFD(m, d, FD_STEP, False, dq, dv, None, None, None, None,
                                     None)
                if key == "inverse":  # MuJoCo's rows are the inputs (transposed)
                    out["inverse_q"][i], out["inverse_v"][i] = dq.T, dv.T
                else:
                    out["forward_q"][i] = -inverse_mass @ dq.T
                    out["forward_v"][i] = -inverse_mass @ dv.T
            out["forward_tau"][i] = inverse_mass

    def transition(self, q: np.ndarray, v: np.ndarray,
                   a: np.ndarray) -> tuple[Transition, ...]:
        """``mjd_transitionFD`` (centered differences of ``mj_step``, MuJoCo's chart) of one
        step at the file's time step, at steps :data:`FD_STEP` and twice that, for the
        semi-implicit Euler and implicitfast integrators, and the same differences of RK4's
        step, which ``mjd_transitionFD`` refuses ("RK4 integrator is not supported", MuJoCo
        4.0): :func:`.dynamics.step_differences` (the smooth dynamics only, as everywhere in the
        check: no damping, no actuation, so implicitfast's implicit term (M − h ∂f/∂v with
        f's passive and actuator forces) is M, and its step Euler's — but on a standalone
        free body, whose block holds the bias's derivative: ``Transition.implicit_bias``)."""
        m, d = self.model, self.data
        n, nv = len(q), m.nv
        size = 2 * nv + m.na
        matrix = np.zeros((size, size))
        out = []
        with smooth(m, self._timestep):  # (a run's couplings and study step left off)
            for name, kind in ((Integrator.EULER, mujoco.mjtIntegrator.mjINT_EULER),
                               (Integrator.IMPLICITFAST, mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
                               (Integrator.RK4, mujoco.mjtIntegrator.mjINT_RK4)):
                why = _unfollowed(m, name)
                fine, coarse = np.zeros((n, 2 * nv, 2 * nv)), np.zeros((n, 2 * nv, 2 * nv))
                if why:  # a skipped row: its differences would be thrown away
                    fine = coarse = np.zeros((n, 0, 0))
                m.opt.integrator = kind
                for i in range(n if not why else 0):
                    for found, step in ((fine, FD_STEP), (coarse, 2 * FD_STEP)):
                        d.qpos[:], d.qvel[:] = q[i], v[i]
                        d.qfrc_applied[:] = 0.0
                        d.ctrl[:] = 0.0
                        if name is Integrator.RK4:
                            found[i] = step_differences(m, d, q[i], v[i], step)
                            continue
                        mujoco.mj_forward(m, d)
                        mujoco.mjd_transitionFD(m, d, step, True, matrix, None, None, None)
                        found[i] = matrix[: 2 * nv, : 2 * nv]
                out.append(Transition(
                    matrix=fine, coarse=coarse, time_step=float(m.opt.timestep),
                    fd_step=FD_STEP, integrator=name, unfollowed=why,
                    implicit_bias=_standalone_free(m) if name is Integrator.IMPLICITFAST
                    else ()))
        return tuple(out)


TENDON_ARMATURE = (
    "mujoco: tendon armature ({tendons}) left out of M, h and the dynamics compared: MuJoCo "
    "adds a Jₜᵀ Jₜ of each tendon to M (measured), and no other engine's parser reads tendons"
)

NAIVE_RK4 = (
    "MuJoCo before 4.0 sums RK4's stage velocities on a ball or free joint without dexp⁻¹ "
    "(order 2 there); the referee's chain rule follows the Runge–Kutta–Munthe-Kaas stages of "
    "MuJoCo ≥ 4.0"
)


def _unfollowed(m: mujoco.MjModel, integrator: Integrator) -> str:
    """Why the referee's chain rule does not follow MuJoCo's ``integrator`` step on ``m``
    (empty where it does)."""
    types = set(int(t) for t in m.jnt_type)
    free = int(mujoco.mjtJoint.mjJNT_FREE) in types
    if integrator is Integrator.RK4 and not RK4_ON_GROUP and (
            free or int(mujoco.mjtJoint.mjJNT_BALL) in types):
        return NAIVE_RK4
    return ""


def _standalone_free(m: mujoco.MjModel) -> tuple[str, ...]:
    """The free joints of MuJoCo's standalone free bodies (``mj_isFreeBody``: a body whose one
    joint is free, alone in its tree, carrying no other body's mass), whose block
    implicitfast solves with the bias's derivative (``mjd_freeMhat``, MuJoCo ≥ 3.11)."""
    if not GYROSCOPIC_IMPLICIT:
        return ()
    out = []
    for j in range(m.njnt):
        body, adr = int(m.jnt_bodyid[j]), int(m.jnt_dofadr[j])
        if (m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE and m.body_jntnum[body] == 1
                and m.tree_dofnum[m.dof_treeid[adr]] == 6
                and m.body_subtreemass[body] == m.body_mass[body]):
            out.append(_joint_name(m, j))
    return tuple(out)


def _joint_name(m: mujoco.MjModel, j: int) -> str:
    """Joint ``j``'s name, or for a joint the file leaves unnamed one of its own that no
    other joint has: ``body:type`` (``body`` its body's name, or ``body 3`` by MuJoCo's id
    where that is unnamed too), with the joint's place among its body's joints where the
    body has several of that type."""
    if m.joint(j).name:
        return m.joint(j).name
    b = int(m.jnt_bodyid[j])
    kind = _TYPES[int(m.jnt_type[j])]
    same = [k for k in range(m.njnt) if int(m.jnt_bodyid[k]) == b
            and _TYPES[int(m.jnt_type[k])] == kind]
    body = m.body(b).name or f"body {b}"
    return f"{body}:{kind}" if len(same) == 1 else f"{body}:{kind}{same.index(j)}"


PROOFS = {
    "GRAVITY_OFF": Proof.MEASURED,
    "TOTAL_MASS": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
