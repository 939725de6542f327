"""The engine-neutral description of a loaded model, read back from each engine.

A tree of *joints*: each joint carries the rigid body that moves with it and with no joint
below it (an engine's fused or welded links lumped in), so that engines which fuse fixed links
(MuJoCo's URDF compiler, Pinocchio) and engines which keep them (Drake) describe the same
thing. Where one body carries several joints, its inertia goes to the last of them and the
others carry none (as Pinocchio models it). Every vector and tensor is in world axes at the
engine's reference configuration (hinges and slides at 0 — MuJoCo: at ``ref`` —,
ball joints at identity, free bodies at the world origin, unrotated), the inertia tensor
about the lumped centre of mass (§2.2, (2.2.39)). The state layout — where a joint's
coordinates sit in the engine's q and v, quaternion order, the axes of a free joint's
velocities — is declared with each joint, so that the comparison layer maps states without
knowing the engine.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from enum import StrEnum
from typing import Any

import numpy as np

from dyncheck.adapters.actuators import Actuator
from dyncheck.adapters.closures import Closure
from dyncheck.vocabulary import JointType, Quantity


class Axes(StrEnum):
    """The axes a velocity (or a generalized force) is resolved in."""

    WORLD = "world"
    LOCAL = "local"
    PARENT = "parent"
    """A ball joint's parent-side frame F, which coincides with the child's frame at the
    reference configuration (Drake's ``BallRpyJoint``: v = ω of the child in F, in F)."""
    RATES = "rates"
    """Not axes: the rates of a chart's angles (:attr:`Orientation.EULER`), v = J⁻¹ ω
    (exercise 23)."""


class Orientation(StrEnum):
    """How a ball or free joint's orientation is held in q."""

    WXYZ = "wxyz"
    """A unit quaternion, scalar first (MuJoCo, Drake's free joint)."""
    XYZW = "xyzw"
    """A unit quaternion, scalar last (Pinocchio, Newton, PyBullet)."""
    RPY = "rpy"
    """A ball joint's (roll, pitch, yaw), R = R_z(yaw) R_y(pitch) R_x(roll) (Drake's
    ``BallRpyJoint``): three coordinates."""
    EULER = "euler"
    """Example 9's angles (body Z, X, Z) (dyncheck's sympy-mechanics model): three
    coordinates, their rates the velocities (:attr:`Axes.RATES`)."""

    @property
    def quaternion(self) -> bool:
        return self in (Orientation.WXYZ, Orientation.XYZW)


class GravityFrame(StrEnum):
    """The rotation through which an engine's dynamics resolve gravity in a free body's frame."""

    STATE = "state"
    """The body's orientation in the state (every engine, as the book, (2.2.23)–(2.2.26))."""
    RPY_REVERSED = "rpy-reversed"
    """Rx(r) Ry(p) Rz(y) of the roll, pitch, yaw (r, p, y) of the state's orientation
    Rz(y) Ry(p) Rx(r): the three composed in reverse order (PyBullet 3.2.7's
    ``calculateInverseDynamics`` of a floating base, measured)."""


def reversed_rpy(rotation: np.ndarray) -> np.ndarray:
    """R′ = Rx(r) Ry(p) Rz(y) where ``rotation`` = Rz(y) Ry(p) Rx(r), p in [−π/2, π/2]
    (:attr:`GravityFrame.RPY_REVERSED`)."""
    from scipy.spatial.transform import Rotation

    rpy = Rotation.from_matrix(rotation).as_euler("xyz")
    return Rotation.from_euler("XYZ", rpy).as_matrix()


NQ = {t: t.nq for t in JointType}
NV = {t: t.nv for t in JointType}
"""Coordinates per joint type, from :class:`~dyncheck.vocabulary.JointType`."""


@dataclass(frozen=True, kw_only=True)
class Layout:
    """Where one joint's coordinates sit in an engine's q and v, and in which convention — the
    one description of a state's layout, for the run's cases (:class:`StateLayout`) and the
    check's models alike.

    ``quat``: a ball or free joint's orientation (:class:`Orientation`); a free joint's q is
    ``(p, orientation)`` unless ``quat_first``; its v is ``(linear, angular)`` unless
    ``angular_first``, each resolved in ``linear_axes`` / ``angular_axes`` (a ball joint's ω
    in ``angular_axes``). ``cos_sin``: a hinge stored as (cos θ, sin θ) (an unbounded revolute
    joint)."""

    q_start: int
    v_start: int
    nq: int
    nv: int
    quat: Orientation = Orientation.WXYZ
    quat_first: bool = False
    angular_first: bool = False
    linear_axes: Axes = Axes.WORLD
    angular_axes: Axes = Axes.LOCAL
    cos_sin: bool = False
    zero: float = 0.0  # hinge, slide: the coordinate's value at the reference configuration
    placement: np.ndarray = field(default_factory=lambda: np.eye(4))  # free: world ← q's frame
    offset: np.ndarray = field(default_factory=lambda: np.eye(4))
    """Free: the body's frame ← the frame whose pose q holds (PyBullet: the base's
    centre-of-mass frame; Newton: ``joint_X_c``); ``local`` axes are that frame's."""
    point: np.ndarray | None = None
    """Free: the point of the body (body frame) whose velocity v holds (Newton: the centre
    of mass); None: the origin of :attr:`offset`'s frame."""

    @classmethod
    def ball(cls, **convention: Any) -> Layout:
        """A ball joint's layout at the start of q and v (:meth:`StateLayout.joint` places it)."""
        quat = Orientation(convention.get("quat", Orientation.WXYZ))
        return cls(q_start=0, v_start=0, nq=4 if quat.quaternion else 3, nv=3, **convention)

    @classmethod
    def free(cls, **convention: Any) -> Layout:
        """A free joint's layout at the start of q and v (:meth:`StateLayout.joint` places it)."""
        quat = Orientation(convention.get("quat", Orientation.WXYZ))
        return cls(q_start=0, v_start=0, nq=7 if quat.quaternion else 6, nv=6, **convention)


@dataclass(frozen=True, kw_only=True)
class StateLayout:
    """How every ball and every free joint is held (:class:`Layout`) by a chart declared once
    (sympy.physics.mechanics's angles); an engine's own layout is read from its model, each
    joint's, and measured on the installed versions (tests/adapters/test_state_layouts.py
    rotates a body by a known quaternion and reads it back). The default
    is the canonical layout, MuJoCo's: quaternion (w, x, y, z), a free joint's position first,
    ω in body axes, a free joint's linear velocity in world axes, (v, ω)."""

    ball: Layout = field(default_factory=Layout.ball)
    free: Layout = field(default_factory=Layout.free)

    def joint(self, kind: JointType, *, q_start: int, v_start: int) -> Layout:
        """The layout of a joint of ``kind`` whose coordinates start at ``q_start``, ``v_start``."""
        if kind is JointType.BALL:
            return replace(self.ball, q_start=q_start, v_start=v_start)
        if kind is JointType.FREE:
            return replace(self.free, q_start=q_start, v_start=v_start)
        return Layout(q_start=q_start, v_start=v_start, nq=1, nv=1)

    def joints(self, kinds: Sequence[JointType]) -> list[Layout]:
        """The layouts of consecutive joints of ``kinds`` (their coordinates one after another)."""
        out, q_start, v_start = [], 0, 0
        for kind in kinds:
            out.append(self.joint(kind, q_start=q_start, v_start=v_start))
            q_start, v_start = q_start + out[-1].nq, v_start + out[-1].nv
        return out

    @property
    def charted(self) -> bool:
        """Whether a ball joint is held in angles (a chart), not a quaternion."""
        return not self.ball.quat.quaternion


@dataclass(frozen=True, kw_only=True)
class TreeJoint:
    """One joint and the rigid body it alone moves (world axes, reference configuration)."""

    name: str
    type: JointType
    parent: str | None
    body: str
    axis: np.ndarray  # unit axis (hinge, slide); zeros otherwise
    anchor: np.ndarray  # a point on the axis / the ball's centre / the free body's origin
    frame: np.ndarray  # 3×3 orientation of the joint's child frame (ball, free)
    mass: float
    com: np.ndarray
    inertia: np.ndarray  # about the centre of mass
    armature: tuple[float, ...]
    damping: tuple[float, ...]
    range: tuple[float, float] | None  # (lower, upper) where the joint is limited
    layout: Layout
    rotor_in_kinetic: bool = True
    """Whether the engine's kinetic energy counts this joint's rotor energy ½ aᵢ vᵢ² (its M
    does wherever it holds the armature)."""
    gravity_frame: GravityFrame = GravityFrame.STATE
    """A free joint: how the engine's h and inverse dynamics resolve gravity in its body's
    frame (the frame whose pose q holds, :attr:`Layout.offset`)."""
    computed_inertia: np.ndarray | None = None
    """The inertia (about the centre of mass, world axes) the engine's dynamics compute with
    where a measured defect makes it differ from the ``inertia`` it holds (PyBullet's
    spherical joint: its link's principal moments taken in the link's axes); None: the held
    one."""
    inertia_derived_from: float = 0.0
    """The size (kg m², a trace) of the tensor the engine's ``inertia`` was derived from where
    it holds another (Drake: about the body's origin, m d² larger; the one about the centre
    of mass is its difference, known to that tensor's round-off); 0: held as stated."""
    parts: int = 1
    """How many bodies' mass properties the engine summed into this joint's body (rigidly
    joined links lumped): the round-off of its mass, centre of mass and inertia grows with
    the sum (:mod:`dyncheck.check.describe`)."""


@dataclass(frozen=True, kw_only=True)
class FixedReading:
    """The engine's own reading of a copy of the model with one hint's fix applied: the
    counterfactual that proves (or disproves) the cause the hint names (#77). ``subject``
    and ``fields``: the hint's (joint, or ``model`` for every joint); ``tree``: the copy as
    the engine reads it, None where it refused the copy (``refused``: its words)."""

    subject: str
    fields: tuple[str, ...]
    fix: str
    """The fix, in words (as the hint names it)."""
    tree: ModelTree | None
    refused: str = ""


@dataclass(frozen=True, kw_only=True)
class FixedCopy:
    """A copy of the model with every fix of the engine's hints that edits the file applied
    together (``fix``: in words; ``text``: the copy, its includes inlined and its asset
    paths absolute): what the engine is run on to answer whether it computes the whole
    model, where it reads the file itself only in part or otherwise (#77)."""

    fix: str
    text: str


@dataclass(frozen=True, kw_only=True)
class Inertial:
    """A body's mass properties as an MJCF ``<inertial>`` states them, in the body's frame:
    its centre of mass ``pos``, principal axes ``quat`` (w x y z), ``mass`` and principal
    moments ``diaginertia``."""

    pos: tuple[float, ...]
    quat: tuple[float, ...]
    mass: float
    diaginertia: tuple[float, ...]


@dataclass(frozen=True, kw_only=True)
class WantsCompiled:
    """A hint whose fix states in the file what the canonical engine compiled: "give the body
    an ``<inertial>``" (``bodies``, by name) or "state stiffness= and damping= on the joint"
    (``joints``); the (``subject``, ``fields``) it explains. The comparison layer applies it
    to a copy, with the canonical engine's values (:attr:`ModelTree.inertials`,
    :attr:`ModelTree.springs`), and has the engine read that copy (:attr:`ModelTree.fixed`)."""

    subject: str
    fields: tuple[str, ...]
    bodies: tuple[str, ...] = ()
    joints: tuple[str, ...] = ()
    every: bool = False
    """Every body stated, and the compiler's ``settotalmass`` dropped (the masses stated
    are already the scaled ones). On the canonical engine's tree: its hint's fix, read by
    each other engine (an attribute only it applies)."""
    box: bool = False
    """The bodies' geoms replaced by one box of the stated inertia, at its centre of mass and
    principal axes: for an engine that takes a body's mass from ``<inertial>`` but its
    inertia from the geoms only (PyBullet's MJCF reader)."""


@dataclass(frozen=True, kw_only=True)
class ModelTree:
    """What one engine holds after reading a file."""

    engine: str
    joints: tuple[TreeJoint, ...]
    gravity: np.ndarray
    nq: int
    nv: int
    notes: tuple[str, ...] = field(default=())
    eps: float = float(np.finfo(float).eps)
    """The engine's arithmetic precision (a float32 port: ε₃₂), which its round-off bounds
    use."""
    inertia_accuracy: float = 0.0
    """How exactly, relative to its trace, the engine stores a body's inertia tensor beyond
    round-off (PyBullet: principal moments from a Jacobi diagonalization that stops at
    off-diagonal terms ≤ 1e-6 trace); why: :meth:`hint` of ("model", "inertia accuracy")."""
    hints: tuple[tuple[str, str, str], ...] = field(default=())
    """(joint, field, why): what the engine is known to do with that field of that joint and
    how to change it — the note of a description row that finds the field read differently;
    joint ``model``: of every joint."""
    mesh_rounding: Mapping[str, float] = field(default_factory=dict)
    """Joint → how far, relative, the mass, centre of mass and inertia its bodies take from
    meshes may lie from the file's digits (MuJoCo: vertices held in float32); absent: none."""
    actuators: tuple[Actuator, ...] = ()
    """Its actuators (:mod:`dyncheck.adapters.actuators`), in the order of its control
    vector; none where it holds none, or holds no actuator model at all (its class does not
    offer :attr:`~dyncheck.adapters.base.Offer.ACTUATION`)."""
    closures: tuple[Closure, ...] = ()
    """The constraints that close its tree, as it holds them
    (:mod:`dyncheck.adapters.closures`); none where it holds none or states none."""
    closures_read: bool = False
    """Whether its loader reads the file's constraints into :attr:`closures` (False: none
    are read, whatever the file holds: its notes say why where it was given a copy
    without them)."""
    closures_unheld: tuple[tuple[str, str], ...] = ()
    """Each kind of constraint (:class:`~dyncheck.adapters.closures.ClosureKind`'s value) its
    loader drops, with how that is known: its own words (a parser's warning, quoted) or the
    measurement."""
    exact_meshes: ModelTree | None = None
    """The engine's reading with every mesh's volume and inertia computed exactly (MuJoCo:
    ``inertia="exact"`` instead of its default ``"legacy"``, which overcounts a non-convex
    mesh's volume, or ``"convex"``, the hull's); None where that changes no body."""
    as_written: ModelTree | None = None
    """The reading with the joints of each body in the order the file writes them, where the
    engine applies them in another (Newton's D6 joint: slides first); None where it applies
    them as written. The referee on both measures what the order changes."""

    measured: frozenset[str] = frozenset()
    """The :attr:`hints` (their text) the engine proved by its own measurement: its own
    report of what it did (a correction it warned of), or the difference measured on its
    counterfactual reading (:attr:`as_written`) or its converted plant."""
    fixed: tuple[FixedReading, ...] = ()
    """Its readings of copies of the model, each with one hint's fix applied (the fix
    measured, :class:`FixedReading`); a hint without one is not verified."""
    inertials: Mapping[str, Inertial] = field(default_factory=dict)
    """Body name → its mass properties as the engine compiled them from the file (MuJoCo, on
    an MJCF): what a copy states so that another engine reads the same, the fix of
    :attr:`wants_compiled`; empty where the engine offers none."""
    springs: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    """Joint name → its (stiffness, damping) as the engine compiled them (MuJoCo, on an MJCF:
    ``springdamper`` resolved); empty where the engine offers none."""
    with_fixes: FixedCopy | None = None
    """The copy with every file edit its hints name applied together, where it has any."""
    wants_compiled: tuple[WantsCompiled, ...] = ()
    """Its hints whose fix states what the canonical engine compiled (:class:`WantsCompiled`)."""

    def fixed_reading(self, joint: str, name: str) -> FixedReading | None:
        """The fixed copy's reading for the hint :meth:`hint` gives (``joint``'s own, else
        the model's), if its fix was applied."""
        for wanted in (joint, "model"):
            if any(j == wanted and f == name for j, f, _ in self.hints):
                return next((r for r in self.fixed
                             if r.subject == wanted and name in r.fields), None)
        return None

    def hint(self, joint: str, name: str) -> str | None:
        for wanted in (joint, "model"):
            why = next((w for j, f, w in self.hints if j == wanted and f == name), None)
            if why is not None:
                return why
        return None

    def joint(self, name: str) -> TreeJoint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)


