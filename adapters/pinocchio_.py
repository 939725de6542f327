"""Pinocchio behind the canonical form, two ways: built programmatically from the
engine-neutral model (``pinocchio``) and loaded from the same MJCF file through Pinocchio's own
MJCF parser (``pinocchio-mjcf``).

Pinocchio's names: M = ``crba`` (upper triangle filled, mirrored here); h = ``rnea(q, v, 0)``
(= ``nonLinearEffects``, gravity included); forward dynamics ``aba``; inverse ``rnea``;
``computeKineticEnergy``, ``computePotentialEnergy`` (V = −Σ mᵢ g·cᵢ). Pinocchio has no time
integrator: :mod:`.integrators` supplies MuJoCo's definitions, run in MuJoCo's state layout
(a quaternion (w, x, y, z); a free joint's linear velocity in world axes, v_w = R v_b, whose
rate is R (v̇_b + ω × v_b)), so that the maps compare like for like; and
:meth:`PinocchioAdapter.solve` integrates with scipy's error-controlled DOP853, on the rotation
group in re-centred exponential coordinates.

Couplings: Pinocchio's constrained forward dynamics ``forwardDynamics(q, v, τ, C, γ = 0)``
(an exact KKT solve with the constant constraint Jacobian C; the multipliers in
``data.lambda_c``, with M v̇ + h = τ + Cᵀ λ). Pinocchio's MJCF parser drops the tendon
equality (see ``dyncheck explain pinocchio-mjcf-equality``), so ``pinocchio-mjcf`` takes C
from the engine-neutral model as well.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from typing import ClassVar

import numpy as np
import pinocchio as pin

from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.adapters.integrators import Addresses, cross, integrate, solve_on_group
from dyncheck.adapters.mjcf import to_mjcf
from dyncheck.adapters.model_tree import Axes, Layout, Orientation, StateLayout
from dyncheck.adapters.pinocchio_registration import REGISTRATIONS
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.cases.multibody import Joint, Multibody
from dyncheck.vocabulary import Integrator

THREADS = max(1, min(2, os.cpu_count() or 1))
"""Threads for Pinocchio's batched ABA/RNEA (the machines this runs on have 2 cores)."""

_AXIS_JOINTS = {
    ("hinge", (1.0, 0.0, 0.0)): pin.JointModelRX,
    ("hinge", (0.0, 1.0, 0.0)): pin.JointModelRY,
    ("hinge", (0.0, 0.0, 1.0)): pin.JointModelRZ,
    ("slide", (1.0, 0.0, 0.0)): pin.JointModelPX,
    ("slide", (0.0, 1.0, 0.0)): pin.JointModelPY,
    ("slide", (0.0, 0.0, 1.0)): pin.JointModelPZ,
}


def _joint(joint: Joint) -> pin.JointModel:
    if joint.type == "ball":
        return pin.JointModelSpherical()  # q = (x, y, z, w), v = angular velocity, local
    if joint.type == "free":
        return pin.JointModelFreeFlyer()  # q = (p, x, y, z, w), v = (v, ω) both local
    axis = tuple(float(x) for x in joint.axis)
    if (joint.type, axis) in _AXIS_JOINTS:
        return _AXIS_JOINTS[joint.type, axis]()
    if joint.type == "hinge":
        return pin.JointModelRevoluteUnaligned(np.asarray(axis))
    return pin.JointModelPrismaticUnaligned(np.asarray(axis))


def build_model(model: Multibody) -> pin.Model:
    """A ``pin.Model`` built with ``addJoint`` and ``appendBodyToJoint``; a body with several
    joints becomes a chain of joints (massless links between them); point masses exact.
    Each body gets a BODY frame of its name on its last joint."""
    pm = pin.Model()
    pm.name = model.name
    pm.gravity = pin.Motion(np.asarray(model.gravity, float), np.zeros(3))
    joint_of: dict[str | None, int] = {None: 0}
    for body in model.bodies:
        jid = joint_of[body.parent]
        placement = pin.SE3(np.eye(3), np.asarray(body.joint_pos, float))
        for joint in body.joints:
            jid = pm.addJoint(jid, _joint(joint), placement, joint.name)
            placement = pin.SE3.Identity()
        inertia = pin.Inertia(body.mass, np.asarray(body.com, float), model.body_inertia(body))
        pm.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        pm.addFrame(pin.Frame(body.name, jid, 0, pin.SE3.Identity(), pin.FrameType.BODY))
        joint_of[body.name] = jid
    return pm


