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
``mj_energyPos`` use). Hinges, slides and a moving base (a spherical or planar joint: a
skipped row naming it). A multibody per top-level body of an MJCF, their coordinates in the
order loaded.

A moving base (``--floating``; an MJCF's free body): PyBullet's state holds the pose of its
centre-of-mass frame (:attr:`~dyncheck.adapters.model_tree.Layout.offset`), q = (p, quat
x-y-z-w), v = (ω in that frame's axes, the centre of mass's velocity in world axes) — the v
``calculateInverseDynamics`` takes; its other conventions, measured and mapped here, are in
:func:`_world_linear`. Its ``calculateInverseDynamics`` resolves gravity in the base frame
through the base orientation's roll, pitch, yaw composed in reverse order (measured to
round-off against Pinocchio: :attr:`~dyncheck.adapters.model_tree.GravityFrame.RPY_REVERSED`),
declared on the tree so that the check predicts the difference it makes.
"""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pybullet as pb

from dyncheck.adapters.base import ModelEngine, Offer
from dyncheck.adapters.mjcf_copy import utf8_file
from dyncheck.adapters.model_files import Format, ModelFile, urdf_inertials
from dyncheck.adapters.model_tree import (
    Axes,
    Dynamics,
    GravityFrame,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    TreeJoint,
    lump,
)
from dyncheck.errors import EngineError, Unsupported

ENGINE = "pybullet"
GRAVITY = np.array([0.0, 0.0, -9.81])
_TYPES = {pb.JOINT_REVOLUTE: JointType.HINGE, pb.JOINT_PRISMATIC: JointType.SLIDE}
_NAMES = {pb.JOINT_SPHERICAL: "spherical", pb.JOINT_PLANAR: "planar",
          pb.JOINT_POINT2POINT: "point2point", pb.JOINT_GEAR: "gear"}
FLAGS_NOTE = (
    "pybullet: loadURDF with URDF_USE_INERTIA_FROM_FILE (without it PyBullet computes each "
    "link's inertia from its collision shapes)"
)
GRAVITY_HINT = (
    "PyBullet's MJCF reader does not read <option gravity> (a PyBullet user sets it with "
    "setGravity; here 0 0 -9.81)"
)
ARMATURE_HINT = "PyBullet has no joint armature (rotor inertia): its M leaves it out"
DIAGONALIZATION = 1e-6
"""PyBullet's URDF importer stores a link's inertia as principal moments found by
``btMatrix3x3::diagonalize(basis, 1e-6, 30)``: Jacobi rotations until every off-diagonal term
is ≤ 1e-6 × the trace (then one more rotation); what is left is dropped."""
ACCURACY_HINT = (
    "PyBullet stores a link's inertia as principal moments from a Jacobi diagonalization "
    "that stops once the off-diagonal terms are below 1e-6 of the trace (its URDF importer: "
    "btMatrix3x3::diagonalize(basis, 1e-6, 30)), dropping them"
)
NO_INERTIAL = (
    "PyBullet's URDF importer gives a link without <inertial> ({links}) a mass of 1 kg and a "
    "unit inertia (its default; MuJoCo and Pinocchio give it none) (fix: give the link an "
    "<inertial>, with mass 0 where it is a frame)"
)
ZEROED_INERTIA = (
    "PyBullet's URDF importer sets the inertia of {links} to zero: it breaks the triangle "
    "inequality I1 + I2 >= I3 (its warning: 'Bad inertia tensor properties, setting inertia "
    "to zero') (fix: correct the file's inertia)"
)
INERTIA_HINT = (
    "PyBullet's MJCF reader does not take a body's inertia from <inertial diaginertia> or "
    "fullinertia (measured: zero, or computed from its geoms) (fix: check the URDF in "
    "PyBullet, or give the bodies geoms whose inertia is the intended one)"
)


MAX_LINKS = 128
"""PyBullet's client state holds at most 128 links (``MAX_NUM_LINKS`` =
``MAX_DEGREE_OF_FREEDOM`` in its SharedMemoryPublic.h): ``getLinkState`` fails beyond."""
_FREE = -1
"""A moving base's link (PyBullet has no joint for it)."""


