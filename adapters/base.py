"""The interface every engine adapter implements.

The standard form, in the engine's own joint coordinates q (positions) and v (velocities):

    M(q) v̇ + h(q, v) = τ

M is the joint-space mass matrix (symmetric positive definite), h the bias forces (Coriolis,
centrifugal *and gravity*, so that h(q, 0) = ∂V/∂q), τ the applied generalized forces; all
are covariant, in the engine's joint coordinates and sign conventions. Energies: T = ½ vᵀ M v;
V as the engine computes it (its datum is the engine's, not the book's). All methods take
batches: q, v, τ, v̇ of shape (n, nv); they return (n, nv, nv), (n, nv) or (n,).
Adapters never see the book's coordinates: the comparison layer maps them.
"""

from __future__ import annotations

import importlib.metadata
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from dyncheck.adapters.actuators import Actuation, InputJacobian
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.model_tree import Derivatives, Dynamics, ModelTree, StateLayout, Transition
from dyncheck.adapters.offers import Field, Offer
from dyncheck.adapters.symbolic import Symbolic
from dyncheck.cases.multibody import Coupling, Multibody
from dyncheck.errors import EngineError, Unsupported
from dyncheck.vocabulary import Quantity

DIVERGED = 1e12
"""A coordinate beyond this (rad or m) means a run has blown up: no case here comes near it."""


