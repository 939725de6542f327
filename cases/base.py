"""The case record: a system defined once, in the book's coordinates and sign conventions."""

from __future__ import annotations

import itertools
import math
from abc import ABC, abstractmethod
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from dyncheck.cases.coordinate_maps import CoordinateMap
from dyncheck.cases.multibody import Multibody
from dyncheck.errors import InvalidInput, finite_array, integer, positive
from dyncheck.vocabulary import Integrator

INTEGRATORS: tuple[str, ...] = tuple(Integrator)
"""Fixed-step integrators as MuJoCo defines them; nominal orders 1, 1, 4. ``rk4-held-force``
is RK4 with a state-dependent external force evaluated once per step and held over the
stages (what setting MuJoCo's ``xfrc_applied`` before ``mj_step`` does): its predicted
order is 1. ``rk2`` and ``rk3`` are Drake's fixed-step Runge–Kutta integrators."""

NOMINAL_ORDER: dict[str, int] = {i: i.nominal_order for i in Integrator}
"""Each integrator's nominal order (the vocabulary's)."""


STEPS: dict[str, tuple[float, ...]] = {
    Integrator.EULER: (2e-3, 1e-3, 5e-4, 2.5e-4),
    Integrator.IMPLICITFAST: (2e-3, 1e-3, 5e-4, 2.5e-4),
    Integrator.RK2: (1e-2, 5e-3, 2.5e-3, 1.25e-3),
    Integrator.RK3: (1e-2, 5e-3, 2.5e-3, 1.25e-3),
    Integrator.RK4: (1e-2, 5e-3, 2.5e-3, 1.25e-3),
}
"""Default halving sequences (s): coarse enough that each integrator's error stands well above
the reference's (~1e-13), fine enough to be in the asymptotic range on these cases."""


@dataclass(frozen=True)
class StateSample:
    """Book-coordinate states at which every implementation is evaluated.

    Shapes: ``q``, ``v``, ``tau`` (applied generalized forces, covariant, for forward dynamics)
    and ``a`` (accelerations, for inverse dynamics) are all (n, ndof).
    """

    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray
    a: np.ndarray

    def __len__(self) -> int:
        return self.q.shape[0]


@dataclass(frozen=True)
class TrajectorySpec:
    """An initial state (book coordinates), a duration (s) and, per integrator, a halving
    sequence of step sizes (s), coarsest first, each dividing the duration."""

    q0: tuple[float, ...]
    v0: tuple[float, ...]
    duration: float
    steps: dict[str, tuple[float, ...]]

    def __post_init__(self) -> None:
        positive("duration", self.duration)
        finite_array("q0", self.q0, (len(self.q0),))
        finite_array("v0", self.v0, (len(self.v0),))
        if len(self.v0) != len(self.q0):
            n = len(self.q0)
            raise InvalidInput("v0", self.v0, f"{n} value{'s' * (n != 1)}, as many as q0")
        for integrator, dts in self.steps.items():
            if integrator not in INTEGRATORS:
                raise InvalidInput("integrator", integrator, f"one of {', '.join(INTEGRATORS)}")
            if len(dts) < 2:
                raise InvalidInput(f"steps[{integrator}]", dts, "at least two step sizes")
            for dt in dts:
                positive(f"steps[{integrator}] dt", dt)
                steps = self.duration / dt
                if abs(steps - round(steps)) > 1e-9 * steps:
                    raise InvalidInput(
                        f"steps[{integrator}] dt", dt, f"a divisor of duration {self.duration}"
                    )
            for coarse, fine in itertools.pairwise(dts):
                if not math.isclose(coarse, 2 * fine, rel_tol=1e-12):
                    raise InvalidInput(f"steps[{integrator}]", dts, "a halving sequence")
        for integrator, dts in self.steps.items():
            ratio = self.grid_step / dts[0]
            if abs(ratio - round(ratio)) > 1e-9 * ratio:
                raise InvalidInput(f"steps[{integrator}]", dts, "steps dividing the coarsest")

    @property
    def grid_step(self) -> float:
        """The spacing of the common comparison grid: the coarsest step of all integrators."""
        return max(dts[0] for dts in self.steps.values())

    def grid(self) -> np.ndarray:
        """Times (s) at which trajectories are compared, shape (k,)."""
        return np.arange(round(self.duration / self.grid_step) + 1) * self.grid_step