@dataclass(frozen=True, kw_only=True)
class Dynamics:
    """An engine's smooth dynamics at a batch of states, in its own layout: M (n, nv, nv),
    h = C v + g (n, nv), forward dynamics at τ = 0 (n, nv), inverse dynamics at the given
    accelerations (n, nv), kinetic and potential energy (n,)."""

    mass_matrix: np.ndarray
    bias: np.ndarray
    forward: np.ndarray
    inverse: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    unavailable: tuple[tuple[str, str], ...] = ()
    """(field, why) for a field the engine does not compute on this model (its values NaN):
    its limit, a skipped row of that quantity in the engine's words."""

    @classmethod
    def at(cls, v: np.ndarray, *, mass_matrix: np.ndarray, bias: np.ndarray,
           inverse: np.ndarray, potential: np.ndarray, forward: np.ndarray | None = None,
           unavailable: tuple[tuple[str, str], ...] = ()) -> Dynamics:
        """From M and h at velocities ``v``: T = ½ vᵀ M v and, unless the engine gave it,
        the forward dynamics at τ = 0, v̇ = −M⁻¹ h."""
        if forward is None:
            forward = -np.linalg.solve(mass_matrix, bias[..., None])[..., 0]
        kinetic = 0.5 * np.einsum("ni,nij,nj->n", v, mass_matrix, v)
        return cls(mass_matrix=mass_matrix, bias=bias, forward=forward, inverse=inverse,
                   kinetic=kinetic, potential=potential, unavailable=unavailable)


