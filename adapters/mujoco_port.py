"""What MuJoCo's ports (MJX, MuJoCo Warp) share: the C engine's MJCF and ``MjModel``, put on
the port; every quantity then computed by the port, batched over states.

The C model is compiled by MuJoCo from the MJCF that :mod:`.mjcf` writes, the file MuJoCo's
own loader reads in the run (one MJCF for all three), then handed to the port (``mjx.put_model``,
``mujoco_warp.put_model``). Nothing below calls the C engine's dynamics: masses, inertias,
gravity and constraint parameters are read back from the port's own copy, and M, h, v̇, τ are
the port's. The ports compute no energies (MJX has no ``energy`` flag; MuJoCo Warp's
``energy_pos``/``energy_vel`` cover gravity alone), so T = ½ vᵀ M v from the port's M and
V = −Σ mᵢ g·xᵢ from the port's centres of mass ``xipos`` — MuJoCo's own definitions
(``mj_energyPos``, ``mj_energyVel``) evaluated on the port's numbers.

Precision: a port in float32 rounds the state itself (relative ε₃₂ = 1.2e-7); its numbers are
returned as float64 arrays, so that the comparison sees exactly what the port computed.
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable
from operator import attrgetter
from typing import ClassVar

import mujoco
import numpy as np

from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.adapters.mjcf import to_mjcf
from dyncheck.cases.multibody import Multibody
from dyncheck.errors import EngineError, Unsupported
from dyncheck.vocabulary import Quantity

CHUNK = 256
"""States per batched call: every call has this shape (the last chunk padded), so that a port
compiles its functions once per model."""

STEPS = 200
"""Steps per compiled stretch of a simulation (the last stretch run whole, its tail dropped)."""


class PortAdapter(Adapter):
    """A port of MuJoCo behind the canonical form; subclasses provide :meth:`_batch` and
    :meth:`_run`."""

    dtype: ClassVar[type[np.floating]] = np.float32
    chunk: int = CHUNK
    """States per batched call (a GPU wants more: ``benchmarks/ports.py`` sets it)."""

    def __init__(self, model: Multibody) -> None:
        if model.central_mu:
            # the field is a force at each body's centre of mass, evaluated at every RK4 stage
            # through MuJoCo C's mjcb_passive; neither port offers a passive-force callback
            raise Unsupported(
                f"{self.name}: an external field evaluated at every stage needs MuJoCo's "
                "mjcb_passive callback, which the port does not offer"
            )
        super().__init__(model)
        self.xml = to_mjcf(model)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self._body_ids = [self.model.body(b.name).id for b in model.bodies]

    @classmethod
    def on_model(cls, model: mujoco.MjModel) -> PortAdapter:
        """The port holding a compiled C model directly — a user's file, which no
        :class:`Multibody` describes (``dyncheck check``): only :meth:`raw` and
        :meth:`_loaded` are meaningful on it."""
        port = cls.__new__(cls)
        port.model = model
        port._put()
        return port

    def raw(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
            a: np.ndarray) -> dict[str, np.ndarray]:
        """Every state's ``M``, ``bias``, ``qacc``, ``qfrc_inverse`` and ``xipos`` as the port
        computes them (float64 arrays of the port's numbers)."""
        return self._chunks(q, v, tau, a)

    def actuate(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                act: np.ndarray) -> dict[str, np.ndarray]:
        """Every state's ``qfrc_actuator`` and ``qacc`` at controls ``u`` and activation
        states ``act`` as the port computes them (a port holding a model with actuation on:
        :meth:`on_model`), :attr:`chunk` states a call (the last padded)."""
        n = q.shape[0]
        parts = []
        for start in range(0, n, self.chunk):
            idx = np.arange(start, start + self.chunk)
            idx[idx >= n] = start
            parts.append(self._actuated(q[idx], v[idx], u[idx], act[idx]))
        return {k: np.concatenate([p[k] for p in parts])[:n].astype(float) for k in parts[0]}

    def _actuated(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                  act: np.ndarray) -> dict[str, np.ndarray]:
        """One chunk of :meth:`actuate` (a port that computes actuators overrides it)."""
        raise Unsupported(f"{self.name} computes no actuator force here")

    def model_array(self, field: str) -> np.ndarray:
        """A model array as the port holds it (:meth:`_loaded`)."""
        return self._loaded(field)

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
    def _run(
        self, q0: np.ndarray, v0: np.ndarray, steps: int, dt: float, integrator: str
    ) -> tuple[np.ndarray, np.ndarray]:
        """The port's own integrator: qpos (steps + 1, nq) and qvel (steps + 1, nv)."""

    # --- the model as the port holds it -----------------------------------------------------

    def _held(self, field: str) -> np.ndarray:
        """A model array as the port holds it, where it differs from the C model's float64
        value by more than the port's rounding (|Δ| > ε|x|); within it, the C model's value:
        rounding the parameters to float32 is part of the float32 round-off the tolerances
        bound, not a different model (a mass changed by 1e-4 in the port is)."""
        port = self._loaded(field)
        c = np.asarray(attrgetter(field)(self.model), dtype=float).reshape(port.shape)
        return np.where(np.abs(port - c) <= self.eps * np.abs(c), c, port)

    def loaded_bodies(self) -> list[LoadedBody]:
        mass, inertia, iquat = (self._held(f) for f in ("body_mass", "body_inertia", "body_iquat"))
        out = []
        for body, i in zip(self.spec.bodies, self._body_ids, strict=True):
            w, x, y, z = iquat[i] / np.linalg.norm(iquat[i])
            rot = np.array(
                [
                    [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
                ]
            )
            out.append(LoadedBody(body.name, float(mass[i]), rot @ np.diag(inertia[i]) @ rot.T))
        return out

    def loaded_gravity(self) -> np.ndarray:
        return self._held("opt.gravity")

    def softness(self) -> tuple[float, ...] | None:
        if not self.model.neq:
            return None
        solref, solimp = self._held("eq_solref"), self._held("eq_solimp")
        params = {(*map(float, r), *map(float, i)) for r, i in zip(solref, solimp, strict=True)}
        if len(params) > 1:
            raise EngineError(f"{self.name}: equalities with different solref/solimp")
        return params.pop()

    # --- the canonical form, batched -----------------------------------------------------------

    def _chunks(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """:meth:`_batch` over all states, CHUNK at a time (the last one padded by repeating
        its first state), concatenated and cut back to the n states."""
        n = q.shape[0]
        parts: list[dict[str, np.ndarray]] = []
        for start in range(0, n, self.chunk):
            idx = np.arange(start, start + self.chunk)
            idx[idx >= n] = start
            parts.append(self._batch(q[idx], v[idx], tau[idx], a[idx]))
        return {k: np.concatenate([p[k] for p in parts])[:n].astype(float) for k in parts[0]}

    def _energies(self, raw: dict[str, np.ndarray], v: np.ndarray) -> tuple[np.ndarray, ...]:
        """T = ½ vᵀ M v and V = −Σ m g·x_com (``mj_energyVel``, ``mj_energyPos``)."""
        kin = 0.5 * np.einsum("ni,nij,nj->n", v, raw["M"], v)
        mass = self._loaded("body_mass")[self._body_ids]
        g = self._loaded("opt.gravity")
        pot = -np.einsum("b,nb->n", mass, raw["xipos"][:, self._body_ids] @ g)
        return kin, pot

    def evaluate_all(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        raw = self._chunks(q, v, tau, a)
        kin, pot = self._energies(raw, v)
        force = raw["efc_force"] if self.spec.couplings else None
        return self._outputs(
            raw["M"], raw["bias"], raw["qacc"], raw["qfrc_inverse"], kin, pot, force
        )

    def _all(self, q: np.ndarray, v=None, tau=None, a=None) -> dict[str, np.ndarray]:
        zero = np.zeros((q.shape[0], self.model.nv))
        return self.evaluate_all(
            q, zero if v is None else v, zero if tau is None else tau, zero if a is None else a
        )

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        return self._all(q)[Quantity.MASS_MATRIX]

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self._all(q, v)[Quantity.BIAS_FORCES]

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self._all(q, v, tau)[Quantity.FORWARD_DYNAMICS]

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        return self._all(q, v, a=a)[Quantity.INVERSE_DYNAMICS]

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self._all(q, v)[Quantity.KINETIC_ENERGY]

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        return self._all(q)[Quantity.POTENTIAL_ENERGY]

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self._all(q, v, tau)[Quantity.CONSTRAINT_FORCE]

    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        self._require(integrator)
        steps = round(duration / dt)
        qs, vs = self._run(np.asarray(q0), np.asarray(v0), steps, dt, integrator)
        return self._trajectory(qs, vs, dt)

    def _require(self, integrator: str) -> None:
        if integrator not in self.integrators:
            raise Unsupported(f"{self.name} offers no integrator {integrator!r}")

    def _trajectory(self, qs: np.ndarray, vs: np.ndarray, dt: float) -> Trajectory:
        """A run as the comparison sees it: float64, times from 0 every ``dt``, checked."""
        qs, vs = qs.astype(float), vs.astype(float)
        return Trajectory(np.arange(len(qs)) * dt, self._check("simulate", qs), vs)

    def raw_calls(self, qe: np.ndarray, ve: np.ndarray, te: np.ndarray,
                  ae: np.ndarray) -> Callable[[], None] | None:
        return None  # timed by its compiled batch, first call apart

