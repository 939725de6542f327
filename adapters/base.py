"""The interface every engine implements (:class:`ModelEngine`), and what it returns.

The standard form, in the engine's own joint coordinates q (positions) and v (velocities):

    M(q) v̇ + h(q, v) = τ

M is the joint-space mass matrix (symmetric positive definite), h the bias forces (Coriolis,
centrifugal *and gravity*, so that h(q, 0) = ∂V/∂q), τ the applied generalized forces; all
are covariant, in the engine's joint coordinates and sign conventions. Energies: T = ½ vᵀ M v;
V as the engine computes it (its datum is the engine's, not the book's). All methods take
batches: q, v, τ, v̇ of shape (n, nv); they return (n, nv, nv), (n, nv) or (n,).
Engines never see the book's coordinates: the comparison layer maps them.
"""

from __future__ import annotations

import importlib.metadata
import time
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from dyncheck.adapters.actuators import Actuation, InputJacobian
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.model_tree import Derivatives, Dynamics, ModelTree, Transition
from dyncheck.adapters.offers import Field, Offer
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import Unsupported


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


Answer = tuple[Any, float] | Exception
"""A request's answer: (its value, the engine's seconds), or the exception it raised."""


class ModelEngine(ABC):
    """An engine's reading of a model file (an MJCF or a URDF): the engine interface of
    ``dyncheck check``, and of ``dyncheck run`` where a registration names ``run`` (the book
    case as its registration hands it, :mod:`dyncheck.case_engine`).

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