QUANTITY_OF: dict[str, Quantity] = dict(zip(
    (f.name for f in fields(Dynamics)),
    (Quantity.MASS_MATRIX, Quantity.BIAS_FORCES, Quantity.FORWARD_DYNAMICS,
     Quantity.INVERSE_DYNAMICS, Quantity.KINETIC_ENERGY, Quantity.POTENTIAL_ENERGY),
    strict=False))  # (its last field, ``unavailable``, is no quantity)
"""A field of :class:`Dynamics` → the quantity it holds."""


class DerivativeChart(StrEnum):
    """With respect to which coordinates of q an engine's derivatives are taken."""

    TANGENT = "tangent"
    """Its velocity coordinates: δ moves q as its own integration of a velocity δ would (a
    hinge's angle; a ball's or free body's rotation in the axes of its angular velocity)."""
    COORDINATES = "coordinates"
    """Its position coordinates themselves (a quaternion's four entries, roll-pitch-yaw):
    Drake's automatic differentiation seeds q."""


@dataclass(frozen=True, kw_only=True)
class Derivatives:
    """An engine's derivatives of the smooth dynamics at a batch of states, in its own layout
    and chart (n, nv, nv each; J[s, i, j] = ∂ outᵢ / ∂ inⱼ): of the forward dynamics at
    τ = 0 with respect to q, v and τ (the last is M⁻¹), and of the inverse dynamics at the
    given accelerations with respect to q and v (with respect to v̇ it is M, compared with
    the dynamics). ``method`` says how the engine computed them; ``step``, a finite
    difference's step (0: none)."""

    forward_q: np.ndarray
    forward_v: np.ndarray
    forward_tau: np.ndarray
    inverse_q: np.ndarray
    inverse_v: np.ndarray
    method: str
    step: float = 0.0
    chart: DerivativeChart = DerivativeChart.TANGENT
    defect: str = ""
    """A defect the engine's own derivatives are known to have on this model (measured), or
    empty; then :attr:`own_differences` holds the engine's finite differences of its own
    dynamics, which the check compares after its analytic ones."""
    own_differences: Derivatives | None = None
    about_origin: tuple[str, ...] = ()
    """The fields the engine forms from spatial quantities about the world origin (a world-
    axes algorithm: a body's inertia there carries m |c|², c its distance from the origin):
    their round-off grows as ε (X/ℓ)², X how far the model stands from the origin, ℓ its
    size — where the others' grows as ε X/ℓ."""


