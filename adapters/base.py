"""The interface every engine adapter implements.

Canonical form, in the engine's own joint coordinates q (positions) and v (velocities):

    M(q) v̇ + h(q, v) = τ

M is the joint-space mass matrix (symmetric positive definite), h the bias forces (Coriolis,
centrifugal *and gravity*, so that h(q, 0) = ∂V/∂q), τ the applied generalized forces; all
are covariant, in the engine's joint coordinates and sign conventions. Energies: T = ½ vᵀ M v;
V as the engine computes it (its datum is the engine's, not the book's). All methods take
batches: q, v, τ, v̇ of shape (n, nv); they return (n, nv, nv), (n, nv) or (n,).
Adapters never see the book's coordinates: the comparison layer maps them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

import numpy as np

from dyncheck.adapters.model_tree import StateLayout
from dyncheck.cases.multibody import Multibody
from dyncheck.errors import EngineError, Unsupported
from dyncheck.vocabulary import Quantity

_T = TypeVar("_T")

DIVERGED = 1e12
"""A coordinate beyond this (rad or m) means a run has blown up: no case here comes near it."""


@dataclass(frozen=True)
class Trajectory:
    """Sampled states: ``t`` (k,), ``q`` and ``v`` (k, nv), engine coordinates."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray


@dataclass(frozen=True)
class LoadedBody:
    """A body's mass (kg) and inertia about its centre of mass (kg·m², body axes) as the engine
    holds it after loading the model — read back, not assumed."""

    name: str
    mass: float
    inertia: np.ndarray


def _computed(kind: str, inputs: object, compute: Callable[[], _T]) -> _T:
    return compute()


def _lambdified(args: Sequence[Any], exprs: Any, modules: str) -> Callable[..., Any]:
    import sympy as sp

    return sp.lambdify(args, exprs, modules=modules, cse=True)


@dataclass(frozen=True, kw_only=True)
class Symbolic:
    """How an adapter that derives its equations symbolically keeps them — ``derive(kind,
    inputs, compute)``: ``compute()``'s result, keyed by ``kind`` and ``inputs`` — and makes
    numeric functions of them — ``lambdify(args, exprs, modules)``, as ``sympy.lambdify``
    with ``cse=True``. The default computes both afresh; the comparison layer, which may see
    the reference, hands in the reference's disk caches (``dyncheck.implementations.CACHED``):
    adapters never import the reference, and nothing is patched in at import."""

    derive: Callable[[str, object, Callable[[], Any]], Any] = _computed
    lambdify: Callable[[Sequence[Any], Any, str], Callable[..., Any]] = _lambdified


AFRESH = Symbolic()
"""Equations derived and compiled afresh (no cache)."""


