"""MuJoCo behind the canonical form, from the MJCF that :mod:`.mjcf` writes.

MuJoCo's names: M from ``mj_fullM``; h = ``qfrc_bias`` (Coriolis, centrifugal and gravity);
forward dynamics ``qacc`` after ``mj_forward`` with ``qfrc_applied`` = τ; inverse dynamics
``qfrc_inverse`` after ``mj_inverse``; energies ``data.energy`` = (V, T), computed inside
``mj_forward`` when the ``energy`` flag is enabled. Integrators are MuJoCo's own.
"""

from __future__ import annotations

from typing import ClassVar

import mujoco
import numpy as np

from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.adapters.mjcf import to_mjcf
from dyncheck.cases.multibody import Multibody

_INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}


class MuJoCoAdapter(Adapter):
    name: ClassVar[str] = "mujoco"
    package: ClassVar[str] = "mujoco"
    integrators: ClassVar[tuple[str, ...]] = tuple(_INTEGRATORS)

    def __init__(self, model: Multibody) -> None:
        super().__init__(model)
        self.xml = to_mjcf(model)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)

    @staticmethod
    def version() -> str:
        return mujoco.__version__

    def loaded_bodies(self) -> list[LoadedBody]:
        out = []
        for body in self.spec.bodies:
            i = self.model.body(body.name).id
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, self.model.body_iquat[i])
            rot = rot.reshape(3, 3)
            inertia = rot @ np.diag(self.model.body_inertia[i]) @ rot.T
            out.append(LoadedBody(body.name, float(self.model.body_mass[i]), inertia))
        return out

    def _eval(self, q: np.ndarray, v: np.ndarray | None = None, tau: np.ndarray | None = None):
        """Yield after ``mj_forward`` at each state of the batch."""
        d = self.data
        for k in range(q.shape[0]):
            d.qpos[:] = q[k]
            d.qvel[:] = 0.0 if v is None else v[k]
            d.qfrc_applied[:] = 0.0 if tau is None else tau[k]
            mujoco.mj_forward(self.model, d)
            yield k, d

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((q.shape[0], self.model.nv, self.model.nv))
        for k, d in self._eval(q):
            mujoco.mj_fullM(self.model, d, out[k])
        return self._check("mass matrix", out)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.empty_like(q, dtype=float)
        for k, d in self._eval(q, v):
            out[k] = d.qfrc_bias
        return self._check("bias forces", out)

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        out = np.empty_like(q, dtype=float)
        for k, d in self._eval(q, v, tau):
            out[k] = d.qacc
        return self._check("forward dynamics", out)

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        out = np.empty_like(q, dtype=float)
        d = self.data
        for k in range(q.shape[0]):
            d.qpos[:], d.qvel[:], d.qacc[:] = q[k], v[k], a[k]
            mujoco.mj_inverse(self.model, d)
            out[k] = d.qfrc_inverse
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
        """One ``mj_forward`` (M, h, v̇, energies) and one ``mj_inverse`` per state."""
        m, d = self.model, self.data
        n, nv = q.shape
        M = np.empty((n, nv, nv))
        bias, fwd, inv, energy = (
            np.empty((n, nv)),
            np.empty((n, nv)),
            np.empty((n, nv)),
            np.empty((n, 2)),
        )
        for k in range(n):
            d.qpos[:], d.qvel[:], d.qfrc_applied[:] = q[k], v[k], tau[k]
            mujoco.mj_forward(m, d)
            mujoco.mj_fullM(m, d, M[k])
            bias[k], fwd[k], energy[k] = d.qfrc_bias, d.qacc, d.energy
            d.qacc[:] = a[k]
            mujoco.mj_inverse(m, d)
            inv[k] = d.qfrc_inverse
        out = {
            "mass_matrix": M,
            "bias_forces": bias,
            "forward_dynamics": fwd,
            "inverse_dynamics": inv,
            "kinetic_energy": energy[:, 1],
            "potential_energy": energy[:, 0],
        }
        return {key: self._check(key, val) for key, val in out.items()}

    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        m, d = self.model, self.data
        steps = round(duration / dt)
        m.opt.timestep = dt
        m.opt.integrator = _INTEGRATORS[integrator]
        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:] = q0, v0
        qs = np.empty((steps + 1, m.nq))
        vs = np.empty((steps + 1, m.nv))
        qs[0], vs[0] = d.qpos, d.qvel
        for k in range(1, steps + 1):
            mujoco.mj_step(m, d)
            qs[k], vs[k] = d.qpos, d.qvel
        return Trajectory(np.arange(steps + 1) * dt, self._check("simulate", qs), vs)