def derivatives(found: dict[str, np.ndarray], *, method: str, step: float = 0.0,
                chart: DerivativeChart = DerivativeChart.TANGENT) -> Derivatives:
    """:class:`Derivatives` from a dict of its five matrices (the engines fill one)."""
    return Derivatives(forward_q=found["forward_q"], forward_v=found["forward_v"],
                       forward_tau=found["forward_tau"], inverse_q=found["inverse_q"],
                       inverse_v=found["inverse_v"], method=method, step=step, chart=chart)


@dataclass(frozen=True, kw_only=True)
class Transition:
    """An engine's Jacobian of one integrator step, x₊ = step(x), x = (δq, v) in its chart
    (n, 2 nv, 2 nv), by finite differences of step ``fd_step`` and, for their error, of
    twice that step (``coarse``)."""

    matrix: np.ndarray
    coarse: np.ndarray
    time_step: float
    fd_step: float
    integrator: str
    unfollowed: str = ""
    """Why the referee's chain rule does not follow this integrator's step on this model
    (RK4's naive stages on a rotation before MuJoCo 4.0): then no differences are taken
    (``matrix`` and ``coarse`` empty) and the row is skipped, saying this; empty: it does."""
    implicit_bias: tuple[str, ...] = ()
    """The free joints whose velocities the step updates with (M + h ∂h/∂v)⁻¹ rather than
    M⁻¹: MuJoCo's implicitfast on a standalone free body (``mjd_freeMhat``, ≥ 3.11: the
    bias's — gyroscopic — derivative in the body's own 6×6 solve)."""