@dataclass(frozen=True)
class Trajectory:
    """Sampled states: ``t`` (k,), ``q`` and ``v`` (k, nv), engine coordinates."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray


@dataclass(frozen=True, kw_only=True)
class Steps:
    """An error-controlled run's step counts: steps taken, and steps shrunk by its error
    control."""

    taken: int
    shrunk: int


@dataclass(frozen=True)
class LoadedBody:
    """A body's mass (kg) and inertia about its centre of mass (kg·m², body axes) as the engine
    holds it after loading the model — read back, not assumed."""

    name: str
    mass: float
    inertia: np.ndarray


class Adapter(ABC):
    """One engine behind the standard form ``M(q) v̇ + h(q, v) = τ``."""

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
    @classmethod
    def steps_in_a_chart(cls) -> bool:
        """Whether its stepping advances a rotating joint in coordinates of its own (angles, a
        quaternion's components: q₊ = q + h N(q) v), not along the rotation group: its runs
        then differ from another engine's by O(h) there. An adapter's is its layout's: a
        ball joint held in angles."""
        return cls.state_layout.charted

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

    def unavailable_quantities(self) -> dict[str, str]:
        """Quantity → why the engine does not compute it on this model (its limit, in its
        words; its values NaN in :meth:`evaluate_all`): none by default."""
        return {}

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
        unavailable = self.unavailable_quantities()  # its limits: NaN, said on their rows
        return {key: val if key in unavailable else self._check(key, val)
                for key, val in out.items()}

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


Answer = tuple[Any, float] | Exception
"""A request's answer: (its value, the engine's seconds), or the exception it raised."""


class ModelEngine(ABC):
    """An engine's reading of a model file (an MJCF or a URDF): the engine interface of
    ``dyncheck check``, and of ``dyncheck run`` where a registration names ``run`` (the book
    case written as a file, :mod:`dyncheck.adapters.model_adapter`).

    It holds the engine-neutral ``tree`` (:class:`~dyncheck.adapters.model_tree.ModelTree`:
    what the engine read, in its own layout) and computes, over a batch of states in that
    layout, the standard form M(q) v̇ + h(q, v) = τ — the book's equations of motion
    (2.2.23)–(2.2.26) in joint coordinates: M, h, τ at v̇ and v̇ at τ = 0, and T, V
    (:meth:`dynamics`). What it offers beyond that is a class fact, :attr:`offers`, never
    found by asking the object; a method it does not offer raises
    :class:`~dyncheck.errors.Unsupported` in the engine's words.

    A batch is asked for by :meth:`submit` and answered by :meth:`collect` (or both kinds
    at once, :meth:`submit_both`): an engine in this process answers at once, one in its own
    process (``dyncheck.check.engines.Isolated``) while the caller computes."""

    engine: str
    """Its implementation's name (the registry's): a class fact."""
    offers: frozenset[Offer] = frozenset()
    """A class fact (a proxy of an engine in another process copies its engine's)."""
    no_actuation: str = ""
    """Why it computes no actuator force where it does not offer
    :attr:`Offer.ACTUATION` (its limit, or dyncheck's, in a sentence); empty: it holds no
    actuator model, its input being the generalized force itself."""
    tree: ModelTree
    steps_in_a_chart: bool = False
    """A class fact: its stepping (:attr:`Offer.STEPPING`) advances a ball or free joint's own
    coordinates (roll-pitch-yaw angles, a quaternion's four components: q₊ = q + h N(q) v),
    not along the rotation group as MuJoCo's Euler does (its runs then differ from another
    engine's by O(h) on a rotating body)."""
    gyroscopic_implicit: bool = False
    """A class fact: its ``implicitfast`` differentiates a free body's gyroscopic force
    (MuJoCo ≥ 3.11: no longer semi-implicit Euler on a free joint)."""
    rk4_group_order: int = 4
    """A class fact: RK4's order on a rotating joint as its stepping defines the stages (2
    where it sums stage velocities across tangent spaces: MuJoCo before 4.0)."""
    couplings_with_field: bool = False
    """A class fact: it holds couplings and a field in one model (MuJoCo's)."""
    no_body_forces: ClassVar[str] = "its model takes no force on a body (an external field)"
    """A class fact: why it takes no field, where it does not offer
    :attr:`Offer.BODY_FORCES` (its limit, in a sentence)."""
    coupled_joints: ClassVar[int | None] = None
    """A class fact, where it offers :attr:`Offer.COUPLINGS`: the most joints one coupling may
    tie (PyBullet's gear constraint: 2); None, any number."""
    no_bias_with_ball: ClassVar[str] = ""
    """A class fact: why it computes no h and no inverse dynamics on a model with a ball
    joint, where it cannot (its limit, in a sentence); empty: it computes them."""
    batches_steps: ClassVar[bool] = False
    """A class fact: :meth:`simulate_many` runs its step sizes at once (MuJoCo Warp's
    worlds), not one after another."""
    per_state_calls: ClassVar[bool] = True
    """A class fact: :meth:`dynamics` is a loop of its own per-state calls, what ``dyncheck
    bench`` times a run against; False: one compiled batch (a port)."""
    max_steps: int | None = None
    """The longest fixed-step run it makes here (None: no limit)."""
    device: str = "cpu"
    """Where it computes (a port: from ``--device``)."""
    definitions: ClassVar[Mapping[str, str]] = {}
    """A class fact: its integrators whose run is another's here (name → the definition it
    runs: Pinocchio's ``implicitfast`` is ``euler``, nothing damped); one run serves both."""
    parser_warnings: tuple[str, ...] = ()
    """Its parser's own warnings on the file, verbatim (Drake's: what it ignores); the
    tree's ``notes`` hold them summarized, with dyncheck's own notes on the reading."""
    _answer: Answer
    _both: tuple[Answer, Answer]

    @abstractmethod
    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics: ...

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ at τ (its layout): M⁻¹ (τ − h) from :meth:`dynamics`, overridden where it has its
        own (:attr:`Offer.FORWARD`) or its h fails."""
        d = self.dynamics(q, v, np.zeros_like(v))
        return np.linalg.solve(d.mass_matrix, (tau - d.bias)[..., None])[..., 0]

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        raise Unsupported(f"{self.engine} offers no derivatives")

    def transition(self, q: np.ndarray, v: np.ndarray,
                   a: np.ndarray) -> tuple[Transition, ...]:
        raise Unsupported(f"{self.engine} offers no step Jacobians")

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``steps`` steps of ``dt`` by ``integrator`` (one of its registration's), q and v at
        every step, the start included (:attr:`Offer.STEPPING`)."""
        raise Unsupported(f"{self.engine} offers no stepping of its own")

    def simulate_many(self, q0: np.ndarray, v0: np.ndarray, dts: Sequence[float],
                      steps: Sequence[int], *, integrator: str,
                      field: Field | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
        """:meth:`simulate` at each step size, ``steps[i]`` steps of ``dts[i]``."""
        return [self.simulate(q0, v0, dt, n, integrator=integrator, field=field)
                for dt, n in zip(dts, steps, strict=True)]

    @classmethod
    def version(cls, package: str) -> str:
        """Its version: its ``package``'s, unless it says more (a port: its device)."""
        return importlib.metadata.version(package)

    @classmethod
    def release_compiled(cls) -> None:
        """Free what it compiled for the models built so far (a port's programs)."""
        return None

    def simulate_controlled(self, q0: np.ndarray, v0: np.ndarray, period: float, samples: int,
                            *, accuracy: float, scheme: str | None = None, caching: bool = True,
                            field: Field | None = None) -> tuple[np.ndarray, np.ndarray, Steps]:
        """Its error-controlled run at ``accuracy`` (``scheme``: its own name of one of its
        error-controlled integrators, None its default; ``caching``: its computation cache,
        which must not change a result), q and v every ``period`` for ``samples`` periods,
        and its step counts (:attr:`Offer.CONTROLLED_STEPPING`)."""
        raise Unsupported(f"{self.engine} offers no error-controlled stepping of its own")

    def solve(self, q0: np.ndarray, v0: np.ndarray, t_eval: np.ndarray, *, rtol: float,
              field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """q, v at ``t_eval``: scipy's DOP853, rtol = atol = ``rtol`` (:attr:`Offer.SOLVING`)."""
        raise Unsupported(f"{self.engine} offers no error-controlled integration")

    def softness(self) -> tuple[float, ...] | None:
        """Its couplings' soft-constraint model (MuJoCo's solref and solimp); None: exact."""
        return None

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """Hold ``couplings`` from now on (:attr:`Offer.COUPLINGS`)."""
        raise Unsupported(f"{self.engine}: its model holds no coupling between joints")

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The couplings' multipliers f (n, couplings) of its forward dynamics at τ, in the
        sign of M v̇ + h = τ + Cᵀ f (:attr:`Offer.COUPLINGS`)."""
        raise Unsupported(f"{self.engine}: its model holds no coupling between joints")

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """v̇ and the multipliers at τ of one solve (:attr:`Offer.COUPLINGS`); by default
        :meth:`forward` and :meth:`constraint_forces`, each its own."""
        return self.forward(q, v, tau), self.constraint_forces(q, v, tau)

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """The generalized force (n, nv, its layout) of ``field`` at each state
        (:attr:`Offer.BODY_FORCES`)."""
        raise Unsupported(f"{self.engine}: its model takes no force on a body")

    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """Its actuators' generalized force at controls ``u`` (n, its tree's actuators) and
        its forward dynamics with that force (its layout)."""
        raise Unsupported(self.no_actuation or f"{self.engine} holds no actuators: its "
                          "input is the generalized force itself")

    def input_jacobians(self, q: np.ndarray, v: np.ndarray,
                        u: np.ndarray) -> tuple[InputJacobian, ...]:
        raise Unsupported(f"{self.engine} offers no step Jacobian in its controls")

    def control_derivatives(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """∂v̇/∂u (n, nv, its actuators) at each state and control, its layout."""
        raise Unsupported(f"{self.engine} offers no derivative in its controls")

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """Its own rows and forward dynamics on its tree's closures (:attr:`Offer.CLOSURES`)."""
        raise Unsupported(f"{self.engine} offers no dynamics with the file's constraints")

    def closed_derivatives(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """∂v̇/∂(q, v) of its constrained dynamics (:attr:`Offer.CLOSED_DERIVATIVES`)."""
        raise Unsupported(f"{self.engine} offers no derivatives with the file's constraints")

    def request(self, kind: str, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Answer:
        """One request of ``kind`` (``dynamics``, ``derivatives``, ``transition``,
        ``actuation`` or ``input_jacobians``, whose ``a`` is the controls, or ``closed``,
        whose ``a`` is τ) answered here,
        timed; its exception handed back, not raised."""
        method = {"dynamics": self.dynamics, "derivatives": self.derivatives,
                  "transition": self.transition, "actuation": self.actuation,
                  "input_jacobians": self.input_jacobians,
                  "control_derivatives": self.control_derivatives, "closed": self.closed,
                  "closed_derivatives": self.closed_derivatives}[kind]
        t0 = time.perf_counter()
        try:
            return method(q, v, a), time.perf_counter() - t0
        except Exception as exc:  # the caller's rows say how the engine failed
            return exc

    def submit(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *,
               kind: str = "dynamics") -> None:
        """Ask for the batch's ``dynamics`` or ``derivatives``: :meth:`collect` answers."""
        self._answer = self.request(kind, q, v, a)

    def collect(self) -> tuple[Any, float]:
        """The submitted batch's answer and the engine's seconds; its exception raised."""
        if isinstance(self._answer, Exception):
            raise self._answer
        return self._answer

    def submit_both(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, k: int) -> None:
        """Ask for the derivatives at the batch and the step Jacobians at its first ``k``
        states in one request: :meth:`collect_both` answers."""
        self._both = (self.request("derivatives", q, v, a),
                      self.request("transition", q[:k], v[:k], a[:k]))

    def collect_both(self) -> tuple[Answer, Answer]:
        return self._both
