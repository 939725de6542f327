"""MuJoCo's loader in a book case's run (:class:`MujocoRun`, a part of
:class:`~.model.MujocoModel`): the couplings, a field of forces on bodies, its own
forward dynamics at τ and its own stepping.

- Forward dynamics at τ: ``qacc`` after ``mj_forward`` with ``qfrc_applied`` = τ.
- Couplings are the file's tendon equalities, MuJoCo's *soft* constraints (the loader of a
  user's file disables every constraint; coupling enables its equalities alone — no contact,
  limit or friction loss): their force is ``efc_force`` of the equality rows
  (``qfrc_constraint = efc_Jᵀ efc_force``), their model the loaded ``eq_solref`` and
  ``eq_solimp`` (``solimp=`` of the loader overrides every equality's: ``mujoco-stiff``, the
  impedance at MuJoCo's ceiling).
- A field: its generalized force Σ Jᵀ F at the bodies' centres of mass (``mj_applyFT``). In a
  simulation it is added at every stage of every step through the passive-force callback
  ``mjcb_passive`` (which MuJoCo calls inside every stage's forward pass, where spring or
  damper forces are enabled: here the springs, of which the model must have none); with
  ``rk4-held-force`` it is written to ``xfrc_applied`` before ``mj_step`` and so held over
  all RK4 stages.
- Stepping: ``mj_step`` with each of MuJoCo's integrators (:data:`.api.INTEGRATORS`);
  its divergence warnings read once at the end — where one was raised, the run is made again
  watching each step, to name the step (MuJoCo resets a diverged state and goes on).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import mujoco
import numpy as np

from dyncheck.adapters.base import Field
from dyncheck.adapters.mujoco.api import INTEGRATORS, SPRINGS_APART, SPRINGS_OFF
from dyncheck.adapters.mujoco.rows import equality_rows
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import EngineError, Unsupported
from dyncheck.vocabulary import Integrator

_DIVERGED = (
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
    mujoco.mjtWarning.mjWARN_BADQACC,
)
_EQUALITIES_ONLY = (mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
                    | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
"""What stays disabled of MuJoCo's constraints once the couplings are on."""


def tendon_couplings(m: mujoco.MjModel) -> list[dict[str, float]]:
    """Each tendon equality as its joints' coefficients (a fixed tendon's ``wrap_prm``, by
    joint name); refused where an equality is not one on a fixed tendon alone."""
    out = []
    for i in range(m.neq):
        if m.eq_type[i] != mujoco.mjtEq.mjEQ_TENDON or m.eq_obj2id[i] >= 0:
            raise Unsupported(f"mujoco: equality {i} is not on one tendon")
        t = int(m.eq_obj1id[i])
        start, count = int(m.tendon_adr[t]), int(m.tendon_num[t])
        coefs: dict[str, float] = {}
        for w in range(start, start + count):
            if m.wrap_type[w] != mujoco.mjtWrap.mjWRAP_JOINT:
                raise Unsupported(f"mujoco: tendon {t} is not a fixed tendon")
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.wrap_objid[w]))
            coefs[name] = coefs.get(name, 0.0) + float(m.wrap_prm[w])
        out.append(coefs)
    return out


def soft_model(m: mujoco.MjModel, solref: np.ndarray, solimp: np.ndarray,
               engine: str) -> tuple[float, ...] | None:
    """(timeconst, dampratio, dmin, dmax, width, mid, power) shared by every equality of
    ``m`` as ``engine`` holds them (``solref``, ``solimp``: MuJoCo C's arrays or a port's
    copies); None where ``m`` has no equality or its constraints are off."""
    if not m.neq or m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONSTRAINT:
        return None
    params = {(*map(float, r), *map(float, i)) for r, i in zip(solref, solimp, strict=True)}
    if len(params) > 1:
        raise EngineError(f"{engine}: equalities with different solref/solimp")
    return params.pop()