def _rotation(quat_xyzw: tuple[float, ...]) -> np.ndarray:
    return np.array(pb.getMatrixFromQuaternion(quat_xyzw), float).reshape(3, 3)


def _pose(position: tuple[float, ...], quat_xyzw: tuple[float, ...]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = _rotation(quat_xyzw), position
    return pose


@dataclass(frozen=True, kw_only=True)
class _Link:
    """One PyBullet link at the reference configuration, world axes."""

    body: int
    index: int
    name: str
    joint: str
    kind: int
    parent: int
    axis: np.ndarray  # world axes
    origin: np.ndarray  # link frame, world
    rotation: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray  # about the com, world axes
    damping: float
    limits: tuple[float, float]
    offset: np.ndarray | None = None  # a moving base: link frame ← centre-of-mass frame


def _load(client: int, source: ModelFile) -> list[int]:
    """The file's multibodies; a URDF as the other engines get it, without geometry and
    ``<mimic>`` (:func:`~dyncheck.adapters.model_files.read`): written to a file of its own
    (``loadURDF`` reads files only), removed once loaded."""
    try:
        if source.format is Format.MJCF:
            with utf8_file(source.path) as file:
                bodies = list(pb.loadMJCF(str(file), physicsClientId=client))
        else:
            with tempfile.TemporaryDirectory(prefix="dyncheck-pybullet-") as folder:
                copy = Path(folder) / "model.urdf"
                copy.write_text(source.text, encoding="utf-8")
                bodies = [pb.loadURDF(str(copy), useFixedBase=not source.floating,
                                      flags=pb.URDF_USE_INERTIA_FROM_FILE,
                                      physicsClientId=client)]
    except pb.error as exc:
        raise EngineError(f"pybullet refused {source.path}: {exc}") from None
    if not bodies:
        raise EngineError(f"pybullet refused {source.path}: no body loaded")
    return bodies


def _zeroed(source: ModelFile, links: list[_Link]) -> tuple[tuple[str, str, str], ...]:
    """Why a URDF link's inertia reads zero: the file's breaks the triangle inequality
    (PyBullet zeroes it), named on the joint that moves the link."""
    bad = set()
    for stated in urdf_inertials(source):
        moments = np.linalg.eigvalsh(np.array(stated.inertia))
        if moments[0] + moments[1] < moments[2] * (1.0 - 1e-12):
            bad.add(stated.link)
    joints = {link.name: link.joint for link in links}
    return tuple((joints[name], "inertia", ZEROED_INERTIA.format(links=repr(name)))
                 for name in sorted(bad) if name in joints)


def _defaulted(source: ModelFile, links: list[_Link]) -> tuple[tuple[str, str, str], ...]:
    """Why a joint's mass reads 1 kg more: a URDF link it carries has no ``<inertial>``."""
    if source.format is not Format.URDF:
        return ()
    bare = {link.get("name", "") for link in ET.fromstring(source.text).findall("link")
            if link.find("inertial") is None}
    by_key = {(link.body, link.index): link for link in links}
    out: dict[str, list[str]] = {}
    for link in links:
        if link.name not in bare:
            continue
        owner: _Link | None = link
        while owner is not None and owner.kind == pb.JOINT_FIXED:
            owner = by_key.get((owner.body, owner.parent))
        if owner is not None:
            out.setdefault(owner.joint, []).append(link.name)
    why = {joint: NO_INERTIAL.format(links=", ".join(repr(n) for n in names))
           for joint, names in out.items()}
    return tuple((joint, field, text) for joint, text in why.items()
                 for field in ("mass", "com", "inertia"))


class PybulletModel(ModelEngine):
    """A PyBullet client holding the file's multibodies, and their neutral tree."""

    engine = ENGINE
    offers = frozenset({Offer.STEPPING})

    def __init__(self, source: ModelFile, *, gravity: np.ndarray | None = None) -> None:
        """``gravity``: what the user sets with ``setGravity`` (a URDF states none; PyBullet's
        MJCF reader ignores the file's); None: (0, 0, −9.81)."""
        self.client = pb.connect(pb.DIRECT)
        self.gravity = GRAVITY.copy() if gravity is None else np.asarray(gravity, float)
        pb.setGravity(*self.gravity, physicsClientId=self.client)
        self.bodies = _load(self.client, source)
        self._movable: dict[int, list[int]] = {}
        self._floating = {body: self._moving_base(body) for body in self.bodies}
        self._root_name = "root_joint" if source.format is Format.URDF else ""
        links = [link for body in self.bodies for link in self._links(body)]
        notes = (FLAGS_NOTE,) if source.format is Format.URDF else ()
        hints: tuple[tuple[str, str, str], ...] = (("model", "armature", ARMATURE_HINT),)
        if source.format is Format.MJCF:
            hints += (("model", "gravity", GRAVITY_HINT), ("model", "inertia", INERTIA_HINT))
        hints += _zeroed(source, links) + _defaulted(source, links)
        if source.format is Format.URDF:
            hints += (("model", "inertia accuracy", ACCURACY_HINT),)
        self.tree = self._tree(links, notes, hints)

    def _moving_base(self, body: int) -> bool:
        """Whether PyBullet gave ``body`` a moving base: its mass matrix has 6 more rows than
        the body has joint coordinates."""
        n = sum(pb.getJointInfo(body, j, physicsClientId=self.client)[2]
                in (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC)
                for j in range(pb.getNumJoints(body, physicsClientId=self.client)))
        mass = pb.calculateMassMatrix(body, [0.0] * n, physicsClientId=self.client)
        return len(mass) != n

    def _links(self, body: int) -> list[_Link]:
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
            rotation = _rotation(base[4])
            name = pb.getBodyInfo(body, physicsClientId=c)[0].decode()
            out.append(_Link(
                body=body, index=-1, name=name, joint=self._root_name or name, kind=_FREE,
                parent=-2, axis=np.zeros(3), origin=np.zeros(3),
                rotation=np.eye(3), mass=float(base[0]), com=np.array(base[3], float),
                inertia=rotation @ np.diag(base[2]) @ rotation.T, damping=0.0,
                limits=(0.0, -1.0), offset=_pose(base[3], base[4]),
            ))
        for j in range(pb.getNumJoints(body, physicsClientId=c)):
            info = pb.getJointInfo(body, j, physicsClientId=c)
            if info[2] not in _TYPES and info[2] != pb.JOINT_FIXED:
                raise Unsupported(f"pybullet joint type {_NAMES.get(info[2], info[2])} "
                                  f"({info[1].decode()!r}) is not checked")
            pb.resetJointState(body, j, 0.0, 0.0, physicsClientId=c)
        for j in range(pb.getNumJoints(body, physicsClientId=c)):
            info = pb.getJointInfo(body, j, physicsClientId=c)
            state = pb.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=c)
            dyn = pb.getDynamicsInfo(body, j, physicsClientId=c)
            com, com_rotation = np.array(state[0], float), _rotation(state[1])
            local_rotation = _rotation(state[3])
            rotation = com_rotation @ local_rotation.T  # the link frame, from the com frame
            origin = com - rotation @ np.array(state[2], float)
            out.append(_Link(
                body=body, index=j, name=info[12].decode(), joint=info[1].decode(),
                kind=info[2], parent=info[16],
                axis=com_rotation @ np.array(info[13], float),  # given in the com frame
                origin=origin, rotation=rotation, mass=float(dyn[0]), com=com,
                inertia=com_rotation @ np.diag(dyn[2]) @ com_rotation.T,
                damping=float(info[6]), limits=(float(info[8]), float(info[9])),
            ))
            if info[2] in _TYPES:
                self._movable.setdefault(body, []).append(j)
        return out

    def _tree(self, links: list[_Link], notes: tuple[str, ...],
              hints: tuple[tuple[str, str, str], ...]) -> ModelTree:
        by_key = {(link.body, link.index): link for link in links}

        def mover(link: _Link | None) -> _Link | None:
            """The nearest link at or above ``link`` that a joint moves (None: a fixed
            base)."""
            while link is not None and link.kind == pb.JOINT_FIXED:
                link = by_key.get((link.body, link.parent))
            return link

        carried: dict[tuple[int, int], list[_Link]] = {}
        for link in links:
            owner = mover(link)
            if owner is not None:
                carried.setdefault((owner.body, owner.index), []).append(link)
        joints, q_at, v_at = [], 0, 0
        for link in links:
            if link.kind not in _TYPES and link.kind != _FREE:
                continue
            parts = carried[(link.body, link.index)]
            mass, com, inertia = lump([p.mass for p in parts], [p.com for p in parts],
                                      [p.inertia for p in parts])
            parent = mover(by_key.get((link.body, link.parent)))
            if link.kind == _FREE:
                assert link.offset is not None
                joints.append(TreeJoint(
                    name=link.joint, type=JointType.FREE, parent=None,
                    body=link.name, axis=np.zeros(3), anchor=link.origin, frame=link.rotation,
                    mass=mass, com=com, inertia=inertia, armature=(0.0,) * 6,
                    damping=(0.0,) * 6, range=None, gravity_frame=GravityFrame.RPY_REVERSED,
                    layout=Layout(q_start=q_at, v_start=v_at, nq=7, nv=6, quat=Orientation.XYZW,
                                  angular_first=True, linear_axes=Axes.WORLD,
                                  angular_axes=Axes.LOCAL, offset=link.offset),
                ))
                q_at, v_at = q_at + 7, v_at + 6
                continue
            lower, upper = link.limits
            kind = _TYPES[link.kind]
            joints.append(TreeJoint(
                name=link.joint, type=kind, parent=parent.joint if parent else None,
                body=link.name, axis=link.axis, anchor=link.origin,
                frame=link.rotation, mass=mass, com=com, inertia=inertia, armature=(0.0,),
                damping=(link.damping,), range=(lower, upper) if lower <= upper else None,
                layout=Layout(q_start=q_at, v_start=v_at, nq=1, nv=1),
            ))
            q_at, v_at = q_at + 1, v_at + 1
        self._masses = [(link.body, link.index, link.mass) for link in links]
        return ModelTree(engine=ENGINE, joints=tuple(joints), gravity=self.gravity.copy(),
                         nq=q_at, nv=v_at, notes=notes, hints=hints,
                         inertia_accuracy=DIAGONALIZATION)

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
        bias, inverse = np.zeros((n, nv)), np.zeros((n, nv))
        potential = np.zeros(n)
        for i in range(n):
            q_at = v_at = 0
            for body in self.bodies:
                movable = self._movable.get(body, [])
                base_q, base_v = (7, 6) if self._floating[body] else (0, 0)
                qs = slice(q_at, q_at + base_q + len(movable))
                vs = slice(v_at, v_at + base_v + len(movable))
                q_at, v_at = qs.stop, vs.stop
                if vs.start == vs.stop:
                    continue
                qb, vb, ab = (list(map(float, x)) for x in (q[i, qs], v[i, vs], a[i, vs]))
                joints = qb[base_q:]
                if base_q:  # its linear acceleration in the centre-of-mass frame's axes
                    ab[3:6] = list(_rotation(tuple(qb[3:7])).T @ np.array(ab[3:6]))
                m = np.array(pb.calculateMassMatrix(body, joints, physicsClientId=c))
                zero = [0.0] * len(vb)
                h = np.array(pb.calculateInverseDynamics(body, qb, vb, zero, physicsClientId=c))
                tau = np.array(pb.calculateInverseDynamics(body, qb, vb, ab, physicsClientId=c))
                if base_q:
                    m, h, tau = _world_linear(np.array(qb[3:7]), m, h, tau)
                    pb.resetBasePositionAndOrientation(body, qb[:3], qb[3:7], physicsClientId=c)
                mass[i, vs, vs], bias[i, vs], inverse[i, vs] = m, h, tau
                for j, x in zip(movable, joints, strict=True):
                    pb.resetJointState(body, j, x, 0.0, physicsClientId=c)
            potential[i] = -self.gravity @ sum((m * self._com(b, j) for b, j, m in self._masses
                                           if m > 0.0), np.zeros(3))
        return Dynamics.at(v, mass_matrix=mass, bias=bias, inverse=inverse,
                           potential=potential)

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float,
                 steps: int) -> tuple[np.ndarray, np.ndarray]:
        """``steps`` calls of ``stepSimulation`` at ``setTimeStep(dt)`` from (q0, v0): q and v
        at every step, the start included. Stated as a PyBullet user writes it for free
        motion: each joint's default velocity motor switched off
        (``setJointMotorControl2(VELOCITY_CONTROL, force=0)`` — it holds the joints
        otherwise) and the multibody's default linear and angular damping (0.04) set to 0
        (``changeDynamics``): what is left is its integrator, semi-implicit Euler
        (v₊ = v + h v̇, q₊ = q + h v₊) of its articulated-body forward dynamics. Hinges and
        slides on a fixed base."""
        c = self.client
        if any(self._floating.values()):
            raise Unsupported("pybullet: a moving base is not stepped by dyncheck yet")
        pb.setTimeStep(dt, physicsClientId=c)
        at = 0
        for body in self.bodies:
            pb.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0,
                              physicsClientId=c)
            for j in self._movable.get(body, []):
                pb.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, force=0.0,
                                         physicsClientId=c)
                pb.changeDynamics(body, j, linearDamping=0.0, angularDamping=0.0,
                                  physicsClientId=c)
                pb.resetJointState(body, j, float(q0[at]), float(v0[at]), physicsClientId=c)
                at += 1
        qs = np.zeros((steps + 1, len(q0)))
        vs = np.zeros((steps + 1, len(v0)))

        def read(k: int) -> None:
            states = [pb.getJointState(body, j, physicsClientId=c) for body in self.bodies
                      for j in self._movable.get(body, [])]
            qs[k] = [x[0] for x in states]
            vs[k] = [x[1] for x in states]

        read(0)
        for k in range(1, steps + 1):
            pb.stepSimulation(physicsClientId=c)
            read(k)
        return qs, vs

    def _com(self, body: int, link: int) -> np.ndarray:
        c = self.client
        if link < 0:
            return np.array(pb.getBasePositionAndOrientation(body, physicsClientId=c)[0])
        return np.array(pb.getLinkState(body, link, computeForwardKinematics=True,
                                        physicsClientId=c)[0])


def _world_linear(quat_xyzw: np.ndarray, mass: np.ndarray, bias: np.ndarray,
                  tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A moving base's rows in one convention, v = (ω in the centre-of-mass frame's axes,
    the centre of mass's velocity in world axes, joints) — the v ``calculateInverseDynamics``
    takes. Measured against Pinocchio (gravity off, any base orientation: agreement to
    round-off once mapped): ``calculateInverseDynamics`` takes the linear acceleration in the
    frame's axes (mapped by the caller, Rᵀ v̇) and returns (force, torque, joints) with the
    force in the frame's axes (reordered and rotated to world axes here, R F);
    ``calculateMassMatrix`` takes the linear velocity in the frame's axes (its M does not
    change with the base's orientation; mapped here by R)."""
    rot = _rotation(tuple(quat_xyzw))
    t = np.eye(len(mass))
    t[3:6, 3:6] = rot.T
    order = np.r_[3:6, 0:3, 6:len(mass)]
    bias, tau = bias[order], tau[order]
    bias[3:6], tau[3:6] = rot @ bias[3:6], rot @ tau[3:6]
    return t.T @ mass @ t, bias, tau
