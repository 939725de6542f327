"""MuJoCo Warp (NVIDIA Warp) as a port of MuJoCo's compiled model
(:class:`~dyncheck.adapters.mujoco.port.Port`, used by :class:`~.model.MujocoWarpModel`),
float32; a chunk of states is a batch of Warp
"worlds" (``nworld``).

MuJoCo Warp's names: ``mujoco_warp.forward`` (``qfrc_bias``, ``qacc`` with ``qfrc_applied`` =
τ), ``mujoco_warp.inverse`` (``qfrc_inverse``), M column by column from ``mul_m`` (M eⱼ; the
port offers no dense M), the equality rows of ``efc.force``. Its integrators, read from its
source (``mujoco_warp/_src/forward.py``, 4.0.0), share MuJoCo C 4.0's definitions: RK4
combines its stages on the rotation group (``_rk_correct_velocity``, Runge–Kutta–Munthe-Kaas)
and ``implicitfast`` applies a free body's gyroscopic derivative (``implicit_free_body``).

The device is Warp's: ``cpu`` unless ``--device`` (or ``DYNCHECK_DEVICE``) names a CUDA device.
On the CPU every kernel launch costs ~0.1 ms, so a step costs ~10 ms (Euler) to ~40 ms (RK4)
even on a pendulum (measured); runs longer than ``CPU_STEPS`` are left to a GPU, where one
step is a captured CUDA graph. Warp's kernel cache keeps compiled kernels across runs in the
folder the command line checked (:mod:`dyncheck.cache.compiled`), never in Warp's own
default under the home folder; without one (``--no-cache``), in a temporary folder.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Sequence
from importlib.metadata import version as _version
from operator import attrgetter
from typing import ClassVar

import mujoco
import mujoco_warp as mjw
import numpy as np
import warp as wp

from dyncheck.adapters.mujoco.api import INTEGRATORS
from dyncheck.adapters.mujoco.port import CHUNK, Port
from dyncheck.adapters.mujoco.rows import equality_rows
from dyncheck.errors import Unsupported
from dyncheck.settings import current

CPU_STEPS = 400
"""The longest run the port makes on Warp's CPU device (~16 s of RK4 steps)."""


def _init_quietly() -> None:
    """Warp started when the port first uses it (never by importing this module): its log
    at errors only (no banner, no line per kernel module loaded — Warp's setting, for the
    process), and ``wp.init()`` with its native library's stderr held back: on a machine
    without a CUDA driver it prints a warning line on every start, which says nothing here
    (the CPU is Warp's device unless ``--device cuda``); shown if initialisation fails."""
    from dyncheck.adapters.compiled import start_warp

    start_warp(wp)  # its log at errors only, its kernel cache checked (or temporary)
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as held:
        os.dup2(held.fileno(), 2)
        try:
            wp.init()
        except Exception:
            os.dup2(saved, 2)
            held.seek(0)
            sys.stderr.write(held.read().decode(errors="replace"))
            raise
        finally:
            os.dup2(saved, 2)
            os.close(saved)



def too_long(steps: int) -> str:
    return (
        f"mujoco-warp on the CPU: {steps} steps at ~10-40 ms each (Warp's kernel launches) "
        f"exceed the CPU budget of {CPU_STEPS} steps a run; run with --device cuda"
    )


def device() -> str:
    """Warp's device for this work: the command's ``--device`` (``cpu``, ``cuda``,
    ``cuda:0``, …; :func:`dyncheck.settings.current`), else ``cpu``."""
    return current().device or "cpu"


