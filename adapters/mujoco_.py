"""MuJoCo C from the MJCF that :mod:`.mjcf` writes, as MuJoCo's ports (:mod:`.mujoco_port`:
MJX, MuJoCo Warp) compile it and compare with it. ``dyncheck run`` reaches MuJoCo C itself
through its file loader (:mod:`.mujoco_model`, :mod:`.mujoco_simulation`).

MuJoCo's names: M from ``mj_fullM``; h = ``qfrc_bias`` (Coriolis, centrifugal and gravity);
forward dynamics ``qacc`` after ``mj_forward`` with ``qfrc_applied`` = τ; inverse dynamics
``qfrc_inverse`` after ``mj_inverse``; energies ``data.energy`` = (V, T), computed inside
``mj_forward`` when the ``energy`` flag is enabled. Integrators are MuJoCo's own.

An external field (``Multibody.central_mu``) enters through MuJoCo's external-force input
``xfrc_applied`` (force at the body's centre of mass). ``qfrc_inverse`` is the *total*
generalized force, so the field's Jᵀ F (``mj_applyFT``) is subtracted to give τ. In a
simulation, a force written to ``xfrc_applied`` before ``mj_step`` is held over all RK4 stages
(``rk4-held-force``); evaluating it at every stage needs the passive-force callback
``mjcb_passive``, which MuJoCo calls inside every stage's forward pass.

Couplings are tendon equalities, MuJoCo's *soft* constraints: their force is ``efc_force`` of
the equality rows (``qfrc_constraint = efc_Jᵀ efc_force``), their model the loaded
``eq_solref`` and ``eq_solimp``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import ClassVar

import mujoco
import numpy as np

from dyncheck.adapters import mujoco_api
from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.adapters.mjcf import to_mjcf
from dyncheck.adapters.mujoco_api import INTEGRATORS, full_inertia
from dyncheck.adapters.mujoco_dynamics import Around, evaluate
from dyncheck.adapters.mujoco_registration import MUJOCO, REGISTRATIONS
from dyncheck.cases.multibody import Multibody
from dyncheck.errors import EngineError
from dyncheck.vocabulary import Integrator

_DIVERGED = (
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
    mujoco.mjtWarning.mjWARN_BADQACC,
)



class MuJoCoAdapter(Adapter):
    name: ClassVar[str] = MUJOCO
    package: ClassVar[str] = REGISTRATIONS[MUJOCO].package
    integrators: ClassVar[tuple[str, ...]] = REGISTRATIONS[MUJOCO].integrators
    couplings_with_field: ClassVar[bool] = True
    """Tendon equalities and xfrc_applied coexist in one MuJoCo model."""
    gyroscopic_implicit: ClassVar[bool] = mujoco_api.GYROSCOPIC_IMPLICIT
    """``implicitfast`` applies a free body's gyroscopic bias-force derivative (MuJoCo ≥ 3.11):
    on a free joint it is no longer semi-implicit Euler (measured: the two differ by O(h) on
    ``rigid_body_free``)."""
    rk4_group_order: ClassVar[int] = 4 if mujoco_api.RK4_ON_GROUP else 2
    """RK4's order on ball and free joints (2 before MuJoCo 4.0: stages summed naively)."""

    def __init__(self, model: Multibody) -> None:
        super().__init__(model)
        self.xml = to_mjcf(model)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self._body_ids = [self.model.body(b.name).id for b in model.bodies]
        self._zero3 = np.zeros(3)

    @staticmethod
    def version() -> str:
        return mujoco.__version__

    def loaded_bodies(self) -> list[LoadedBody]:
        out = []
        for body, i in zip(self.spec.bodies, self._body_ids, strict=True):
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, self.model.body_iquat[i])
            rot = rot.reshape(3, 3)
            inertia = rot @ np.diag(self.model.body_inertia[i]) @ rot.T
            out.append(LoadedBody(body.name, float(self.model.body_mass[i]), inertia))
        return out

    def loaded_gravity(self) -> np.ndarray:
        return np.array(self.model.opt.gravity)

    def softness(self) -> tuple[float, ...] | None:
        """(timeconst, dampratio, dmin, dmax, width, mid, power) of the equalities."""
        if not self.model.neq:
            return None
        params = {
            (*map(float, self.model.eq_solref[i]), *map(float, self.model.eq_solimp[i]))
            for i in range(self.model.neq)
        }
        if len(params) > 1:
            raise EngineError(f"{self.name}: equalities with different solref/solimp")
        return params.pop()

    def _equality_force(self, d: mujoco.MjData) -> np.ndarray:
        """efc_force of the equality rows, in equality order (after ``mj_forward``)."""
        rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        order = np.argsort(d.efc_id[rows], kind="stable")
        return np.array(d.efc_force[rows[order]])

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty((q.shape[0], self.model.neq))
        for k, d in self._eval(q, v, tau):
            out[k] = self._equality_force(d)
        return self._check("constraint force", out)

    # --- the external field ---------------------------------------------------------------

    def _field_xfrc(self, d: mujoco.MjData) -> None:
        """xfrc_applied from the field at the current body positions (kinematics done)."""
        for body, i in zip(self.spec.bodies, self._body_ids, strict=True):
            d.xfrc_applied[i, :3] = self.spec.central_force(body.mass, d.xipos[i])

    def _field_generalized(self, d: mujoco.MjData, out: np.ndarray) -> np.ndarray:
        """out += Jᵀ F of the field (positions from the last forward pass)."""
        for body, i in zip(self.spec.bodies, self._body_ids, strict=True):
            F = self.spec.central_force(body.mass, d.xipos[i])
            mujoco.mj_applyFT(self.model, d, F, self._zero3, d.xipos[i].copy(), i, out)
        return out

    def _set(self, q: np.ndarray, v: np.ndarray | None, tau: np.ndarray | None) -> None:
        d = self.data
        d.qpos[:] = q
        d.qvel[:] = 0.0 if v is None else v
        d.qfrc_applied[:] = 0.0 if tau is None else tau
        if self.spec.central_mu:
            mujoco.mj_kinematics(self.model, d)
            self._field_xfrc(d)

    def _eval(
        self, q: np.ndarray, v: np.ndarray | None = None, tau: np.ndarray | None = None
    ) -> Iterator[tuple[int, mujoco.MjData]]:
        """Yield after ``mj_forward`` at each state of the batch."""
        for k in range(q.shape[0]):
            self._set(q[k], None if v is None else v[k], None if tau is None else tau[k])
            mujoco.mj_forward(self.model, self.data)
            yield k, self.data

    # --- the canonical form ----------------------------------------------------------------

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((q.shape[0], self.model.nv, self.model.nv))
        for k, d in self._eval(q):
            full_inertia(self.model, d, out[k])
        return self._check("mass matrix", out)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.empty_like(v, dtype=float)
        for k, d in self._eval(q, v):
            out[k] = d.qfrc_bias
        return self._check("bias forces", out)

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty_like(v, dtype=float)
        for k, d in self._eval(q, v, tau):
            out[k] = d.qacc
        return self._check("forward dynamics", out)

    def _inverse_one(self, a: np.ndarray) -> np.ndarray:
        d = self.data
        d.qacc[:] = a
        mujoco.mj_inverse(self.model, d)
        tau = d.qfrc_inverse.copy()
        if self.spec.central_mu:
            tau -= self._field_generalized(d, np.zeros(self.model.nv))
        return tau

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        out = np.empty_like(v, dtype=float)
        for k in range(q.shape[0]):
            self._set(q[k], v[k], None)
            out[k] = self._inverse_one(a[k])
        return self._check("inverse dynamics", out)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.empty(q.shape[0])
        for k, d in self._eval(q, v):
            out[k] = d.energy[1]
        return self._check("kinetic energy", out)

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        out = np.empty(q.shape[0])
        for k, d in self._eval(q):
            out[k] = d.energy[0]
        return self._check("potential energy", out)

    def evaluate_all(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """One ``mj_forward`` (M, h, v̇, energies) and one ``mj_inverse`` per state
        (:func:`~.mujoco_dynamics.evaluate`), the field's force held in ``xfrc_applied`` and
        taken from the inverse dynamics, the couplings' forces read after each forward."""
        m, d = self.model, self.data
        force = np.empty((len(q), m.neq)) if self.spec.couplings else None
        around = Around()
        if self.spec.central_mu:
            def held(d: mujoco.MjData) -> None:
                mujoco.mj_kinematics(m, d)
                self._field_xfrc(d)

            around = replace(around, before=held, taken_from_inverse=lambda d: (
                self._field_generalized(d, np.zeros(m.nv))))
        if force is not None:
            def tensions(k: int, d: mujoco.MjData) -> None:
                force[k] = self._equality_force(d)

            around = replace(around, after_forward=tensions)
        e = evaluate(m, d, q=q, v=v, tau=tau, a=a, around=around)
        return self._outputs(e.mass, e.bias, e.forward, e.inverse, e.kinetic, e.potential,
                             force)

    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        """MuJoCo's own ``mj_step``; its divergence warnings read once at the end — where
        one was raised, the run is made again watching each step, to name the step."""
        return self._stepped(q0, v0, duration, dt, integrator, watch=False)

    def _stepped(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str,
        *, watch: bool,
    ) -> Trajectory:
        m, d = self.model, self.data
        steps = round(duration / dt)
        m.opt.timestep = dt
        m.opt.integrator = INTEGRATORS[integrator]
        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:] = q0, v0
        qs = np.empty((steps + 1, m.nq))
        vs = np.empty((steps + 1, m.nv))
        qs[0], vs[0] = d.qpos, d.qvel
        held = integrator == Integrator.RK4_HELD_FORCE
        field = bool(self.spec.central_mu)
        if field and not held:
            mujoco.set_mjcb_passive(self._passive)
        def diverged() -> bool:
            return any(d.warning[w].number for w in _DIVERGED)

        try:
            for k in range(1, steps + 1):
                if field and held:
                    mujoco.mj_kinematics(m, d)
                    self._field_xfrc(d)
                mujoco.mj_step(m, d)
                qs[k], vs[k] = d.qpos, d.qvel
                if watch and diverged():
                    # MuJoCo resets a diverged state and goes on; dyncheck reports it
                    raise EngineError(
                        f"mujoco {integrator} diverged at step {k} (t = {k * dt:g}): NaN or "
                        "huge qpos/qvel/qacc, state reset by MuJoCo"
                    )
        finally:
            if field and not held:
                mujoco.set_mjcb_passive(None)
        if diverged() and not watch:  # warnings count: run again, watching each step, to name it
            return self._stepped(q0, v0, duration, dt, integrator, watch=True)
        return Trajectory(np.arange(steps + 1) * dt, self._check("simulate", qs), vs)

    def _passive(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """mjcb_passive: the field's Jᵀ F added at every stage of every step."""
        if m is self.model:
            self._field_generalized(d, d.qfrc_passive)

    def raw_calls(self, qe: np.ndarray, ve: np.ndarray, te: np.ndarray,
                  ae: np.ndarray) -> Callable[[], None] | None:
        m, d = self.model, self.data
        mass = np.empty((m.nv, m.nv))

        def loop() -> None:
            for k in range(len(qe)):
                d.qpos[:], d.qvel[:], d.qfrc_applied[:] = qe[k], ve[k], te[k]
                mujoco.mj_forward(m, d)
                full_inertia(m, d, mass)
                d.qacc[:] = ae[k]
                mujoco.mj_inverse(m, d)

        return loop
