"""MuJoCo's smooth dynamics at a batch of states, for its loader (:mod:`.model`, which
serves the run and the check): per state one ``mj_forward`` with ``qfrc_applied`` = τ — M from
``mj_fullM`` (armature included), h = ``qfrc_bias``, v̇ = ``qacc``, the energies (V, T) =
``data.energy`` — and one ``mj_inverse`` at v̇ = a, ``qfrc_inverse``. ``mjData``'s arrays are
bound once (a small model's state costs ~6 µs: the attribute reads around the two engine calls
were a fifth of it)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import mujoco
import numpy as np

from dyncheck.adapters.mujoco.api import PASSIVE_OFF, full_inertia

SMOOTH_ONLY = (
    mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    | mujoco.mjtDisableBit.mjDSBL_ACTUATION
    | PASSIVE_OFF
    | mujoco.mjtDisableBit.mjDSBL_SENSOR
)
"""What MuJoCo's smooth dynamics leave off: constraints, actuation, passive forces, sensors."""


@contextmanager
def smooth(m: mujoco.MjModel, timestep: float) -> Iterator[mujoco.MjModel]:
    """``m`` computing its smooth dynamics at the file's ``timestep`` while the block runs
    (:data:`SMOOTH_ONLY` off, the integrator as it was), its options restored after: a
    derivative or a step Jacobian is of the smooth tree whatever a run did to the model
    before (its couplings enabled, a study's step size and integrator set)."""
    flags, step, integrator = m.opt.disableflags, m.opt.timestep, m.opt.integrator
    m.opt.disableflags |= int(SMOOTH_ONLY)
    m.opt.timestep = timestep
    try:
        yield m
    finally:
        m.opt.disableflags, m.opt.timestep, m.opt.integrator = flags, step, integrator


@dataclass(frozen=True, kw_only=True)
class Evaluated:
    """The batch's values, one row (or matrix) per state."""

    mass: np.ndarray
    bias: np.ndarray
    forward: np.ndarray
    inverse: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray


def evaluate(m: mujoco.MjModel, d: mujoco.MjData, *, q: np.ndarray, v: np.ndarray,
             tau: np.ndarray, a: np.ndarray) -> Evaluated:
    """M, h, v̇ at τ, the energies and τ at v̇ = a at every state of the batch (rows)."""
    n, nv = v.shape
    mass = np.empty((n, nv, nv))
    bias, fwd, inv = np.empty((n, nv)), np.empty((n, nv)), np.empty((n, nv))
    energy = np.empty((n, 2))
    qpos, qvel, qfrc, qacc = d.qpos, d.qvel, d.qfrc_applied, d.qacc
    qbias, qinv, en = d.qfrc_bias, d.qfrc_inverse, d.energy
    forward, inverse = mujoco.mj_forward, mujoco.mj_inverse
    for k in range(n):
        qpos[:], qvel[:], qfrc[:] = q[k], v[k], tau[k]
        forward(m, d)
        full_inertia(m, d, mass[k])
        bias[k], fwd[k], energy[k] = qbias, qacc, en
        qacc[:] = a[k]
        inverse(m, d)
        inv[k] = qinv
    return Evaluated(mass=mass, bias=bias, forward=fwd, inverse=inv, kinetic=energy[:, 1],
                     potential=energy[:, 0])


def step_differences(m: mujoco.MjModel, d: mujoco.MjData, q: np.ndarray, v: np.ndarray,
                      step: float) -> np.ndarray:
    """∂x₊/∂x of one ``mj_step`` from (q, v) by centered differences of ``step`` in MuJoCo's
    chart — q nudged by ``mj_integratePos``, q₊ compared by ``mj_differentiatePos`` —, the
    scheme of ``mjd_transitionFD`` (``engine_derivative_fd.c``), for a step it refuses."""
    nv = m.nv

    def stepped(nudge: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d.qpos[:] = q
        mujoco.mj_integratePos(m, d.qpos, nudge[:nv], 1.0)
        d.qvel[:] = v + nudge[nv:]
        d.qfrc_applied[:] = 0.0
        d.ctrl[:] = 0.0
        d.time = 0.0
        mujoco.mj_step(m, d)
        return d.qpos.copy(), d.qvel.copy()

    centre, _ = stepped(np.zeros(2 * nv))
    out = np.zeros((2 * nv, 2 * nv))
    tangent = np.zeros(nv)
    for k in range(2 * nv):
        nudge = np.zeros(2 * nv)
        nudge[k] = step
        ends = []
        for sign in (1.0, -1.0):
            q_next, v_next = stepped(sign * nudge)
            mujoco.mj_differentiatePos(m, tangent, 1.0, centre, q_next)
            ends.append(np.concatenate([tangent, v_next]))
        out[:, k] = (ends[0] - ends[1]) / (2 * step)
    return out