def geared(tree: ModelTree, acting: Mapping[str, tuple[float, float]],
           fix: Callable[[float], str]) -> tuple[FixedReading, ...]:
    """The fixed readings of a fix made on the engine that has each actuator named in
    ``acting`` act with the gear measured with it (name → the file's gear, the measured
    one): one per actuator, its ``gear`` field, ``fix(file's gear)`` its words."""
    fixed = replace(tree, actuators=tuple(
        replace(a, gear=acting[a.name][1]) if a.name in acting else a for a in tree.actuators))
    return tuple(FixedReading(subject=name, fields=("gear",), tree=fixed, fix=fix(gear))
                 for name, (gear, _) in acting.items())


@dataclass(frozen=True, kw_only=True)
class Canonical:
    """The canonical joint order and where each joint's coordinates sit in it."""

    names: tuple[str, ...]
    types: tuple[JointType, ...]
    q_start: tuple[int, ...]
    v_start: tuple[int, ...]
    nq: int
    nv: int
    zeros: tuple[float, ...]  # a hinge's or slide's coordinate at the reference configuration


def canonical(tree: ModelTree) -> Canonical:
    """The tree's joints in its order, each joint's coordinates where the canonical layout
    (MuJoCo's) puts them."""
    types = tuple(j.type for j in tree.joints)
    places = StateLayout().joints(types)  # the canonical layout: MuJoCo's
    return Canonical(
        names=tuple(j.name for j in tree.joints), types=types,
        q_start=tuple(p.q_start for p in places), v_start=tuple(p.v_start for p in places),
        nq=sum(p.nq for p in places), nv=sum(p.nv for p in places),
        zeros=tuple(j.layout.zero for j in tree.joints),
    )
