"""What MuJoCo's ports (MJX, MuJoCo Warp) share: MuJoCo's compiled ``MjModel`` put on the
port, and every quantity then computed by the port, batched over states (:class:`Port`). The
engine interface is the loader's (:class:`~.port_model.PortModel`), in ``dyncheck run`` as
in ``dyncheck check``: the port reads no file.

Nothing below calls the C engine's dynamics: masses, inertias, gravity and constraint
parameters are read back from the port's own copy, and M, h, v̇, τ are the port's.

Precision: a port in float32 rounds the state itself (relative ε₃₂ = 1.2e-7); its numbers are
returned as float64 arrays, so that the comparison sees exactly what the port computed.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from operator import attrgetter
from typing import ClassVar

import mujoco
import numpy as np

from dyncheck.errors import Unsupported

CHUNK = 256
"""States per batched call: every call has this shape (the last chunk padded), so that a port
compiles its functions once per model."""

STEPS = 200
"""Steps per compiled stretch of a simulation (the last stretch run whole, its tail dropped)."""


class Port(ABC):
    """MuJoCo's compiled model on a port (:meth:`on_model`); subclasses put it there and
    compute a chunk of states (:meth:`_batch`) and a run (:meth:`run`)."""

    name: str
    """The engine's name, as its loader gives it (:meth:`on_model`)."""
    dtype: ClassVar[type[np.floating]] = np.float32
    chunk: int = CHUNK
    """States per batched call (a GPU wants more: ``benchmarks/ports.py`` sets it)."""
    batches_steps: ClassVar[bool] = False
    """Whether :meth:`run_many` runs several step sizes at once (MuJoCo Warp's worlds)."""
    max_steps: int | None = None
    """The longest run it makes here (None: no limit)."""
    device: str = "cpu"
    """Where it computes (from ``--device``)."""
    model: mujoco.MjModel

    @classmethod
    def on_model(cls, model: mujoco.MjModel, *, name: str) -> Port:
        """The port holding the compiled C model ``model``, for the engine ``name``."""
        port = cls()
        port.name, port.model = name, model
        port._put()
        return port

    @staticmethod
    @abstractmethod
    def version(package: str) -> str:
        """The port's version (its ``package``'s) and its device."""

    @classmethod
    def release_compiled(cls) -> None:
        """Free what the port compiled for the models built so far (nothing by default)."""
        return None

    def raw(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
            a: np.ndarray) -> dict[str, np.ndarray]:
        """Every state's ``M``, ``bias``, ``qacc`` (at τ), ``qfrc_inverse`` (at v̇ = a),
        ``xipos`` and ``efc_force`` of the equality rows as the port computes them (float64
        arrays of the port's numbers), :attr:`chunk` states a call (the last padded)."""
        return self._chunked(self._batch, q, v, tau, a)

    def actuate(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                act: np.ndarray) -> dict[str, np.ndarray]:
        """Every state's ``qfrc_actuator`` and ``qacc`` at controls ``u`` and activation
        states ``act`` as the port computes them (a port holding a model with actuation on)."""
        return self._chunked(self._actuated, q, v, u, act)

    def equality_rows(self, q: np.ndarray, v: np.ndarray,
                      tau: np.ndarray) -> dict[str, np.ndarray]:
        """Every state's ``qacc`` at τ and its active equality rows in MuJoCo's order (by
        equality, as ``mj_forward`` makes them): ``pos`` (n, m), ``J`` (n, m, nv),
        ``force``, the reference acceleration ``aref`` and ``D`` = 1/R (n, m), as the port
        computes them
        (a port holding a model with its equalities alone on,
        :func:`.closures.equalities_on`)."""
        return self._chunked(self._equality_batch, q, v, tau)

    def _equality_batch(self, q: np.ndarray, v: np.ndarray,
                        tau: np.ndarray) -> dict[str, np.ndarray]:
        """One chunk of :meth:`equality_rows` (a port that computes them overrides it)."""
        raise Unsupported(f"{self.name} computes no constraint rows here")

    def _chunked(self, batch: Callable[..., dict[str, np.ndarray]],
                 *arrays: np.ndarray) -> dict[str, np.ndarray]:
        """``batch`` over all states, :attr:`chunk` at a time (the last one padded by
        repeating its first state), concatenated and cut back to the n states."""
        n = arrays[0].shape[0]
        parts: list[dict[str, np.ndarray]] = []
        for start in range(0, n, self.chunk):
            idx = np.arange(start, start + self.chunk)
            idx[idx >= n] = start
            parts.append(batch(*(x[idx] for x in arrays)))
        return {k: np.concatenate([p[k] for p in parts])[:n].astype(float) for k in parts[0]}

    def _actuated(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                  act: np.ndarray) -> dict[str, np.ndarray]:
        """One chunk of :meth:`actuate` (a port that computes actuators overrides it)."""
        raise Unsupported(f"{self.name} computes no actuator force here")

    def held(self, field: str) -> np.ndarray:
        """A model array as the port holds it, where it differs from the C model's float64
        value by more than the port's rounding (|Δ| > ε|x|); within it, the C model's value:
        rounding the parameters to float32 is part of the float32 round-off the tolerances
        bound, not a different model (a mass changed by 1e-4 in the port is)."""
        port = self._loaded(field)
        c = np.asarray(attrgetter(field)(self.model), dtype=float).reshape(port.shape)
        eps = float(np.finfo(self.dtype).eps)
        return np.where(np.abs(port - c) <= eps * np.abs(c), c, port)

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> dict[str, np.ndarray]:
        """Its own derivatives of its dynamics (MJX's, by JAX), where it has them."""
        raise Unsupported(f"{self.name} offers no derivatives of its dynamics")

    def model_array(self, field: str) -> np.ndarray:
        """A model array as the port holds it, float64 (see :meth:`_loaded`)."""
        return self._loaded(field)

    def run_many(self, q0: np.ndarray, v0: np.ndarray, *, dts: Sequence[float],
                 steps: Sequence[int], integrator: str) -> list[tuple[np.ndarray, np.ndarray]]:
        """:meth:`run` at each step size, ``steps[i]`` steps of ``dts[i]`` (a port that
        batches them overrides it)."""
        return [self.run(q0, v0, dt=dt, steps=n, integrator=integrator)
                for dt, n in zip(dts, steps, strict=True)]

    # --- what each port provides ----------------------------------------------------------

    @abstractmethod
    def _put(self) -> None:
        """Hand ``self.model`` (the C model) to the port."""

    @abstractmethod
    def _loaded(self, field: str) -> np.ndarray:
        """A model array (``body_mass``, ``body_inertia``, ``body_iquat``, ``opt.gravity``,
        ``eq_solref``, ``eq_solimp``) read back from the port's copy, as float64."""

    @abstractmethod
    def _batch(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """One padded chunk (``chunk`` states): ``M`` (n, nv, nv), ``bias``, ``qacc``,
        ``qfrc_inverse`` (n, nv), ``xipos`` (n, nbody, 3), ``efc_force`` (n, neq)."""

    @abstractmethod
    def run(self, q0: np.ndarray, v0: np.ndarray, *, dt: float, steps: int,
            integrator: str) -> tuple[np.ndarray, np.ndarray]:
        """The port's own integrator: qpos (steps + 1, nq) and qvel (steps + 1, nv), in the
        port's numbers."""
