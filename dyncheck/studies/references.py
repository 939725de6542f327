"""Reference trajectories of a case's model variants (DOP853 at rtol 1e-13, with an error
estimate) and the general method stepped by the engines' fixed-step integrators."""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numpy as np

from dyncheck import coordinates as co
from dyncheck.adapters.integrators import Addresses, integrate
from dyncheck.cache.measured import reused
from dyncheck.cases.base import Case
from dyncheck.cases.coordinate_maps import CoordinateMap
from dyncheck.implementations import general_method, reference_trajectory
from dyncheck.variants import Variant
from dyncheck.vocabulary import Integrator

T = TypeVar("T")


def difference(case: Case, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a − b| per coordinate, angles of ``case.periodic`` taken modulo 2π."""
    d = a - b
    for i, periodic in enumerate(case.periodic):
        if periodic:
            d[..., i] = (d[..., i] + np.pi) % (2 * np.pi) - np.pi
    return np.abs(d)


class References:
    """Reference trajectories on the case's grid, per model variant, with error estimates."""

    def __init__(self, case: Case) -> None:
        self.case = case
        self.t = case.trajectory.grid()
        self._cache: dict[Variant, tuple[np.ndarray, float]] = {}
        self._discrete: dict[tuple[Variant, str, float], tuple[np.ndarray, np.ndarray]] = {}

    def __call__(self, variant: Variant) -> tuple[np.ndarray, float]:
        """(q on the grid, estimated max error of q)."""
        if variant not in self._cache:
            self._cache[variant] = self._stored("dop853", (variant,), lambda: self._solve(variant))
        return self._cache[variant]

    def _solve(self, variant: Variant) -> tuple[np.ndarray, float]:
        ref = reference_trajectory(self.case, variant, self.t, rtol=1e-13)
        tighter = reference_trajectory(self.case, variant, self.t, rtol=2.5e-14)
        return ref, float(np.abs(ref - tighter).max())

    def _stored(self, what: str, key: tuple, compute: Callable[[], T]) -> T:
        """``compute()``, or what an earlier run stored for the same case and ``key`` with the
        same dyncheck, libraries and machine (:func:`~dyncheck.cache.measured.reused`: the
        same inputs give the same numbers, read back to the last bit), so that a second run
        steps no reference; ``--no-cache`` computes afresh."""
        label = f"{self.case.name}-{what}"
        return reused("references", label, [repr((self.case, *key)).encode()], compute,
                      expect=tuple)

    def discrete(self, variant: Variant, integrator: str, dt: float) -> np.ndarray:
        """q (book coordinates) at every step of the general method stepped by a fixed-step
        integrator *in the engine's coordinates*, as the engines step: v̇ is mapped by
        (2.2.5) (ā = J a + ∂²x̄ v v), so the discrete map is the engines' own, also where the
        coordinate map is non-linear. With ``rk4-held-force`` the field's engine-coordinate
        force J⁻ᵀ Q is frozen at the start of each step."""
        return self.discrete_engine(variant, integrator, dt)[0]

    def discrete_engine(
        self, variant: Variant, integrator: str, dt: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`discrete` as (book q, engine q) at every step. A soft-constraint model is
        stepped on the free masses themselves — the engine's coordinates are the reference's
        free coordinates (the same s = A x + b, checked here) — as they leave the cords."""
        if integrator == Integrator.IMPLICITFAST:  # the same map: D = 0
            integrator = Integrator.EULER
        key = (variant, integrator, dt)
        if key not in self._discrete:
            self._discrete[key] = self._stored(
                "discrete", key, lambda: self._step(variant, integrator, dt)
            )
        return self._discrete[key]

    def _step(self, variant: Variant, integrator: str, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`discrete_engine`'s run, computed."""
        dyn = general_method(self.case, variant)
        cmap = self.case.engine_map()
        spec = self.case.trajectory
        steps = round(spec.duration / dt)
        if getattr(dyn, "softness", None) is not None:
            if not (
                np.array_equal(cmap.A, dyn.cords.A)
                and np.array_equal(np.asarray(cmap.offset), dyn.cords.b)
            ):
                raise ValueError(f"{self.case.name}: engine map is not the free coordinates")
            s0, sd0 = dyn.cords.to_free(np.asarray(spec.q0), np.asarray(spec.v0))
            qe, _ = integrate(
                lambda s, sd, held=None: dyn.free(s[None], sd[None])[0],
                s0[0],
                sd0[0],
                dt,
                steps,
                integrator,
            )
            return cmap.to_book(qe), qe

        def book_state(qe: np.ndarray, ve: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            qb = cmap.to_book(qe[None])
            return qb, co.velocity_to_book(cmap, qb, ve[None])

        def acc(qe: np.ndarray, ve: np.ndarray, held=None) -> np.ndarray:
            qb, vb = book_state(qe, ve)
            tau = np.zeros_like(qb)
            if held is not None:  # replace the live field force by the frozen one
                tau = co.force_to_book(cmap, qb, held[None]) - dyn.field_force(qb)
            ab = dyn.forward(qb, vb, tau)
            return co.acceleration_to_engine(cmap, qb, vb, ab)[0]

        def freeze(qe: np.ndarray, ve: np.ndarray) -> np.ndarray:
            qb, _ = book_state(qe, ve)
            return co.force_to_engine(cmap, qb, dyn.field_force(qb))[0]

        q0 = np.asarray(spec.q0, float)[None]
        qe0 = cmap.to_engine(q0)[0]
        ve0 = co.velocity_to_engine(cmap, q0, np.asarray(spec.v0, float)[None])[0]
        layout = Addresses.of([j.type for j in self.case.multibody().joints])
        qe, _ = integrate(acc, qe0, ve0, dt, steps, integrator, freeze=freeze, layout=layout)
        _require_chart(cmap, layout, qe)
        return cmap.to_book(qe), qe


def _require_chart(cmap: CoordinateMap, layout: Addresses, qe: np.ndarray) -> None:
    """The book's coordinates must determine the engine state along the stepped run (the
    map's velocities and accelerations are those of ``to_engine(to_book(qe))``). A spherical
    pendulum's bob direction does not fix the spin about the rod, which the stepped rotation
    group acquires (a geometric phase): there the prediction is refused, not made wrong."""
    back = cmap.to_engine(cmap.to_book(qe))
    gap = np.abs(back - qe)
    for qa, _ in layout.rotations():
        dots = np.abs(np.sum(back[:, qa : qa + 4] * qe[:, qa : qa + 4], axis=1))
        gap[:, qa : qa + 4] = 2 * np.arccos(np.clip(dots, 0.0, 1.0))[:, None]
    if gap.max() > 1e-6:
        raise ValueError(
            f"the book's coordinates do not determine the engine state along the run (gap "
            f"{gap.max():.2g}): {cmap.description}"
        )
