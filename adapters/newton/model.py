"""A user's model in Newton (optional extra ``newton``), through Newton's own importers
(``ModelBuilder.add_urdf``, ``add_mjcf``; ``--floating`` gives the URDF root a free joint,
``floating=True``), finalized on Warp's CPU device, computing in float32.

Newton keeps fixed joints (lumped here into the moving body they are fixed to). A joint's
frame is the child body's pose composed with ``joint_X_c``; its axis ``joint_axis`` is in that
frame. M and the generalized gravity and Coriolis forces are ``eval_inverse_dynamics_passive``
(M with ``joint_armature`` on its diagonal), h = C v̇ + g, inverse dynamics
``eval_inverse_dynamics_force``; Newton offers no forward dynamics outside its solvers, so
forward dynamics is M⁻¹(−h) from its M and h (float64 solve); T = ½ vᵀ M v and
V = −Σ mᵢ g·xᵢ from its M and its bodies' centres of mass (MuJoCo's ``mj_energyVel`` and
``mj_energyPos`` definitions). The tree declares ε₃₂: its round-off bounds use it.

State layout (Newton 1.8's ``Model.joint_qd``): a free joint's q = (p, quat x-y-z-w) of the
frame ``joint_X_c`` in the child body, relative to ``joint_X_p`` in the parent; its
v = (velocity of the child's centre of mass, angular velocity), both in the parent's axes
(the world's for a root), linear first; a ball joint's q = quat x-y-z-w.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from dyncheck.adapters.actuators import Actuation
from dyncheck.adapters.base import Field, ModelEngine, Offer
from dyncheck.adapters.closures import ClosedReading, ClosureKind
from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import equalities, inline
from dyncheck.adapters.formats.mjcf_copy import utf8_file
from dyncheck.adapters.inertia import lump
from dyncheck.adapters.model_tree import (
    Axes,
    Dynamics,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    TreeJoint,
)
from dyncheck.adapters.newton import actuators as newton_actuators
from dyncheck.adapters.newton import closures as newton_closures
from dyncheck.adapters.newton.counterfactual import proved
from dyncheck.adapters.newton.d6 import D6_ORDER, d6_chain, written_order
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format
from dyncheck.errors import EngineError, Unsupported

ENGINE = "newton"
EPS32 = float(np.finfo(np.float32).eps)
NO_LIMIT = 1e9
"""Newton's unlimited joints carry ±1e10 (``newton.MAXVAL``)."""
DEVICE = "cpu"


def _pose(transform: np.ndarray) -> np.ndarray:
    """A Warp transform (p, quat x-y-z-w) as a 4×4 matrix, in float64."""
    from scipy.spatial.transform import Rotation

    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_quat(np.asarray(transform[3:7], float)).as_matrix()
    pose[:3, 3] = transform[:3]
    return pose