def load_mjcf(xml: str) -> pin.Model:
    """``pin.buildModelFromMJCF`` on the MJCF text (through a temporary file)."""
    fd, path = tempfile.mkstemp(suffix=".xml")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(xml)
        return pin.buildModelFromMJCF(path)
    finally:
        os.unlink(path)


class PinocchioAdapter(Adapter):
    name: ClassVar[str] = "pinocchio"
    state_layout: ClassVar[StateLayout] = StateLayout(
        ball=Layout.ball(quat=Orientation.XYZW),
        free=Layout.free(quat=Orientation.XYZW, linear_axes=Axes.LOCAL))
    """``JointModelSpherical``: q (x, y, z, w), ω in the joint's local frame; free-flyer q
    (p, x, y, z, w), v (v, ω) both in the body frame (programmatic or from MJCF)."""
    package: ClassVar[str] = "pin"
    integrators: ClassVar[tuple[str, ...]] = REGISTRATIONS["pinocchio"].integrators
    adaptive: ClassVar[bool] = True

    def __init__(self, model: Multibody) -> None:
        super().__init__(model)
        self.model = self._build(model)
        self.data = self.model.createData()
        self.__pool: pin.ModelPool | None = None
        # the joint that carries each body's inertia, found through the body's frame
        self._joint_ids = [self._body_joint(b.name) for b in model.bodies]
        self._C = model.coupling_matrix() if model.couplings else None
        self.layout = Addresses.of([j.type for j in model.joints])
        # MuJoCo's positions → Pinocchio's: each quaternion (w, x, y, z) → (x, y, z, w), as
        # one permutation of q (and its inverse); the free joints, whose linear velocity
        # changes frame
        self._to_pin = np.arange(self.model.nq)
        self._free: list[tuple[int, int]] = []
        for jt, qa, va in self.layout.joints:
            if jt in ("ball", "free"):
                k = qa + (3 if jt == "free" else 0)
                self._to_pin[k : k + 4] = [k + 1, k + 2, k + 3, k]
            if jt == "free":
                self._free.append((qa, va))
        self._to_mj = np.argsort(self._to_pin)
        self._zero_tau = np.zeros(self.model.nv)  # τ = 0 at every stage (read-only to ABA)
        # the field's constants, read once (:meth:`_fext` runs at every stage): each body's
        # mass, joint and centre of mass in that joint's frame, and every joint's zero force
        self._levers = [
            (b.mass, j, np.array(self.model.inertias[j].lever))
            for b, j in zip(model.bodies, self._joint_ids, strict=True)
        ]
        self._no_forces = pin.StdVec_Force()
        self._no_forces.extend([pin.Force.Zero() for _ in range(self.model.njoints)])

    def _build(self, model: Multibody) -> pin.Model:
        return build_model(model)

    def _body_joint(self, name: str) -> int:
        frame = self.model.frames[self.model.getFrameId(name, pin.FrameType.BODY)]
        return int(frame.parentJoint)

    @staticmethod
    def version() -> str:
        return pin.__version__

    def loaded_bodies(self) -> list[LoadedBody]:
        return [
            LoadedBody(
                b.name, float(self.model.inertias[j].mass), np.array(self.model.inertias[j].inertia)
            )
            for b, j in zip(self.spec.bodies, self._joint_ids, strict=True)
        ]

    def loaded_gravity(self) -> np.ndarray:
        return np.array(self.model.gravity.linear)

    def _fext(self, q: np.ndarray) -> pin.StdVec_Force | None:
        """The field as Pinocchio's external forces: per joint, in the joint's local frame,
        the force at each body's centre of mass (``None`` without a field)."""
        if not self.spec.central_mu:
            return None
        d = self.data
        pin.forwardKinematics(self.model, d, q)
        fext = pin.StdVec_Force(self._no_forces)  # a copy
        for mass, j, lever in self._levers:
            c = d.oMi[j].act(lever)
            F = self.spec.central_force(mass, c)
            fext[j] = fext[j] + d.oMi[j].actInv(pin.Force(F, cross(c, F)))
        return fext

    def _constrained(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ of the KKT solve; the multipliers are left in ``data.lambda_c``."""
        gamma = np.zeros(self._C.shape[0])  # C is constant: no drift term
        return pin.forwardDynamics(self.model, self.data, q, v, tau, self._C, gamma).copy()

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty((q.shape[0], self._C.shape[0]))
        for k in range(q.shape[0]):
            self._constrained(q[k], v[k], tau[k])
            out[k] = self.data.lambda_c
        return self._check("constraint force", out)

    def _aba(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, fext=None) -> np.ndarray:
        if self._C is not None:
            return self._constrained(q, v, tau)
        fext = self._fext(q) if fext is None else fext
        if fext is None:
            return pin.aba(self.model, self.data, q, v, tau)
        return pin.aba(self.model, self.data, q, v, tau, fext)

    def _rnea(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        fext = self._fext(q)
        if fext is None:
            return pin.rnea(self.model, self.data, q, v, a)
        return pin.rnea(self.model, self.data, q, v, a, fext)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((q.shape[0], self.model.nv, self.model.nv))
        for k in range(q.shape[0]):
            upper = np.triu(pin.crba(self.model, self.data, q[k]))
            out[k] = upper + np.triu(upper, 1).T
        return self._check("mass matrix", out)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        zero = np.zeros(self.model.nv)
        out = np.array([pin.rnea(self.model, self.data, q[k], v[k], zero) for k in range(len(q))])
        return self._check("bias forces", out)

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.array([self._aba(q[k], v[k], tau[k]) for k in range(len(q))])
        return self._check("forward dynamics", out)

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        out = np.array([self._rnea(q[k], v[k], a[k]) for k in range(len(q))])
        return self._check("inverse dynamics", out)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = [pin.computeKineticEnergy(self.model, self.data, q[k], v[k]) for k in range(len(q))]
        return self._check("kinetic energy", np.array(out))

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        out = [pin.computePotentialEnergy(self.model, self.data, q[k]) for k in range(len(q))]
        return self._check("potential energy", np.array(out))

    def definition(self, integrator: str) -> str:
        """dyncheck's ``implicitfast`` has D = 0 here (no damping, no actuators): ``euler``."""
        return Integrator.EULER if integrator == Integrator.IMPLICITFAST else integrator

    def to_mujoco(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio's state → MuJoCo's layout: quaternions (x, y, z, w) → (w, x, y, z), a
        free joint's body-frame linear velocity v_b → v_w = R v_b."""
        q, v = np.asarray(q, float)[self._to_mj], np.array(v, float)
        for qa, va in self._free:
            v[va : va + 3] = quat_to_matrix(q[None, qa + 3 : qa + 7])[0] @ v[va : va + 3]
        return q, v

    def from_mujoco(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The inverse of :meth:`to_mujoco`."""
        if not self.layout.rotating:  # the same layout: each stage's state as it is
            return np.asarray(q, float), np.asarray(v, float)
        q = np.asarray(q, float)
        if self._free:
            v = np.array(v, float)
            for qa, va in self._free:
                v[va : va + 3] = quat_to_matrix(q[None, qa + 3 : qa + 7])[0].T @ v[va : va + 3]
        return q[self._to_pin], np.asarray(v, float)

    def mujoco_acceleration(self, q: np.ndarray, v: np.ndarray, held=None) -> np.ndarray:
        """v̇ in MuJoCo's layout: Pinocchio's ABA, a free joint's v̇_b turned into
        R (v̇_b + ω × v_b), the rate of v_w = R v_b."""
        qp, vp = self.from_mujoco(q, v)
        a = self._aba(qp, vp, self._zero_tau, held)
        if not self.layout.rotating:
            return a
        for qa, va in self._free:
            R = quat_to_matrix(q[None, qa + 3 : qa + 7])[0]
            lin, ang = slice(va, va + 3), slice(va + 3, va + 6)
            a[lin] = R @ (a[lin] + cross(vp[ang], vp[lin]))
        return a

    def _stage_acceleration(self) -> Callable[..., np.ndarray]:
        """:meth:`mujoco_acceleration`; where the layouts agree and there is neither a cord
        nor a field, the very call it comes down to (ABA at τ = 0), bound once: a stage's cost
        on a small model is Python's calls around the dynamics, not the dynamics."""
        if self.layout.rotating or self._C is not None or self.spec.central_mu:
            return self.mujoco_acceleration
        aba, m, d, zero = pin.aba, self.model, self.data, self._zero_tau

        def acc(q: np.ndarray, v: np.ndarray, held: object = None) -> np.ndarray:
            return aba(m, d, q, v, zero)  # no field: nothing held (``_fext`` is None)

        return acc

    def _states_from_mujoco(self, qs: np.ndarray, vs: np.ndarray) -> tuple:
        """:meth:`from_mujoco` of every state of a run: at once where no free joint turns a
        velocity (moving values only), state by state otherwise."""
        if not self._free:
            return qs[:, self._to_pin], vs
        pairs = [self.from_mujoco(q, v) for q, v in zip(qs, vs, strict=True)]
        return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])

    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        """MuJoCo's definition of ``integrator`` (:mod:`.integrators`), in MuJoCo's layout."""
        steps = round(duration / dt)
        qs, vs = integrate(
            self._stage_acceleration(),
            *self.to_mujoco(q0, v0),
            dt,
            steps,
            integrator,
            freeze=lambda q, v: self._fext(self.from_mujoco(q, v)[0]),
            layout=self.layout,
        )
        qs, vs = self._states_from_mujoco(qs, vs)
        return Trajectory(np.arange(steps + 1) * dt, self._check("simulate", qs), vs)

    def evaluate_all(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """One pass over the states with preallocated outputs: ``crba``, ``rnea`` (h),
        ``aba``, ``rnea`` (τ) and the two energies — the same calls as the one-quantity
        methods, without their per-call allocation."""
        m, d = self.model, self.data
        n, nv = v.shape
        zero = np.zeros(nv)
        M, bias, fwd, inv = (
            np.empty((n, nv, nv)),
            np.empty((n, nv)),
            np.empty((n, nv)),
            np.empty((n, nv)),
        )
        kin, pot = np.empty(n), np.empty(n)
        crba, rnea, aba = pin.crba, pin.rnea, pin.aba
        kinetic, potential = pin.computeKineticEnergy, pin.computePotentialEnergy
        field = bool(self.spec.central_mu)
        coupled = self._C is not None
        force = np.empty((n, self._C.shape[0])) if coupled else None
        for k in range(n):
            qk, vk = q[k], v[k]
            M[k] = crba(m, d, qk)
            bias[k] = rnea(m, d, qk, vk, zero)
            if coupled:
                fwd[k] = self._constrained(qk, vk, tau[k])
                force[k] = d.lambda_c
                inv[k] = rnea(m, d, qk, vk, a[k])
            elif field:
                fwd[k] = self._aba(qk, vk, tau[k])
                inv[k] = self._rnea(qk, vk, a[k])
            else:
                fwd[k] = aba(m, d, qk, vk, tau[k])
                inv[k] = rnea(m, d, qk, vk, a[k])
            kin[k] = kinetic(m, d, qk, vk)
            pot[k] = potential(m, d, qk)
        M = np.triu(M) + np.swapaxes(np.triu(M, 1), 1, 2)
        return self._outputs(M, bias, fwd, inv, kin, pot, force)

    @property
    def _pool(self) -> pin.ModelPool:
        if self.__pool is None:
            self.__pool = pin.ModelPool(self.model, THREADS)
        return self.__pool

    def solve(self, q0: np.ndarray, v0: np.ndarray, t_eval: np.ndarray, rtol: float) -> Trajectory:
        """scipy's DOP853 at rtol = atol = ``rtol`` (:func:`.integrators.solve_on_group`)."""
        qs, vs = solve_on_group(
            self.mujoco_acceleration,
            *self.to_mujoco(q0, v0),
            t_eval,
            rtol,
            layout=self.layout,
            label=self.name,
        )
        qs, vs = self._states_from_mujoco(qs, vs)
        return Trajectory(t_eval, self._check("solve", qs), vs)

    def raw_calls(self, qe: np.ndarray, ve: np.ndarray, te: np.ndarray,
                  ae: np.ndarray) -> Callable[[], None] | None:
        m, d = self.model, self.data
        zero = np.zeros(m.nv)

        def loop() -> None:
            for k in range(len(qe)):
                q, v = qe[k], ve[k]
                pin.crba(m, d, q)
                pin.rnea(m, d, q, v, zero)
                pin.aba(m, d, q, v, te[k])
                pin.rnea(m, d, q, v, ae[k])
                pin.computeKineticEnergy(m, d, q, v)
                pin.computePotentialEnergy(m, d, q)

        return loop



class PinocchioMJCFAdapter(PinocchioAdapter):
    """The very same MJCF file MuJoCo loads, read by Pinocchio's MJCF parser."""

    name: ClassVar[str] = "pinocchio-mjcf"

    def _build(self, model: Multibody) -> pin.Model:
        self.xml = to_mjcf(model)
        return load_mjcf(self.xml)