@dataclass(frozen=True)
class Case(ABC):
    """A system of the book: parameters in its coordinates, sampled states, a trajectory.

    Subclasses add the physical parameters (SI units, documented per field) and implement the
    engine-neutral model and the map from book coordinates to engine joint coordinates.
    """

    name: ClassVar[str]
    title: ClassVar[str]
    book_refs: ClassVar[str]
    coordinates: ClassVar[tuple[str, ...]]
    periodic: ClassVar[tuple[bool, ...]] = ()
    """Per coordinate: an angle whose differences are taken modulo 2π (default: none)."""

    n_states: int = 16
    seed: int = 20261122
    trajectory: TrajectorySpec = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        """What every case shares: a positive sample count, a seed numpy accepts, an initial
        state with one value per coordinate."""
        integer("n_states", self.n_states, 1)
        integer("seed", self.seed, 0)
        if self.trajectory is not None and len(self.trajectory.q0) != self.ndof:
            raise InvalidInput("trajectory.q0", self.trajectory.q0,
                               f"{self.ndof} value{'s' * (self.ndof != 1)}, one per "
                               f"coordinate {self.coordinates}")

    @property
    def ndof(self) -> int:
        return len(self.coordinates)

    @property
    def n_bodies(self) -> int:
        return len(self.multibody().bodies)

    @abstractmethod
    def params(self) -> dict[str, float]:
        """The physical parameters by the book's names (m, l, g, …)."""

    @abstractmethod
    def multibody(self) -> Multibody:
        """The engine-neutral model every adapter builds from."""

    @abstractmethod
    def engine_map(self) -> CoordinateMap:
        """x̄(x): the engine's joint coordinates as functions of the book's (2.2.2)."""

    @abstractmethod
    def rest(self) -> np.ndarray:
        """A configuration (book coordinates) used as the datum of potential energy."""

    @abstractmethod
    def state_scale(self) -> tuple[float, float, float]:
        """Ranges (max |q̇|, max |τ|, max |q̈|) for sampled states."""

    def chart_singularity(self, q: np.ndarray) -> str | None:
        """Why ``q`` (one state, book coordinates) lies on the chart's singular set, or None.
        The default chart has none."""
        return None

    def check_state(self, field: str, q: tuple[float, ...] | np.ndarray) -> None:
        """InvalidInput when a user-given state sits on the chart's singular set."""
        why = self.chart_singularity(np.asarray(q, dtype=float))
        if why:
            raise InvalidInput(
                field,
                tuple(float(x) for x in q),
                f"off the singular set of the book's chart ({why})",
            )

    def q_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Sampling box of the book's coordinates, away from the chart's singular set."""
        return np.full(self.ndof, -np.pi), np.full(self.ndof, np.pi)

    def iter_states(
        self, n: int | None = None, chunk: int = 8192, *, start: int = 0, stop: int | None = None
    ) -> Iterator[StateSample]:
        """Deterministic states in chunks of at most ``chunk``: the rest state first, then
        seeded uniform samples, angles in (−π, π). Each array has its own random stream, so
        the states do not depend on the chunk size; ``start``/``stop`` select the states
        [start, stop) of the ``n`` — the same numbers, the streams jumped ahead (PCG64's
        ``advance``: one 64-bit draw per uniform double), so that a sweep can be cut into
        slices on several workers."""
        n = self.n_states if n is None else n
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise InvalidInput("states", n, "a positive integer")
        stop = n if stop is None else stop
        if not 0 <= start < stop <= n:
            raise InvalidInput("states slice", (start, stop), f"within [0, {n}]")
        bits = [np.random.PCG64(s) for s in np.random.SeedSequence(self.seed).spawn(4)]
        streams = [np.random.Generator(b.advance(start * self.ndof)) for b in bits]
        vmax, taumax, amax = self.state_scale()
        low, high = self.q_bounds()
        bounds: tuple[tuple[np.ndarray | float, np.ndarray | float], ...] = (
            (low, high), (-vmax, vmax), (-taumax, taumax), (-amax, amax)
        )
        for first in range(start, stop, chunk):
            k = min(chunk, stop - first)
            q, v, tau, a = (
                g.uniform(lo, hi, (k, self.ndof))
                for g, (lo, hi) in zip(streams, bounds, strict=True)
            )
            if first == 0:
                q[0], v[0], tau[0], a[0] = self.rest(), 0.0, 0.0, 0.0
            yield StateSample(q=q, v=v, tau=tau, a=a)

    def sample_states(self, n: int | None = None) -> StateSample:
        """All of :meth:`iter_states` in one sample."""
        return next(self.iter_states(n, chunk=n or self.n_states))