def _transform(pose: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return np.concatenate([pose[:3, 3], Rotation.from_matrix(pose[:3, :3]).as_quat()])


def _last(label: str) -> str:
    """A joint's or body's name from Newton's label, which prefixes the path to it (URDF:
    ``robot/joint``; MJCF: ``worldbody/body/…/joint``)."""
    return label.rsplit("/", 1)[-1]


CORRECTED = (
    "Newton's finalize corrected the inertia of {bodies} (its validation, on by default: a "
    "principal moment below 1e-6 of the largest, or the triangle inequality broken, is "
    "repaired by adding the shift it needs plus 1e-6 kg m² to the diagonal; it warns only "
    "with a count) (fix: correct the file's inertia, or set the builder's balance_inertia, "
    "inertia_relative_tolerance, inertia_correction)"
)


def _load(source: ModelFile):  # -> (newton.Model, names of the bodies whose inertia it changed)
    import warp as wp

    from dyncheck.adapters.compiled import start_warp

    start_warp(wp)  # in the engine's own process: no banner, no kernel log; its kernel cache
    import newton

    builder = newton.ModelBuilder()
    try:
        if source.format is Format.MJCF:
            with utf8_file(source.path) as file:
                builder.add_mjcf(str(file))
        else:  # the file's text without geometry and <mimic> (model_files.read), as for all
            builder.add_urdf(source.text, floating=source.floating)
        with warnings.catch_warnings():  # its count of corrected bodies: named below instead
            # (a NewtonWarning since 1.8, a UserWarning before: its parent class)
            warnings.simplefilter("ignore", UserWarning)
            model = builder.finalize(device=DEVICE)
    except (ValueError, KeyError, IndexError, TypeError, RuntimeError, OSError) as exc:
        message = " ".join(str(exc).split()) or type(exc).__name__
        raise EngineError(f"newton refused {source.path}: {message}") from None
    stated = np.array([np.asarray(i, float) for i in builder.body_inertia]).reshape(-1, 3, 3)
    kept = np.asarray(model.body_inertia.numpy() if model.body_inertia is not None
                      else stated, float)
    scale = np.maximum(np.abs(stated).max(axis=(1, 2)), 1e-30)
    changed = np.abs(kept - stated).max(axis=(1, 2)) > 1e-5 * scale  # beyond float32 rounding
    return model, [_last(model.body_label[b]) for b in np.flatnonzero(changed)]


class NewtonModel(ModelEngine):
    """A finalized Newton model on the CPU and its neutral tree."""

    engine = ENGINE
    offers = frozenset({Offer.STEPPING, Offer.ACTUATION, Offer.BODY_FORCES, Offer.CLOSURES})

    def __init__(self, source: ModelFile) -> None:
        import newton

        self.newton = newton
        self.model, corrected = _load(source)
        m = self.model
        self.types = m.joint_type.numpy()
        kinds = {int(newton.JointType.REVOLUTE): JointType.HINGE,
                 int(newton.JointType.PRISMATIC): JointType.SLIDE,
                 int(newton.JointType.BALL): JointType.BALL,
                 int(newton.JointType.FREE): JointType.FREE}
        fixed = int(newton.JointType.FIXED)
        self.d6 = int(newton.JointType.D6)
        self._text = source.text if source.format is Format.MJCF else ""
        self._equalities = [e.tag for e in equalities(inline(source.path))] \
            if source.format is Format.MJCF else []
        for j, t in enumerate(self.types):
            if int(t) not in kinds and int(t) not in (fixed, self.d6):
                raise Unsupported(f"newton joint type {newton.JointType(int(t)).name} "
                                  f"({self._name(j)!r}) is not checked")
        self.kinds, self.fixed = kinds, fixed
        self.q_start, self.v_start = m.joint_q_start.numpy(), m.joint_qd_start.numpy()
        self.loops = newton_closures.loops(m)  # (#78: constraints, not joints of the tree)
        self.held = newton_closures.held(m, self.loops, {
            int(newton.JointType.BALL): ClosureKind.CONNECT,
            int(newton.JointType.FIXED): ClosureKind.WELD})
        urdf, self._mimics_refused = newton_closures.urdf_mimics(
            lambda: _load(replace(source, text=source.closed_text))[0], list(m.joint_label)
        ) if source.format is Format.URDF and source.closed_text else ((), "")
        self.mimics = newton_closures.mimics(m) + urdf
        self.state = m.state()
        notes: tuple[str, ...] = (
            f"newton: {newton.__version__} on Warp's {DEVICE} device, float32",)
        if source.floating and source.format is Format.URDF:
            notes += ("newton: add_urdf(floating=True): a free joint at the URDF root",)
        self._corrected = corrected
        self.tree = self._tree(notes)

    def _name(self, joint: int) -> str:
        return _last(self.model.joint_label[joint])

    def _reference_q(self) -> np.ndarray:
        """Joints at zero, ball joints at identity, free bodies at the world origin,
        unrotated: q = X_p⁻¹ X_c."""
        m = self.model
        q = np.zeros(m.joint_coord_count)
        x_p, x_c = m.joint_X_p.numpy(), m.joint_X_c.numpy()
        for j, t in enumerate(self.types):
            qs = self.q_start[j]
            if self.kinds.get(int(t)) is JointType.BALL:
                q[qs + 3] = 1.0
            elif self.kinds.get(int(t)) is JointType.FREE:
                q[qs : qs + 7] = _transform(np.linalg.inv(_pose(x_p[j])) @ _pose(x_c[j]))
        return q

    def _fk(self, q: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """Body poses (4×4, float64 from Newton's float32) at ``q``."""
        s = self.state
        s.joint_q.assign(q.astype(np.float32))
        s.joint_qd.assign(np.zeros(self.model.joint_dof_count, np.float32) if v is None
                          else v.astype(np.float32))
        self.newton.eval_fk(self.model, s.joint_q, s.joint_qd, s)
        return np.array([_pose(t) for t in s.body_q.numpy()])

    def _tree(self, notes: tuple[str, ...]) -> ModelTree:
        m = self.model
        bodies = self._fk(self._reference_q())
        x_p, x_c = m.joint_X_p.numpy(), m.joint_X_c.numpy()
        parent, child = m.joint_parent.numpy(), m.joint_child.numpy()
        axes = m.joint_axis.numpy()
        mass, com, inertia = m.body_mass.numpy(), m.body_com.numpy(), m.body_inertia.numpy()
        armature, damping = m.joint_armature.numpy(), m.joint_damping.numpy()
        lower, upper = m.joint_limit_lower.numpy(), m.joint_limit_upper.numpy()
        joint_of = {int(c): j for j, c in enumerate(child) if j not in self.loops}

        def mover(body: int) -> int | None:
            """The joint that moves ``body`` (through fixed joints), None: the world."""
            while body >= 0:
                j = joint_of.get(body)
                if j is None:
                    return None
                if int(self.types[j]) != self.fixed:
                    return j
                body = int(parent[j])
            return None

        carried: dict[int, list[int]] = {}
        for b in range(m.body_count):
            owner = mover(b)
            if owner is not None:
                carried.setdefault(owner, []).append(b)
        joints: list[TreeJoint] = []
        self._masses = mass.astype(float)
        self._coms = com.astype(float)
        fused = {j: self._fused(j) for j, t in enumerate(self.types) if int(t) == self.d6}
        last = {j: chain[-1][0] for j, chain in fused.items()}
        for j, t in enumerate(self.types):
            kind = self.kinds.get(int(t))
            if (kind is None and j not in fused) or j in self.loops:
                continue
            parts = carried.get(j, [])
            total, centre, tensor = lump(
                [float(mass[b]) for b in parts],
                [bodies[b][:3, :3] @ com[b] + bodies[b][:3, 3] for b in parts],
                [bodies[b][:3, :3] @ inertia[b] @ bodies[b][:3, :3].T for b in parts])
            frame = bodies[child[j]] @ _pose(x_c[j])
            above = mover(int(parent[j]))
            if j in fused:
                joints += d6_chain(fused[j], frame=frame, body=self._body(int(child[j])),
                                   axes=axes[self.v_start[j] : self.v_start[j + 1]],
                                   parent=None if above is None else last.get(above,
                                                                              self._name(above)),
                                   lumped=(total, centre, tensor),
                                   starts=(int(self.q_start[j]), int(self.v_start[j])))
                continue
            assert kind is not None
            qs, vs = int(self.q_start[j]), int(self.v_start[j])
            nv = kind.nv
            dofs = slice(vs, vs + nv)
            limited = nv == 1 and abs(lower[vs]) < NO_LIMIT and abs(upper[vs]) < NO_LIMIT
            if kind is JointType.FREE:
                layout = Layout(q_start=qs, v_start=vs, nq=7, nv=6, quat=Orientation.XYZW,
                                linear_axes=Axes.WORLD, angular_axes=Axes.WORLD,
                                placement=_pose(x_p[j]), offset=_pose(x_c[j]),
                                point=np.asarray(com[child[j]], float))
            elif kind is JointType.BALL:
                layout = Layout(q_start=qs, v_start=vs, nq=4, nv=3, quat=Orientation.XYZW,
                                angular_axes=Axes.PARENT)
            else:
                layout = Layout(q_start=qs, v_start=vs, nq=1, nv=1)
            joints.append(TreeJoint(
                name=self._name(j), type=kind,
                parent=None if above is None else last.get(above, self._name(above)),
                body=self._body(int(child[j])),
                axis=frame[:3, :3] @ axes[vs] if nv == 1 else np.zeros(3),
                anchor=frame[:3, 3], frame=frame[:3, :3], mass=total, com=centre,
                inertia=tensor, parts=max(len(parts), 1),
                armature=tuple(float(x) for x in armature[dofs]),
                damping=tuple(float(x) for x in damping[dofs]),
                range=(float(lower[vs]), float(upper[vs])) if limited else None,
                layout=layout,
            ))
        return self._closed(self._finished(joints, notes, carried=carried, fused=fused),
                            bodies=bodies, mover=mover)

    def _closed(self, tree: ModelTree, *, bodies: np.ndarray,
                mover: Callable[[int], int | None]) -> ModelTree:
        """``tree`` with Newton's constraints (:mod:`.closures`: its loop joints at the body
        poses ``bodies``, each on the tree joint ``mover`` names for its body)."""
        closures = newton_closures.read(
            self.model, self.held, self.mimics, bodies=bodies, pose=_pose, name=self._name,
            mover=lambda b: None if (j := mover(b)) is None else self._name(j))
        if self._mimics_refused:
            return replace(tree, closures=closures, closures_read=False, notes=(
                *tree.notes, f"{self._mimics_refused}: its constraints are not read"))
        return replace(tree, closures=closures, closures_read=True,
                       closures_unheld=newton_closures.unheld(
                           self._equalities, loops=len(self.held),
                           mimics=len(self.mimics)))

    def _finished(self, joints: list[TreeJoint], notes: tuple[str, ...], *,
                  carried: dict[int, list[int]],
                  fused: dict[int, list[tuple[str, JointType]]]) -> ModelTree:
        """The tree of ``joints`` with its hints (inertias Newton corrected, fused joints'
        order: both measured, by Newton's own report and by the referee on the order as
        written), actuators and, where it fused joints, their written order."""
        m, child = self.model, self.model.joint_child.numpy()
        hints: list[tuple[str, str, str]] = []
        for j in range(len(self.types)):
            named = [self._body(b) for b in carried.get(j, [])
                     if self._body(b) in self._corrected]
            if named:
                why = CORRECTED.format(bodies=", ".join(repr(b) for b in named))
                hints.append((self._name(j), "inertia", why))
        names = [self._name(j) for j in range(m.joint_count)]
        acts = newton_actuators.read(m, self.newton, names)
        fused = {j: chain for j, chain in fused.items()  # (slides only: applied as written)
                 if [n for n, _ in chain] != self._name(j).split("_")}
        for j, chain in fused.items():
            why = D6_ORDER.format(body=self._body(int(child[j])),
                                  written=" ".join(self._name(j).split("_")),
                                  applied=" ".join(n for n, _ in chain))
            hints += [(name, f, why) for name, _ in chain
                      for f in ("parent", "mass", "com", "inertia")]
        tree = ModelTree(engine=ENGINE, joints=tuple(joints),
                         gravity=np.asarray(m.gravity.numpy()[0], float),
                         nq=m.joint_coord_count, nv=m.joint_dof_count, notes=notes, eps=EPS32,
                         hints=(*hints, *newton_actuators.hints(m, acts)),
                         measured=frozenset(w for _, _, w in hints), actuators=acts)
        tree = proved(m, self.newton, tree, names)  # (#77: on its own solver)
        if not fused:
            return tree
        return replace(tree, as_written=written_order(
            tree, [self._name(j).split("_") for j in fused]))

    def _fused(self, j: int) -> list[tuple[str, JointType]]:
        """The joints Newton's MJCF importer fused into D6 joint ``j``, in the order it
        applies them — its linear axes first, then its angular ones, each group in the
        written order (``jcalc_transform``: translate, then rotate by the angular axes
        composed intrinsically) — named from its label (the written names joined by "_"),
        their kinds from the file."""

        n_lin, n_ang = (int(x) for x in self.model.joint_dof_dim.numpy()[j])
        names = self._name(j).split("_")
        written = {e.get("name"): e.get("type", "hinge")
                   for e in parsing.root(self._text).iter("joint")} if self._text else {}
        slides = [n for n in names if written.get(n) == "slide"]
        hinges = [n for n in names if written.get(n) == "hinge"]
        if len(names) != n_lin + n_ang or len(slides) != n_lin or len(hinges) != n_ang:
            raise Unsupported(f"newton fused joints into a D6 joint ({self._name(j)!r}) whose "
                              "joints its label and the file do not name unambiguously")
        axes = self.model.joint_axis.numpy()[self.v_start[j] + n_lin : self.v_start[j + 1]]
        if n_ang > 1 and np.abs(axes @ axes.T - np.eye(n_ang)).max() > 1e-6:
            raise Unsupported(f"newton's D6 joint {self._name(j)!r} has angular axes that are "
                              "not orthogonal, which it orthonormalizes: not mapped")
        return [(n, JointType.SLIDE) for n in slides] + [(n, JointType.HINGE) for n in hinges]

    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """Its drives' force by its Featherstone solver (:mod:`.actuators`)."""
        return newton_actuators.actuation(
            self.model, self.newton, newton_actuators.drives(self.model, self.newton), q=q,
            v=v, u=u)

    def _body(self, b: int) -> str:
        return _last(self.model.body_label[b])

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        import warp as wp

        m, newton = self.model, self.newton
        n, nv = len(q), m.joint_dof_count
        width = m.max_dofs_per_articulation
        mass_out = wp.zeros((m.articulation_count, width, width), dtype=wp.float32,
                            device=DEVICE)
        gravity_out, coriolis_out, force_out = (
            wp.zeros(nv, dtype=wp.float32, device=DEVICE) for _ in range(3))
        qdd = wp.zeros(nv, dtype=wp.float32, device=DEVICE)
        dofs = self._articulation_dofs()
        mass = np.zeros((n, nv, nv))
        bias, inverse = np.zeros((n, nv)), np.zeros((n, nv))
        potential = np.zeros(n)
        gravity = np.asarray(m.gravity.numpy()[0], float)
        for i in range(n):
            bodies = self._fk(q[i], v[i])
            newton.eval_inverse_dynamics_passive(m, self.state, mass_matrix=mass_out,
                                                 gravity_force=gravity_out,
                                                 coriolis_force=coriolis_out)
            blocks = mass_out.numpy()
            for k, index in enumerate(dofs):
                mass[i][np.ix_(index, index)] = blocks[k, : len(index), : len(index)]
            bias[i] = gravity_out.numpy() + coriolis_out.numpy()
            qdd.assign(a[i].astype(np.float32))
            newton.eval_inverse_dynamics_force(m, self.state, mass_matrix=mass_out,
                                               joint_qdd=qdd, coriolis_force=coriolis_out,
                                               gravity_force=gravity_out, joint_f=force_out)
            inverse[i] = force_out.numpy()
            centres = np.einsum("bij,bj->bi", bodies[:, :3, :3], self._coms) + bodies[:, :3, 3]
            potential[i] = -float(self._masses @ (centres @ gravity))
        return Dynamics.at(v, mass_matrix=mass, bias=bias, inverse=inverse,
                           potential=potential, forward=self._solved(mass, -bias))

    def _solved(self, mass: np.ndarray, force: np.ndarray) -> np.ndarray:
        """M⁻¹ f on the degrees of freedom its articulations move; a loop joint's own (#78:
        a constraint, which no articulation moves, its block of M zero) keep v̇ = 0."""
        if not self.loops:
            return np.linalg.solve(mass, force[..., None])[..., 0]
        moved = np.concatenate(self._articulation_dofs())
        out = np.zeros_like(force, dtype=float)
        out[:, moved] = np.linalg.solve(mass[:, moved[:, None], moved[None, :]],
                                        force[:, moved, None])[..., 0]
        return out

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ at τ: M⁻¹ (τ − h) (:meth:`_solved`)."""
        d = self.dynamics(q, v, np.zeros_like(v))
        return self._solved(d.mass_matrix, tau - d.bias)

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """Its M and h closed by its constraints' rows from its own kinematics
        (:func:`.closures.rows`, :func:`.closures.closed`)."""
        d = self.dynamics(q, v, np.zeros_like(v))
        held = newton_closures.rows(self.model, self.newton, self.state, loops=self.held,
                                    mimicked=self.mimics, q=q, v=v, pose=_pose)
        return newton_closures.closed(d.mass_matrix, tau - d.bias, held,
                                      moved=np.concatenate(self._articulation_dofs()))

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``steps`` steps of Newton's Featherstone solver (``SolverFeatherstone``: forward
        dynamics by the articulated-body algorithm, then semi-implicit Euler, v₊ = v + h v̇,
        q₊ = q + h v₊ on hinges and slides), from (q0, v0), no control, no contacts: q and v
        at every step, the start included (float64 from Newton's float32). ``field``: forces
        on bodies at the centres of mass its state holds at each step's start, given as its
        ``State.body_f`` (world axes, at the centre of mass)."""
        model, newton = self.model, self.newton
        solver = newton.solvers.SolverFeatherstone(model)
        now, after, control = model.state(), model.state(), model.control()
        now.joint_q.assign(np.asarray(q0, np.float32))
        now.joint_qd.assign(np.asarray(v0, np.float32))
        newton.eval_fk(model, now.joint_q, now.joint_qd, now)
        qs = np.zeros((steps + 1, len(q0)))
        vs = np.zeros((steps + 1, len(v0)))
        qs[0], vs[0] = now.joint_q.numpy(), now.joint_qd.numpy()
        for k in range(1, steps + 1):
            now.clear_forces()
            if field is not None:
                self._apply(now, field)
            solver.step(now, after, control, None, dt)
            now, after = after, now
            qs[k], vs[k] = now.joint_q.numpy(), now.joint_qd.numpy()
        return qs, vs

    def _apply(self, state: Any, field: Field) -> None:
        """``field`` at the centres of mass of ``state``'s bodies (its ``body_q``), written
        to its ``body_f`` (linear force first, world axes, at the centre of mass)."""
        assert state.body_q is not None and state.body_f is not None
        poses = state.body_q.numpy()
        index = {self._body(b): b for b in range(self.model.body_count)}
        where = {}
        for name in index:
            pose = _pose(poses[index[name]])
            where[name] = pose[:3, :3] @ self._coms[index[name]] + pose[:3, 3]
        wrench = np.zeros((self.model.body_count, 6), np.float32)
        for name, force in field(where).items():
            wrench[index[name], :3] = force
        state.body_f.assign(wrench)

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """The field's generalized force by its Featherstone solver: its net joint force
        ``joint_tau`` of one step with the field in ``body_f`` minus without (float32)."""
        model, newton = self.model, self.newton
        solver = newton.solvers.SolverFeatherstone(model)
        now, after, control = model.state(), model.state(), model.control()
        out = np.zeros((len(q), model.joint_dof_count))
        for i in range(len(q)):
            taus = []
            for forced in (True, False):
                now.joint_q.assign(q[i].astype(np.float32))
                now.joint_qd.assign(v[i].astype(np.float32))
                newton.eval_fk(model, now.joint_q, now.joint_qd, now)
                now.clear_forces()
                if forced:
                    self._apply(now, field)
                solver.step(now, after, control, None, 1e-3)
                taus.append(solver.joint_tau.numpy().astype(float))
            out[i] = taus[0] - taus[1]
        return out

    def _articulation_dofs(self) -> list[np.ndarray]:
        """Each articulation's velocity indices, in Newton's order."""
        m = self.model
        of = m.joint_articulation.numpy()
        out = []
        for k in range(m.articulation_count):
            index = [np.arange(self.v_start[j], self.v_start[j + 1])
                     for j in np.flatnonzero(of == k)]
            out.append(np.concatenate(index) if index else np.zeros(0, int))
        return out


PROOFS = {
    "CORRECTED": Proof.MEASURED,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
