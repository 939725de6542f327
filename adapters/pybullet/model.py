"""A user's model in PyBullet (optional extra ``pybullet``), through PyBullet's own parsers
(``loadURDF``, ``loadMJCF``) on a ``DIRECT`` client.

Flags stated, as a PyBullet user writes them: a URDF is loaded with
``URDF_USE_INERTIA_FROM_FILE`` (without it PyBullet computes each link's inertia from its
collision shapes and ignores the file's tensor) and ``useFixedBase=True`` unless
``--floating``; gravity is ``setGravity(0, 0, -9.81)`` (PyBullet's default is none, and its
MJCF reader does not read ``<option gravity>``). PyBullet keeps fixed joints as links (lumped
here into the moving link they are fixed to) and stores a link's inertia as principal moments
in its inertial frame (read back as the tensor R diag(I) Rᵀ in world axes). The link frames
are computed from the centre-of-mass frames (``getLinkState``'s ``worldLinkFrame`` is rounded to
float32). M = ``calculateMassMatrix``, h = ``calculateInverseDynamics`` at v̇ = 0, inverse
dynamics ``calculateInverseDynamics`` — which apply no joint damping (read back as a field);
forward dynamics M⁻¹(−h); PyBullet computes no energies, so T = ½ vᵀ M v from its M and
V = −Σ mᵢ g·xᵢ from its centres of mass (the definitions MuJoCo's ``mj_energyVel`` and
``mj_energyPos`` use). Hinges, slides, spherical joints and a moving base (a planar joint:
a skipped row naming it). A multibody per top-level body of an MJCF, their coordinates in
the order loaded.

A spherical joint: q = quaternion x-y-z-w, ω in the child link's axes (measured). Its
``calculateInverseDynamics`` does not take a multibody with one (``NO_INVERSE``: h and the
inverse dynamics are its stated limit, ``Dynamics.unavailable``); the forward dynamics come
from one ``stepSimulation`` (:meth:`PybulletModel.forward`); and its dynamics take the link's
principal moments in the link's axes, dropping the inertial frame's rotation — declared on
the tree (``TreeJoint.computed_inertia``) so that the check predicts what that changes.

A moving base (``--floating``; an MJCF's free body): PyBullet's state holds the pose of its
centre-of-mass frame (:attr:`~dyncheck.adapters.model_tree.Layout.offset`), q = (p, quat
x-y-z-w), v = (ω in that frame's axes, the centre of mass's velocity in world axes) — the v
``calculateInverseDynamics`` takes; its other conventions, measured and mapped here, are in
:func:`~.base.world_linear`. Its ``calculateInverseDynamics`` resolves gravity in the
base frame
through the base orientation's roll, pitch, yaw composed in reverse order (measured to
round-off against Pinocchio: :attr:`~dyncheck.adapters.model_tree.GravityFrame.RPY_REVERSED`),
declared on the tree so that the check predicts the difference it makes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import pybullet as pb

from dyncheck.adapters.base import Field, ModelEngine, Offer
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.inertia import lump
from dyncheck.adapters.model_tree import (
    Axes,
    Dynamics,
    GravityFrame,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    TreeJoint,
)
from dyncheck.adapters.pybullet.base import base_state, place_base, world_linear
from dyncheck.adapters.pybullet.counterfactual import gravity_fixed, inertial_fixed
from dyncheck.adapters.pybullet.couplings import GEARED, Gear, gears, multipliers
from dyncheck.adapters.pybullet.files import (
    ACCURACY_HINT,
    ARMATURE_HINT,
    DIAGONALIZATION,
    FLAGS_NOTE,
    FREE_BASE,
    GRAVITY_HINT,
    MAX_LINKS,
    Link,
    bare_links,
    defaulted,
    load,
    mjcf_hints,
    pose,
    rotation_of,
    unheld,
    zeroed,
)
from dyncheck.adapters.pybullet.forces import apply_field, field_force, named_links
from dyncheck.adapters.pybullet.state import KINDS, REST, PybulletState
from dyncheck.adapters.registration import Format
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import Unsupported

ENGINE = "pybullet"
MJCF_EPS = float(np.finfo(np.float32).eps)
"""PyBullet's MJCF reader holds the file's numbers rounded to float32 (measured: a body at
``pos`` 1 with a child at −0.6 stands at 1 − float32(0.6), a capsule's centre at
float32(0.7)): its readings of an MJCF, and the dynamics it computes from them, carry ε₃₂."""
GRAVITY = np.array([0.0, 0.0, -9.81])
_NAMES = {pb.JOINT_PLANAR: "planar", pb.JOINT_POINT2POINT: "point2point",
          pb.JOINT_GEAR: "gear"}
STEP = 1e-3
"""The time step of the one ``stepSimulation`` whose velocity change gives PyBullet's
forward dynamics on a multibody with a spherical joint, v̇ = (v₊ − v)/h: its semi-implicit
Euler step is exactly that (no damping, no motor), to ε |v| / (h |v̇|) relative."""
NO_INVERSE = (
    "PyBullet's calculateInverseDynamics does not take a multibody with a spherical joint "
    "(its Python API raises SystemError: it passes no multi-DoF joint to its inverse "
    "dynamics, as its maintainers state in bullet3 PR #1381)"
)
class PybulletModel(PybulletState, ModelEngine):
    """A PyBullet client holding the file's multibodies, and their neutral tree."""

    engine = ENGINE
    offers = frozenset({Offer.STEPPING, Offer.BODY_FORCES, Offer.COUPLINGS})
    coupled_joints = GEARED
    no_bias_with_ball = NO_INVERSE
    no_actuation = ("pybullet holds no actuator model (no control law of a file's actuators "
                    "or transmissions): a script drives each joint with "
                    "setJointMotorControl2 (TORQUE_CONTROL applies the torque it is given; "
                    "its POSITION_CONTROL and VELOCITY_CONTROL motors are constraints, not a "
                    "force law: tutorial 12)")

    def __init__(self, source: ModelFile, *, gravity: np.ndarray | None = None,
                 fixes: bool = True) -> None:
        """``gravity``: what the user sets with ``setGravity`` (a URDF states none; PyBullet's
        MJCF reader ignores the file's); None: (0, 0, −9.81). ``fixes``: read a copy with
        each hint's fix applied (:attr:`ModelTree.fixed`)."""
        self.client = pb.connect(pb.DIRECT)
        self.gravity = GRAVITY.copy() if gravity is None else np.asarray(gravity, float)
        pb.setGravity(*self.gravity, physicsClientId=self.client)
        self.bodies = load(self.client, source)
        self._movable: dict[int, list[tuple[int, int]]] = {}  # body → (joint, its type)
        self._damping: dict[tuple[int, int], float] = {}  # (body, joint) → the file's
        self._floating = {body: self._moving_base(body) for body in self.bodies}
        self._root_name = "root_joint" if source.format is Format.URDF else ""
        self._read_eps = MJCF_EPS if source.format is Format.MJCF else float(np.finfo(float).eps)
        links = [link for body in self.bodies for link in self._links(body)]
        notes = (FLAGS_NOTE,) if source.format is Format.URDF else ()
        hints: tuple[tuple[str, str, str], ...] = (("model", "armature", ARMATURE_HINT),)
        weighed, wants = mjcf_hints(source)
        if source.format is Format.MJCF:
            hints += (("model", "gravity", GRAVITY_HINT), *weighed)
        bare = bare_links(source, links)
        hints += zeroed(source, links) + defaulted(bare)
        if source.format is Format.URDF:
            hints += (("model", "inertia accuracy", ACCURACY_HINT),)
        self.tree = replace(self._tree(links, notes, hints), wants_compiled=wants)
        if (dropped := unheld(self.client, source)) is not None:  # (#78: measured)
            self.tree = replace(self.tree, closures_read=True, closures_unheld=dropped)
        if fixes:  # (#77: the fix of a bare link measured on a copy; the stated gravity set)
            self.tree = replace(self.tree, fixed=inertial_fixed(
                source, bare, self._copy_tree) + gravity_fixed(
                source, self.gravity, self._copy_tree))
        self._balls = any(kind == pb.JOINT_SPHERICAL for joints in self._movable.values()
                          for _, kind in joints)
        self._gears: list[Gear] = []

    def _copy_tree(self, copy: ModelFile, *, gravity: np.ndarray | None = None) -> ModelTree:
        """The tree of ``copy`` as PyBullet reads it under the same gravity (or
        ``gravity``), its client closed after."""
        model = PybulletModel(copy, gravity=self.gravity if gravity is None else gravity,
                              fixes=False)
        try:
            return model.tree
        finally:
            pb.disconnect(physicsClientId=model.client)

    def _moving_base(self, body: int) -> bool:
        """Whether PyBullet gave ``body`` a moving base: its mass matrix has 6 more rows than
        the body has joint coordinates."""
        kinds = [pb.getJointInfo(body, j, physicsClientId=self.client)[2]
                 for j in range(pb.getNumJoints(body, physicsClientId=self.client))]
        q = [x for kind in kinds for x in REST.get(kind, ())]
        nv = sum(JointType(KINDS[kind]).nv for kind in kinds if kind in KINDS)
        mass = pb.calculateMassMatrix(body, q, physicsClientId=self.client)
        return len(mass) != nv

    def _links(self, body: int) -> list[Link]:
        """The body's links at the reference configuration: joints at 0, a moving base's
        link frame at the world origin, unrotated (its centre-of-mass frame, whose pose
        PyBullet's base state holds, at the local inertial frame)."""
        c = self.client
        count = pb.getNumJoints(body, physicsClientId=c)
        if count > MAX_LINKS:
            raise Unsupported(f"pybullet holds at most {MAX_LINKS} links of a multibody in its "
                              f"client state (MAX_NUM_LINKS); this one has {count}")
        out = []
        base = pb.getDynamicsInfo(body, -1, physicsClientId=c)
        if self._floating[body]:
            pb.resetBasePositionAndOrientation(body, base[3], base[4], physicsClientId=c)
            rotation = rotation_of(base[4])
            name = pb.getBodyInfo(body, physicsClientId=c)[0].decode()
            out.append(Link(
                body=body, index=-1, name=name, joint=self._root_name or name, kind=FREE_BASE,
                parent=-2, axis=np.zeros(3), origin=np.zeros(3),
                rotation=np.eye(3), mass=float(base[0]), com=np.array(base[3], float),
                inertia=rotation @ np.diag(base[2]) @ rotation.T, damping=0.0,
                limits=(0.0, -1.0), offset=pose(base[3], base[4]),
            ))
        for j in range(pb.getNumJoints(body, physicsClientId=c)):
            info = pb.getJointInfo(body, j, physicsClientId=c)
            if info[2] not in KINDS and info[2] != pb.JOINT_FIXED:
                raise Unsupported(f"pybullet joint type {_NAMES.get(info[2], info[2])} "
                                  f"({info[1].decode()!r}) is not checked")
            if info[2] == pb.JOINT_SPHERICAL:
                pb.resetJointStateMultiDof(body, j, REST[info[2]], [0.0] * 3,
                                           physicsClientId=c)
            else:
                pb.resetJointState(body, j, 0.0, 0.0, physicsClientId=c)
        for j in range(pb.getNumJoints(body, physicsClientId=c)):
            info = pb.getJointInfo(body, j, physicsClientId=c)
            state = pb.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=c)
            dyn = pb.getDynamicsInfo(body, j, physicsClientId=c)
            com, com_rotation = np.array(state[0], float), rotation_of(state[1])
            local_rotation = rotation_of(state[3])
            rotation = com_rotation @ local_rotation.T  # the link frame, from the com frame
            origin = com - rotation @ np.array(state[2], float)
            out.append(Link(
                body=body, index=j, name=info[12].decode(), joint=info[1].decode(),
                kind=info[2], parent=info[16],
                axis=(com_rotation @ np.array(info[13], float) if info[2] != pb.JOINT_SPHERICAL
                      else np.zeros(3)),  # given in the com frame; a ball's: none
                origin=origin, rotation=rotation, mass=float(dyn[0]), com=com,
                inertia=com_rotation @ np.diag(dyn[2]) @ com_rotation.T,
                moments=np.array(dyn[2], float),
                damping=float(info[6]), limits=(float(info[8]), float(info[9])),
            ))
            if info[2] in KINDS:
                self._movable.setdefault(body, []).append((j, info[2]))
                self._damping[(body, j)] = float(info[6])
        return out

    def _tree(self, links: list[Link], notes: tuple[str, ...],
              hints: tuple[tuple[str, str, str], ...]) -> ModelTree:
        by_key = {(link.body, link.index): link for link in links}

        def mover(link: Link | None) -> Link | None:
            """The nearest link at or above ``link`` that a joint moves (None: a fixed
            base)."""
            while link is not None and link.kind == pb.JOINT_FIXED:
                link = by_key.get((link.body, link.parent))
            return link

        carried: dict[tuple[int, int], list[Link]] = {}
        for link in links:
            owner = mover(link)
            if owner is not None:
                carried.setdefault((owner.body, owner.index), []).append(link)
        joints, q_at, v_at = [], 0, 0
        for link in links:
            if link.kind not in KINDS and link.kind != FREE_BASE:
                continue
            parts = carried[(link.body, link.index)]
            mass, com, inertia = lump([p.mass for p in parts], [p.com for p in parts],
                                      [p.inertia for p in parts])
            computed = None
            if link.kind == pb.JOINT_SPHERICAL and link.moments is not None:
                # its dynamics take the link's principal moments in the link's own axes,
                # dropping its inertial frame's rotation (measured to 1e-13 against the
                # rigid body's Euler equations with diag(moments): SPHERICAL_INERTIA)
                axes = link.rotation @ np.diag(link.moments) @ link.rotation.T
                computed = lump([p.mass for p in parts], [p.com for p in parts],
                                [axes if p is link else p.inertia for p in parts])[2]
                if np.abs(computed - inertia).max() <= 1e-12 * max(np.trace(inertia), 1e-300):
                    computed = None
            parent = mover(by_key.get((link.body, link.parent)))
            if link.kind == FREE_BASE:
                assert link.offset is not None
                joints.append(TreeJoint(
                    name=link.joint, type=JointType.FREE, parent=None,
                    body=link.name, axis=np.zeros(3), anchor=link.origin, frame=link.rotation,
                    mass=mass, com=com, inertia=inertia, parts=len(parts), armature=(0.0,) * 6,
                    damping=(0.0,) * 6, range=None, gravity_frame=GravityFrame.RPY_REVERSED,
                    layout=Layout(q_start=q_at, v_start=v_at, nq=7, nv=6, quat=Orientation.XYZW,
                                  angular_first=True, linear_axes=Axes.WORLD,
                                  angular_axes=Axes.LOCAL, offset=link.offset),
                ))
                q_at, v_at = q_at + 7, v_at + 6
                continue
            lower, upper = link.limits
            kind = KINDS[link.kind]
            ball = kind is JointType.BALL
            joints.append(TreeJoint(
                name=link.joint, type=kind, parent=parent.joint if parent else None,
                body=link.name, axis=link.axis, anchor=link.origin,
                frame=link.rotation, mass=mass, com=com, inertia=inertia, parts=len(parts),
                armature=(0.0,) * kind.nv, damping=(link.damping,) * kind.nv,
                computed_inertia=computed,
                range=(lower, upper) if lower <= upper and not ball else None,
                # a spherical joint: q = quaternion x-y-z-w, ω in the child link's axes
                # (measured: its M is constant in q alone on one joint; its stepped
                # velocities agree with MuJoCo's ball joint to round-off)
                layout=Layout(q_start=q_at, v_start=v_at, nq=4, nv=3, quat=Orientation.XYZW,
                              angular_axes=Axes.LOCAL) if ball
                else Layout(q_start=q_at, v_start=v_at, nq=1, nv=1),
            ))
            q_at, v_at = q_at + kind.nq, v_at + kind.nv
        self._masses = [(link.body, link.index, link.mass) for link in links]
        return ModelTree(engine=ENGINE, joints=tuple(joints), gravity=self.gravity.copy(),
                         nq=q_at, nv=v_at, notes=notes, hints=hints, eps=self._read_eps,
                         inertia_accuracy=DIAGONALIZATION,
                         measured=frozenset({ARMATURE_HINT}))  # (its API holds none)

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *,
                 gravity: np.ndarray | None = None) -> Dynamics:
        """``gravity``: another gravity vector for this call (its potential energy too)."""
        if gravity is not None:
            held, self.gravity = self.gravity, np.asarray(gravity, float)
            pb.setGravity(*self.gravity, physicsClientId=self.client)
            try:
                return self.dynamics(q, v, a)
            finally:
                self.gravity = held
                pb.setGravity(*held, physicsClientId=self.client)
        c, n, nv = self.client, len(q), self.tree.nv
        mass = np.zeros((n, nv, nv))
        bias, inverse, forward = np.zeros((n, nv)), np.zeros((n, nv)), np.zeros((n, nv))
        potential = np.zeros(n)
        for i in range(n):
            q_at = v_at = 0
            for body in self.bodies:
                movable = self._movable.get(body, [])
                base_q = 7 if self._floating[body] else 0
                nq, nv_body = self._size(body)
                qs, vs = slice(q_at, q_at + nq), slice(v_at, v_at + nv_body)
                q_at, v_at = qs.stop, vs.stop
                if vs.start == vs.stop:
                    continue
                qb, vb, ab = (list(map(float, x)) for x in (q[i, qs], v[i, vs], a[i, vs]))
                joints = qb[base_q:]
                if base_q:  # its linear acceleration in the centre-of-mass frame's axes
                    ab[3:6] = list(rotation_of(tuple(qb[3:7])).T @ np.array(ab[3:6]))
                m = np.array(pb.calculateMassMatrix(body, joints, physicsClientId=c))
                if any(kind == pb.JOINT_SPHERICAL for _, kind in movable):
                    mass[i, vs, vs] = m
                    bias[i, vs] = inverse[i, vs] = np.nan
                    forward[i, vs] = self._stepped(body, qb, vb)
                    continue
                zero = [0.0] * len(vb)
                h = np.array(pb.calculateInverseDynamics(body, qb, vb, zero, physicsClientId=c))
                tau = np.array(pb.calculateInverseDynamics(body, qb, vb, ab, physicsClientId=c))
                if base_q:
                    m, h, tau = world_linear(np.array(qb[3:7]), m, h, tau)
                    pb.resetBasePositionAndOrientation(body, qb[:3], qb[3:7], physicsClientId=c)
                mass[i, vs, vs], bias[i, vs], inverse[i, vs] = m, h, tau
                if self._balls:  # (otherwise M⁻¹ h of the whole system, below)
                    forward[i, vs] = -np.linalg.solve(m, h)
                self._place(body, joints)
            potential[i] = -self.gravity @ sum((m * self._com(b, j) for b, j, m in self._masses
                                           if m > 0.0), np.zeros(3))
        if not self._balls:  # (M⁻¹ h of the whole system: the values as before)
            return Dynamics.at(v, mass_matrix=mass, bias=bias, inverse=inverse,
                               potential=potential)
        return Dynamics.at(v, mass_matrix=mass, bias=bias, inverse=inverse, forward=forward,
                           potential=potential,
                           unavailable=(("bias", NO_INVERSE), ("inverse", NO_INVERSE)))

    def _stepped(self, body: int, q: list[float], v: list[float],
                 tau: list[float] | None = None) -> np.ndarray:
        """PyBullet's forward dynamics at τ (None: 0) of a fixed-base multibody, from one
        ``stepSimulation`` of :data:`STEP` with τ applied by its torque-controlled motors
        (a spherical joint's in its child link's axes, as its velocities); the body is put
        back at (q, rest) after. Its calculateInverseDynamics fails on a spherical joint
        (:data:`NO_INVERSE`): its h is not to be had, its forward dynamics are."""
        if self._floating[body]:
            raise Unsupported("pybullet: a moving base with a spherical joint is not stepped "
                              "by dyncheck yet")
        c, dof = self.client, 0
        self._free_motion(body)
        pb.setTimeStep(STEP, physicsClientId=c)
        self._place(body, q, v)
        for j, kind in self._movable.get(body, []):
            nv = JointType(KINDS[kind]).nv
            applied = [0.0] * nv if tau is None else [float(x) for x in tau[dof : dof + nv]]
            if kind == pb.JOINT_SPHERICAL:
                pb.setJointMotorControlMultiDof(body, j, pb.TORQUE_CONTROL, force=applied,
                                                physicsClientId=c)
            else:
                pb.setJointMotorControl2(body, j, pb.TORQUE_CONTROL, force=applied[0],
                                         physicsClientId=c)
            dof += nv
        pb.stepSimulation(physicsClientId=c)
        out = (np.array(self._velocities(body)) - np.array(v)) / STEP
        self._place(body, q)
        self._free_motion(body, keep_joint_damping=True)  # motors off, the file's damping
        return out

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ at τ: M⁻¹ (τ − h) from its calculateMassMatrix and calculateInverseDynamics; on
        a multibody with a spherical joint, where the latter fails, or with couplings (its
        gear constraints act in its step), from its steps (:meth:`_stepped`)."""
        if not self._balls and not self._gears:
            return super().forward(q, v, tau)
        return self._steps(q, v, tau)[0]

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """The couplings as its gear constraints (:mod:`.couplings`)."""
        joints = {pb.getJointInfo(body, j, physicsClientId=self.client)[1].decode(): (body, j)
                  for body in self.bodies for j, _ in self._movable.get(body, [])}
        self._gears = gears(self.client, joints, couplings)

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Its gears' multipliers in the step that gives :meth:`forward`."""
        return self._steps(q, v, tau)[1]

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """v̇ and its gears' multipliers of the same steps (:meth:`_steps`)."""
        return self._steps(q, v, tau)

    def _steps(self, q: np.ndarray, v: np.ndarray,
               tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out, forces = np.zeros_like(v), np.zeros((len(q), len(self._gears)))
        for i in range(len(q)):
            q_at = v_at = 0
            for body in self.bodies:
                nq, nv = self._size(body)
                out[i, v_at : v_at + nv] = self._stepped(
                    body, [float(x) for x in q[i, q_at : q_at + nq]],
                    [float(x) for x in v[i, v_at : v_at + nv]],
                    [float(x) for x in tau[i, v_at : v_at + nv]])
                q_at, v_at = q_at + nq, v_at + nv
                held = [k for k, g in enumerate(self._gears) if g.body == body]
                forces[i, held] = multipliers(self.client, [self._gears[k] for k in held])
        return out, forces

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``steps`` calls of ``stepSimulation`` at ``setTimeStep(dt)`` from (q0, v0): q and v
        at every step, the start included. Stated as a PyBullet user writes it for free
        motion: each joint's default motor switched off
        (``setJointMotorControl2(VELOCITY_CONTROL, force=0)`` — it holds the joints
        otherwise; a spherical joint's ``setJointMotorControlMultiDof`` with zero gains and
        force) and the multibody's default linear and angular damping (0.04) set to 0
        (``changeDynamics``), the file's joint damping kept: what is left is its integrator,
        semi-implicit Euler (v₊ = v + h v̇, q₊ = q + h v₊) of its articulated-body forward
        dynamics. A moving base is placed and read through its base state
        (``resetBaseVelocity``/``getBaseVelocity``: both velocities in world axes, mapped to
        the layout's ω in the centre-of-mass frame's axes). ``field``: forces on links at
        their centres of mass at each step's start (:func:`~.forces.apply_field`)."""
        c = self.client
        pb.setTimeStep(dt, physicsClientId=c)
        q_at = v_at = 0
        for body in self.bodies:
            self._free_motion(body, keep_joint_damping=True)
            nq, nv = self._size(body)
            qb, vb = ([float(x) for x in y[at : at + n]]
                      for y, at, n in ((q0, q_at, nq), (v0, v_at, nv)))
            if self._floating[body]:
                place_base(self.client, body, qb[:7], vb[:6])
                qb, vb = qb[7:], vb[6:]
            self._place(body, qb, vb)
            q_at, v_at = q_at + nq, v_at + nv
        qs = np.zeros((steps + 1, len(q0)))
        vs = np.zeros((steps + 1, len(v0)))

        def read(k: int) -> None:
            states = [base_state(self.client, body) if self._floating[body] else ([], [])
                      for body in self.bodies]
            qs[k] = [x for body, (q, _) in zip(self.bodies, states, strict=True)
                     for x in (*q, *self._positions(body))]
            vs[k] = [x for body, (_, v) in zip(self.bodies, states, strict=True)
                     for x in (*v, *self._velocities(body))]

        links = named_links(c, self.bodies) if field is not None else {}
        read(0)
        for k in range(1, steps + 1):
            if field is not None:
                apply_field(c, links, field)
            pb.stepSimulation(physicsClientId=c)
            read(k)
        return qs, vs

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """The field's generalized force by its ``calculateJacobian`` (fixed bases)."""
        links = named_links(self.client, self.bodies)
        out = np.zeros((len(q), self.tree.nv))
        for i in range(len(q)):
            q_at = v_at = 0
            for body in self.bodies:
                nq, nv = self._size(body)
                if self._floating[body] or self._balls:
                    raise Unsupported("pybullet: a force on a moving base or through a "
                                      "spherical joint is not mapped by dyncheck")
                joints = [float(x) for x in q[i, q_at : q_at + nq]]
                self._place(body, joints)
                out[i, v_at : v_at + nv] = field_force(
                    self.client, body, joints=joints, links=links, field=field)
                q_at, v_at = q_at + nq, v_at + nv
        return out

    def _com(self, body: int, link: int) -> np.ndarray:
        c = self.client
        if link < 0:
            return np.array(pb.getBasePositionAndOrientation(body, physicsClientId=c)[0])
        return np.array(pb.getLinkState(body, link, computeForwardKinematics=True,
                                        physicsClientId=c)[0])