class MujocoWarpPort(Port):
    """MuJoCo Warp in float32 (Warp's ``float``)."""

    dtype: ClassVar[type[np.floating]] = np.float32

    def _put(self) -> None:
        _init_quietly()  # wp.init() returns at once when Warp has started
        self.model.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        self.device = device()
        self.max_steps = CPU_STEPS if self.device == "cpu" else None
        with wp.ScopedDevice(self.device):
            self.mw = mjw.put_model(self.model)
            self.dw = mjw.make_data(self.model, nworld=CHUNK)

    @staticmethod
    def version(package: str) -> str:
        _init_quietly()
        where = wp.get_device(device())
        warp = f"warp-lang {wp.__version__}"
        return f"{_version(package)} ({warp}, device {where.alias}: {where.name})"

    def _loaded(self, field: str) -> np.ndarray:
        obj = attrgetter(field)(self.mw)
        values = obj.numpy() if hasattr(obj, "numpy") else np.asarray(obj)
        values = np.asarray(values, dtype=float)
        # batched model fields carry a leading world axis of length one
        per_model = {"body_mass": 1, "opt.gravity": 1, "body_inertia": 2, "body_iquat": 2}
        per_model |= {"eq_solref": 2, "eq_solimp": 2}
        while values.ndim > per_model.get(field, values.ndim):
            values = values[0]
        return values

    def _assign(self, name: str, values: np.ndarray) -> None:
        getattr(self.dw, name).assign(wp.array(values.astype(np.float32), device=self.device))

    def _batch(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        m, d, nv = self.mw, self.dw, self.model.nv
        with wp.ScopedDevice(self.device):
            self._assign("qpos", q)
            self._assign("qvel", v)
            self._assign("qfrc_applied", tau)
            mjw.forward(m, d)
            out = {
                "bias": d.qfrc_bias.numpy().copy(),
                "qacc": d.qacc.numpy().copy(),
                "xipos": d.xipos.numpy().copy(),
            }
            M = np.empty((CHUNK, nv, nv))
            res = wp.zeros((CHUNK, nv), dtype=float)
            for j in range(nv):
                e = np.zeros((CHUNK, nv), np.float32)
                e[:, j] = 1.0
                mjw.mul_m(m, d, res, wp.array(e))
                M[:, :, j] = res.numpy()
            out["M"] = M
            out["efc_force"] = self._efc_equality()
            self._assign("qacc", a)
            mjw.inverse(m, d)
            out["qfrc_inverse"] = d.qfrc_inverse.numpy().copy()
        return out

    def _actuated(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                  act: np.ndarray) -> dict[str, np.ndarray]:
        with wp.ScopedDevice(self.device):
            for name, values in (("qpos", q), ("qvel", v), ("ctrl", u), ("act", act)):
                if values.shape[1]:
                    self._assign(name, values)
            self._assign("qfrc_applied", np.zeros_like(v))
            mjw.forward(self.mw, self.dw)
            return {"qfrc_actuator": self.dw.qfrc_actuator.numpy().copy(),
                    "qacc": self.dw.qacc.numpy().copy()}

    def _equality_batch(self, q: np.ndarray, v: np.ndarray,
                        tau: np.ndarray) -> dict[str, np.ndarray]:
        """Its ``efc`` rows of type equality ordered by their equality (``efc.id``), its
        dense ``efc.J`` (a sparse one is refused)."""
        if getattr(self.mw, "is_sparse", False):
            raise Unsupported("mujoco-warp holds this model's constraint Jacobian sparse: "
                              "its rows are not read here")
        with wp.ScopedDevice(self.device):
            self._assign("qpos", q)
            self._assign("qvel", v)
            self._assign("qfrc_applied", tau)
            mjw.forward(self.mw, self.dw)
            kind, ident, pos, jac, force, aref, weight = (x.numpy() for x in (
                self.dw.efc.type, self.dw.efc.id, self.dw.efc.pos, self.dw.efc.J,
                self.dw.efc.force, self.dw.efc.aref, self.dw.efc.D))
            nefc, qacc = self.dw.nefc.numpy(), self.dw.qacc.numpy().copy()
        picked = [equality_rows(kind[w], ident[w], nefc[w]) for w in range(CHUNK)]
        if len({len(r) for r in picked}) != 1:
            raise Unsupported("mujoco-warp made another number of equality rows in one world")
        at = np.arange(CHUNK)[:, None]
        rows = np.array(picked)
        return {"qacc": qacc, "pos": pos[at, rows],  # (its J's columns padded past nv)
                "J": jac[at, rows][..., : self.model.nv], "force": force[at, rows],
                "aref": aref[at, rows], "D": weight[at, rows]}

    def _efc_equality(self) -> np.ndarray:
        """efc.force of the equality rows, in equality order, per world."""
        neq = self.model.neq
        out = np.zeros((CHUNK, neq))
        if not neq:
            return out
        kind, ident, force = (
            x.numpy() for x in (self.dw.efc.type, self.dw.efc.id, self.dw.efc.force)
        )
        nefc = self.dw.nefc.numpy()
        for w in range(CHUNK):
            rows = equality_rows(kind[w], ident[w], nefc[w])
            if len(rows):  # (none where the model computes with its equalities off: a check's
                # smooth dynamics; dm_control's quadruped failed here, "could not broadcast")
                out[w] = force[w, rows]
        return out

    batches_steps: ClassVar[bool] = True
    """A study's step sizes run as worlds of one batch, each with its own ``opt.timestep``
    (MuJoCo Warp reads the timestep per world): a step of every world costs one step's kernel
    launches, which dominate on a CPU."""

    def run(self, q0: np.ndarray, v0: np.ndarray, *, dt: float, steps: int,
            integrator: str) -> tuple[np.ndarray, np.ndarray]:
        return self.run_many(q0, v0, dts=[dt], steps=[steps], integrator=integrator)[0]

    def run_many(self, q0: np.ndarray, v0: np.ndarray, *, dts: Sequence[float],
                 steps: Sequence[int], integrator: str) -> list[tuple[np.ndarray, np.ndarray]]:
        """World i steps ``dts[i]`` and is read for its first ``steps[i]`` steps; the worlds
        do not interact (each world's arithmetic is that of a run of its own)."""
        longest, worlds = max(steps), len(dts)
        if self.max_steps is not None and longest > self.max_steps:
            raise Unsupported(too_long(longest))
        self.model.opt.timestep = dts[0]
        self.model.opt.integrator = INTEGRATORS[integrator]
        with wp.ScopedDevice(self.device):
            m = mjw.put_model(self.model)
            m.opt.timestep = wp.array(np.asarray(dts, np.float32), dtype=float)
            d = mjw.make_data(self.model, nworld=worlds)
            d.qpos.assign(wp.array(np.tile(np.asarray(q0, np.float32), (worlds, 1))))
            d.qvel.assign(wp.array(np.tile(np.asarray(v0, np.float32), (worlds, 1))))
            qs = np.empty((longest + 1, worlds, self.model.nq))
            vs = np.empty((longest + 1, worlds, self.model.nv))
            qs[0], vs[0] = d.qpos.numpy(), d.qvel.numpy()
            for k in range(1, longest + 1):
                mjw.step(m, d)
                qs[k], vs[k] = d.qpos.numpy(), d.qvel.numpy()
        return [(qs[: n + 1, i], vs[: n + 1, i]) for i, n in enumerate(steps)]