class MujocoRun:
    """The run's offers of MuJoCo's loader (see the module); ``model`` and ``data`` are the
    loader's."""

    engine: str
    model: mujoco.MjModel
    data: mujoco.MjData

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """The file's tendon equalities, which must be ``couplings`` (the same joints and
        coefficients, in order), enabled as MuJoCo's soft constraints."""
        m = self.model
        held = tendon_couplings(m)
        wanted = [{name: float(c) for name, c in coupling.coefs} for coupling in couplings]
        if held != wanted:
            raise Unsupported(f"mujoco: the file's tendon equalities {held} are not the "
                              f"couplings {wanted}")
        m.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
        m.opt.disableflags |= int(_EQUALITIES_ONLY)

    def softness(self) -> tuple[float, ...] | None:
        """(timeconst, dampratio, dmin, dmax, width, mid, power) of its equalities (None
        without)."""
        return soft_model(self.model, self.model.eq_solref, self.model.eq_solimp, self.engine)

    def _forwards(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> Iterator[int]:
        """Each state's index, after ``mj_forward`` with ``qfrc_applied`` = τ."""
        m, d = self.model, self.data
        for k in range(len(q)):
            d.qpos[:], d.qvel[:], d.qfrc_applied[:] = q[k], v[k], tau[k]
            mujoco.mj_forward(m, d)
            yield k

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``qacc`` at τ (with the couplings where they are on)."""
        out = np.empty((len(q), self.model.nv))
        for k in self._forwards(q, v, tau):
            out[k] = self.data.qacc
        return out

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``efc_force`` of the equality rows at τ, in equality order."""
        return self.constrained(q, v, tau)[1]

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``qacc`` and the equality rows' ``efc_force`` of one ``mj_forward`` per state."""
        d = self.data
        vdot, forces = np.empty((len(q), self.model.nv)), np.empty((len(q), self.model.neq))
        for k in self._forwards(q, v, tau):
            vdot[k] = d.qacc
            forces[k] = d.efc_force[equality_rows(d.efc_type, d.efc_id, d.nefc)]
        return vdot, forces

    def _pushed(self, field: Field, out: np.ndarray) -> np.ndarray:
        """out += Σ Jᵀ F of ``field`` at the bodies' centres of mass (kinematics done)."""
        m, d = self.model, self.data
        where = {m.body(i).name: d.xipos[i].copy() for i in range(1, m.nbody)}
        zero = np.zeros(3)
        for name, force in field(where).items():
            i = m.body(name).id
            mujoco.mj_applyFT(m, d, np.asarray(force, float), zero, where[name], i, out)
        return out

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """Σ Jᵀ F of ``field`` at each state (``mj_applyFT``)."""
        m, d = self.model, self.data
        out = np.zeros((len(q), m.nv))
        for k in range(len(q)):
            d.qpos[:], d.qvel[:] = q[k], v[k]
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            self._pushed(field, out[k])
        return out

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``mj_step`` with ``integrator`` (see the module)."""
        return self._stepped(q0, v0, dt, steps, integrator, field, watch=False)

    def _stepped(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, integrator: str,
                 field: Field | None, *, watch: bool) -> tuple[np.ndarray, np.ndarray]:
        m, d = self.model, self.data
        m.opt.timestep = dt
        m.opt.integrator = INTEGRATORS[integrator]
        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:] = q0, v0
        qs, vs = np.empty((steps + 1, m.nq)), np.empty((steps + 1, m.nv))
        qs[0], vs[0] = d.qpos, d.qvel
        held = field if integrator == Integrator.RK4_HELD_FORCE else None
        flags = m.opt.disableflags
        if field is not None and held is None:
            self._staged(field)

        def diverged() -> bool:
            return any(d.warning[w].number for w in _DIVERGED)

        try:
            for k in range(1, steps + 1):
                if held is not None:
                    mujoco.mj_kinematics(m, d)
                    d.xfrc_applied[:] = 0.0
                    where = {m.body(i).name: d.xipos[i] for i in range(1, m.nbody)}
                    for name, force in held(where).items():
                        d.xfrc_applied[m.body(name).id, :3] = force
                mujoco.mj_step(m, d)
                qs[k], vs[k] = d.qpos, d.qvel
                if watch and diverged():
                    raise EngineError(
                        f"mujoco {integrator} diverged at step {k} (t = {k * dt:g}): NaN or "
                        "huge qpos/qvel/qacc, state reset by MuJoCo")
        finally:
            m.opt.disableflags = flags
            mujoco.set_mjcb_passive(None)
            d.xfrc_applied[:] = 0.0
        if diverged() and not watch:  # warnings count: run again, watching each step
            return self._stepped(q0, v0, dt, steps, integrator, field, watch=True)
        return qs, vs

    def _staged(self, field: Field) -> None:
        """The field added at every stage: ``mjcb_passive``, called where spring forces are
        enabled (refused where the model has springs or other passive forces)."""
        m = self.model
        dampers = not SPRINGS_APART and (np.any(m.dof_damping)
                                                    or np.any(m.tendon_damping))
        if np.any(m.jnt_stiffness) or np.any(m.tendon_stiffness) or dampers or \
                np.any(m.body_gravcomp) or m.opt.density or m.opt.viscosity:
            raise Unsupported("mujoco: a field at every stage rides on the passive-force "
                              "callback; the model has passive forces of its own")
        m.opt.disableflags &= ~SPRINGS_OFF
        model = m

        def passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
            if m is model:
                self._pushed(field, d.qfrc_passive)

        mujoco.set_mjcb_passive(passive)