class Adapter(ABC):
    """One engine behind the canonical form ``M(q) v̇ + h(q, v) = τ``."""

    state_layout: ClassVar[StateLayout] = StateLayout()
    """How the engine stores rotations and their velocities (the canonical layout unless the
    adapter declares otherwise)."""

    name: ClassVar[str]
    """Implementation name, as used on the command line."""
    package: ClassVar[str]
    """The pip package that provides the engine."""
    integrators: ClassVar[tuple[str, ...]]
    """Fixed-step integrators :meth:`simulate` accepts."""
    adaptive: ClassVar[bool] = False
    """Whether :meth:`solve` (error-controlled integration by scipy) is offered."""
    requires_couplings: ClassVar[bool] = False
    """An implementation that exists only for models with couplings (it equals another one
    elsewhere)."""
    gyroscopic_implicit: ClassVar[bool] = False
    """Whether the engine's ``implicitfast`` differentiates a free body's gyroscopic force (a
    different map from semi-implicit Euler there)."""
    dtype: ClassVar[type[np.floating]] = np.float64
    """The floating-point type the engine computes in."""
    inertia_rounded: bool = False
    """Whether the engine's loader stores an inertia tensor rounded beyond round-off of its
    read-back (PyBullet: principal moments of a Jacobi diagonalization stopped at 1e-6 of
    the trace): a rigid body's tensor as held is then part of its model variant."""
    couplings_with_field: ClassVar[bool] = False
    """Whether the adapter holds couplings and an external field in one model (refused, before
    any work, where it does not)."""

    @classmethod
    def create(cls, model: Multibody, *, symbolic: Symbolic) -> Adapter:
        """The adapter of ``model``, handed how to keep symbolic equations (used only by an
        adapter that derives them: it overrides this)."""
        return cls(model)

    def __init__(self, model: Multibody) -> None:
        if model.couplings and model.central_mu and not self.couplings_with_field:
            raise Unsupported(f"{self.name}: couplings together with a field")
        self.spec = model

    max_steps: int | None = None
    """The longest fixed-step run the engine makes here (None: no limit); a study whose runs
    are longer is refused before any of them starts."""
    device: str = "cpu"
    """Where the engine computes (a port: from ``--device``)."""
    rk4_group_order: ClassVar[int] = 4
    """RK4's order on a rotating joint as the engine defines its stages there (2 where it
    sums stage velocities across tangent spaces: MJX, MuJoCo before 4.0)."""
    error_controlled: ClassVar[bool] = False
    """Whether the engine offers error-controlled integration of its own
    (``simulate_controlled``: Drake's)."""
    parser_warnings: Sequence[str] = ()
    """What the engine's parser said it ignored in the case's model (Drake's)."""

    @property
    def eps(self) -> float:
        """The engine's unit round-off (ε of its floating-point type)."""
        return float(np.finfo(self.dtype).eps)

    @staticmethod
    @abstractmethod
    def version() -> str:
        """The engine's version string."""

    @classmethod
    def release_compiled(cls) -> None:
        """Free what the engine compiled for the models built so far (called when a run drops
        a case's models): an engine that compiles per model and keeps every program would
        otherwise grow without bound over a run. Nothing to free by default."""
        return None

    @abstractmethod
    def loaded_bodies(self) -> list[LoadedBody]:
        """Masses and inertias as loaded, in the spec's body order."""

    @abstractmethod
    def loaded_gravity(self) -> np.ndarray:
        """The gravity vector (m/s², world frame) the engine holds after loading."""

    @abstractmethod
    def mass_matrix(self, q: np.ndarray) -> np.ndarray: ...

    @abstractmethod
    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...

    @abstractmethod
    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray: ...

    @abstractmethod
    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray: ...

    @abstractmethod
    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...

    @abstractmethod
    def potential_energy(self, q: np.ndarray) -> np.ndarray: ...

    @abstractmethod
    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        """Fixed-step integration from (q0, v0) for ``round(duration / dt)`` steps, τ = 0."""

    batches_steps: ClassVar[bool] = False
    """Whether :meth:`simulate_many` runs several step sizes at once (MuJoCo Warp: one world
    per step size) rather than one after another."""

    def simulate_many(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dts: Sequence[float],
        integrator: str,
    ) -> list[Trajectory]:
        """:meth:`simulate` at each step size of ``dts`` — the same runs, one per step size."""
        return [self.simulate(q0, v0, duration, dt, integrator) for dt in dts]

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The couplings' multipliers f (n, n_couplings) of the forward-dynamics solve at τ,
        in the sign of ``M v̇ + h = τ + Cᵀ f`` (C = ``spec.coupling_matrix()``)."""
        raise NotImplementedError(f"{self.name} reports no constraint force")

    def softness(self) -> tuple[float, ...] | None:
        """How the loaded model enforces couplings: ``None`` for exactly (a KKT solve), or a
        soft constraint's parameters (MuJoCo: solref + solimp, read back from the model)."""
        return None

    def evaluate_all(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """Every quantity at each state, keyed ``mass_matrix``, ``bias_forces``,
        ``forward_dynamics`` (at τ), ``inverse_dynamics`` (at v̇ = a), ``kinetic_energy``,
        ``potential_energy`` and, with couplings, ``constraint_force`` (at τ). Engines
        override this with their cheapest batched path."""
        out: dict[str, np.ndarray] = {
            Quantity.MASS_MATRIX: self.mass_matrix(q),
            Quantity.BIAS_FORCES: self.bias(q, v),
            Quantity.FORWARD_DYNAMICS: self.forward(q, v, tau),
            Quantity.INVERSE_DYNAMICS: self.inverse(q, v, a),
            Quantity.KINETIC_ENERGY: self.kinetic_energy(q, v),
            Quantity.POTENTIAL_ENERGY: self.potential_energy(q),
        }
        if self.spec.couplings:
            out[Quantity.CONSTRAINT_FORCE] = self._check(
                "constraint force", self.constraint_force(q, v, tau)
            )
        return out

    def defects(self) -> tuple[str, ...]:
        """What the engine is known (measured) to do wrong on this model, each in a sentence
        a failed row cites as its evidence; none by default."""
        return ()

    def defect_effects(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                       a: np.ndarray) -> dict[str, np.ndarray]:
        """Quantity → what :meth:`defects` add to the engine's values at each state (its
        layout, as :meth:`evaluate_all` at the same arguments): the predicted size a failed
        row's difference is checked against. None by default."""
        return {}

    def definition(self, integrator: str) -> str:
        """The integrator's definition as a name: two names with the same definition give the
        same run (dyncheck's own ``implicitfast`` is ``euler`` where nothing is damped)."""
        return integrator

    def solve(self, q0: np.ndarray, v0: np.ndarray, t_eval: np.ndarray, rtol: float) -> Trajectory:
        """Error-controlled integration (scipy's DOP853) of the engine's forward dynamics."""
        raise NotImplementedError(f"{self.name} offers no error-controlled integration")

    def _outputs(
        self,
        M: np.ndarray,
        bias: np.ndarray,
        fwd: np.ndarray,
        inv: np.ndarray,
        kin: np.ndarray,
        pot: np.ndarray,
        constraint: np.ndarray | None = None,
    ) -> dict[str, np.ndarray]:
        """The batched quantities under their canonical names, each checked finite."""
        out = {
            Quantity.MASS_MATRIX: M,
            Quantity.BIAS_FORCES: bias,
            Quantity.FORWARD_DYNAMICS: fwd,
            Quantity.INVERSE_DYNAMICS: inv,
            Quantity.KINETIC_ENERGY: kin,
            Quantity.POTENTIAL_ENERGY: pot,
        }
        if constraint is not None:
            out[Quantity.CONSTRAINT_FORCE] = constraint
        return {key: self._check(key, val) for key, val in out.items()}

    def _check(self, what: str, value: np.ndarray) -> np.ndarray:
        if not np.all(np.isfinite(value)):
            raise EngineError(f"{self.name}: {what} returned a non-finite value")
        if what == "simulate" and np.abs(value).max() > DIVERGED:
            raise EngineError(f"{self.name}: simulate diverged (|q| > {DIVERGED:g})")
        return value

    def raw_calls(self, qe: np.ndarray, ve: np.ndarray, te: np.ndarray,
                  ae: np.ndarray) -> Callable[[], None] | None:
        """The engine's plainest loop over these states (its layout): every quantity of
        :meth:`evaluate_all` by the engine's own calls, state by state — what ``dyncheck
        bench`` times the adapter against. None: no engine call of its own to time
        (dyncheck's symbolic peer, a port timed by its compiled batch)."""
        return None

