"""Trajectories: the observed order of accuracy of every engine × integrator, and
engine-against-engine runs of the same integrator.

Each run starts from the case's initial state (book coordinates, mapped to the engine's) and
is compared on a common grid of times against the reference trajectory of *the same model*
(the general method on the implementation's model variant, DOP853 at rtol = atol = 1e-13), so
that the study measures the integrator alone. The observed order between steps h₁ = 2h₂ is
p = ln(E₁/E₂)/ln(h₁/h₂) (Roy 2005); a step counts as asymptotic only where its error exceeds
100× the reference's own error estimate |ref(1e-13) − ref(2.5e-14)| (2.5e-14 is near the
smallest rtol DOP853 accepts).

Two engines with the same integrator and step are compared step by step: on the same model
they must agree to accumulated round-off; on models that differ by a named convention, their
difference must equal the predicted one — the reference's equations for the two model
variants stepped by the same fixed-step integrator (MuJoCo's definition), within that
round-off. A run passes when the
finest asymptotic pair shows the nominal order ± 0.1; a large error at a coarse step is the
integrator's truncation error, reported with its size, not a failure.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import combinations
from typing import Any

import numpy as np

from dyncheck import coordinates as co
from dyncheck.adapters.integrators import STEPPERS, Layout, integrate
from dyncheck.cases import NOMINAL_ORDER, Case
from dyncheck.cases.coordinate_maps import CoordinateMap, EulerAngleMap
from dyncheck.cases.multibody import ROTATING
from dyncheck.comparison import describe, soft_factor
from dyncheck.conventions import is_chart
from dyncheck.errors import EngineNotInstalled, Unsupported
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    SOFT_CONSTRAINT,
    Implementation,
    Variant,
    book_variant,
    compared,
    general_method,
    reference_trajectory,
)
from dyncheck.reference import rigid
from dyncheck.results import ConvergencePoint, Discrepancy
from dyncheck.tolerances import (
    EPS,
    ORDER_SLACK,
    REFERENCE_MARGIN,
    ROUNDOFF_MARGIN,
    accumulated,
    first_near_max,
    roundoff_floor,
)

TRUNCATION = "integrator truncation error"
PRE_ASYMPTOTIC = "pre-asymptotic step (a fast constraint mode)"
CHARTS_DIFFER = "rotating-body state stepped in different charts"
NAIVE_GROUP_RK4 = "RK4 stages summed across the rotation group's tangent spaces (order 2)"
HELD_FORCE = "state-dependent force held over RK4 stages"
GYROSCOPIC_IMPLICIT = "MuJoCo's implicitfast applies a free body's gyroscopic derivative"


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
            ref = reference_trajectory(self.case, variant, self.t, rtol=1e-13)
            tighter = reference_trajectory(self.case, variant, self.t, rtol=2.5e-14)
            self._cache[variant] = ref, float(np.abs(ref - tighter).max())
        return self._cache[variant]

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
        integrator = "euler" if integrator == "implicitfast" else integrator  # same map, D = 0
        key = (variant, integrator, dt)
        if key not in self._discrete:
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
                self._discrete[key] = (cmap.to_book(qe), qe)
                return self._discrete[key]

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
            layout = Layout.of([j.type for j in self.case.multibody().joints])
            qe, _ = integrate(acc, qe0, ve0, dt, steps, integrator, freeze=freeze, layout=layout)
            _require_chart(cmap, layout, qe)
            self._discrete[key] = (cmap.to_book(qe), qe)
        return self._discrete[key]


def _require_chart(cmap: CoordinateMap, layout: Layout, qe: np.ndarray) -> None:
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


def _energy_drift(
    case: Case,
    impl: Implementation,
    variant: Variant | None,
    dt: float,
    integrator: str,
    q: np.ndarray,
) -> np.ndarray | None:
    """Relative energy error along a run (conservation, (2.2.36)'s T + V = h), evaluated with
    the reference's energy of the implementation's own model."""
    v = getattr(impl, "velocities", lambda *_: None)(dt, integrator)
    if v is None or variant is None:
        return None
    dyn = general_method(case, variant)
    energy = dyn.kinetic_energy(q, v) + dyn.potential_energy(q)
    if hasattr(dyn, "field_potential"):
        energy = energy + dyn.field_potential(q)
    return np.abs(energy - energy[0]) / max(float(np.abs(energy).max()), 1e-300)


def _momentum_drift(
    case: Case, impl: Implementation, dt: float, integrator: str, q: np.ndarray
) -> np.ndarray | None:
    """|H(t) − H(0)| / |H(0)| along a run of a rigid case (its last three coordinates are
    Example 9's angles): H = ℓ Ī ω̄ in space axes, conserved by (2.2.49) with M = 0."""
    v = getattr(impl, "velocities", lambda *_: None)(dt, integrator)
    if v is None or not hasattr(case, "inertia"):
        return None
    angles, rates = q[:, -3:], v[:, -3:]
    euler = EulerAngleMap()
    w = np.einsum("nij,nj->ni", euler.jacobian(angles), rates)
    H = np.einsum("nij,nj->ni", euler._rotation(angles), rigid.angular_momentum(case.inertia(), w))
    return np.linalg.norm(H - H[0], axis=1) / np.linalg.norm(H[0])


def observed_orders(dts: list[float], errors: list[float]) -> list[float]:
    """p between consecutive steps; NaN for the first."""
    out = [float("nan")]
    for i in range(1, len(dts)):
        out.append(float(np.log(errors[i - 1] / errors[i]) / np.log(dts[i - 1] / dts[i])))
    return out


def finest_pair(asymptotic: list[bool]) -> int | None:
    """The index i of the finest pair of consecutive steps (i − 1, i) both in the asymptotic
    range, or None: where an observed order is read."""
    pairs = [i for i in range(1, len(asymptotic)) if asymptotic[i] and asymptotic[i - 1]]
    return pairs[-1] if pairs else None


@dataclass
class TrajectoryFigures:
    """What the report plots: the book model's reference on the grid, and per engine ×
    integrator the finest run's configuration and its error against its own reference."""

    t: np.ndarray
    reference: np.ndarray
    runs: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    errors: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    steps: dict[tuple[str, str], float] = field(default_factory=dict)
    energy: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    momentum: dict[tuple[str, str], np.ndarray] = field(default_factory=dict)
    """|H(t) − H(0)| / |H(0)| of the finest run, H = ℓ Ī ω̄ the angular momentum in space
    axes ((2.2.42), (2.2.50)), for rigid bodies under no moment about the centre of mass."""
    """|E(t) − E(0)| / max|E| of the finest run, E = T + V (+ the field's V) of its own model."""


def study(
    case: Case, impls: dict[str, Implementation | Exception]
) -> tuple[list[ConvergencePoint], list[Discrepancy], TrajectoryFigures]:
    """The order-of-accuracy study, the engine-against-engine trajectory rows, and the data
    for the report's figures."""
    spec = case.trajectory
    refs = References(case)
    figures = TrajectoryFigures(refs.t, refs(book_variant(case))[0])
    points: list[ConvergencePoint] = []
    rows: list[Discrepancy] = []
    runs: dict[tuple[str, str, float], np.ndarray] = {}
    variants: dict[str, Variant | None] = {}
    engines = [n for n in IMPLEMENTATIONS if n in impls and n not in ("book", "reference")]
    rotating = any(j.type in ROTATING for j in case.multibody().joints)
    for name in engines:
        impl = impls[name]
        if isinstance(impl, Exception):
            rows.append(_unavailable(case, name, impl))
            continue
        variant = variants[name] = impl.variant()
        for integrator, dts in spec.steps.items():
            if integrator not in impl.integrators:
                continue
            nominal = NOMINAL_ORDER[integrator]
            convention = HELD_FORCE if integrator == "rk4-held-force" else ""
            group_order = getattr(getattr(impl, "adapter", None), "rk4_group_order", nominal)
            if integrator.startswith("rk4") and rotating and group_order < nominal:
                nominal, convention = group_order, NAIVE_GROUP_RK4
            ref, ref_err = refs(variant or book_variant(case))
            errors, worst = [], []
            limit = getattr(getattr(impl, "adapter", None), "max_steps", None)
            longest = round(spec.duration / min(dts))
            if limit is not None and longest > limit:  # refused before any run starts
                why = Unsupported(
                    f"{name}: the study's longest run has {longest} steps, more than the "
                    f"{limit} this engine makes here ({impl.adapter.device})"  # type: ignore[attr-defined]
                )
                rows.append(_unavailable(case, name, why, integrator, dts[0]))
                continue
            try:
                for dt in dts:
                    _, q = impl.simulate(dt, integrator)
                    runs[name, integrator, dt] = q
                    diff = difference(case, q[:: round(spec.grid_step / dt)], ref).max(axis=1)
                    errors.append(float(diff.max()))
                    band = accumulated(round(spec.duration / dt)).rtol * float(np.abs(ref).max())
                    worst.append(first_near_max(diff, band))
            except Exception as exc:  # a diverging or crashing run is a row, not a crash
                rows.append(_unavailable(case, name, exc, integrator, dt))
                continue
            if case.multibody().couplings:
                rows.append(_drift_row(case, impl, variant, refs, integrator, dts[0]))
            figures.runs[name, integrator] = q[:: round(spec.grid_step / dt)]
            figures.errors[name, integrator] = diff
            figures.steps[name, integrator] = dt
            drift = _energy_drift(case, impl, variant, dt, integrator, q)
            if drift is not None:
                figures.energy[name, integrator] = drift
            h_drift = _momentum_drift(case, impl, dt, integrator, q)
            if h_drift is not None:
                figures.momentum[name, integrator] = h_drift
            orders = observed_orders(list(dts), errors)
            # a step is asymptotic where its error stands clear of the reference's error and
            # of the run's own round-off (roundoff_floor: float32 ports reach it)
            scale = float(np.abs(ref).max())
            floors = [
                ROUNDOFF_MARGIN * roundoff_floor(impl.eps, round(spec.duration / h)) * scale
                for h in dts
            ]
            asym = [
                e > REFERENCE_MARGIN * ref_err and e > f
                for e, f in zip(errors, floors, strict=True)
            ]
            finest = finest_pair(asym)
            # no asymptotic pair because of the run's own precision, not the reference's
            limited = finest is None and any(e <= f for e, f in zip(errors, floors, strict=True))
            degree = getattr(general_method(case, variant), "polynomial_degree", None)
            exact = variant is not None and degree is not None and nominal >= degree > 1
            if exact:
                # q(t) is a polynomial the integrator reproduces: only round-off remains
                tol = accumulated(round(spec.duration / dts[-1]), eps=impl.eps)
                verdict = "passed" if max(errors) <= tol.rtol * scale else "failed"
                convention = ""
                note = (
                    f"q(t) is a polynomial of degree {degree} in t, which {integrator} "
                    f"(order {nominal}) integrates exactly: max error {max(errors):.2g} within "
                    f"{tol.basis} (x scale {scale:.3g})"
                )
            elif variant is None:
                verdict, note = "failed", "model differs from the book in an unpredicted way"
            elif limited:
                # truncation below the precision's round-off: no order to observe; the runs
                # must still agree with the reference within accumulated round-off
                tol = accumulated(round(spec.duration / dts[-1]), eps=impl.eps)
                verdict = "passed" if max(errors) <= tol.rtol * scale else "failed"
                note = (
                    f"errors {min(errors):.2g} to {max(errors):.2g}: fewer than two steps stand "
                    f"clear of {ROUNDOFF_MARGIN:g} x the run's round-off eps sqrt(N) x scale "
                    f"(eps = {impl.eps:.3g}): {integrator}'s order cannot be observed in this "
                    f"precision; max error within {tol.basis} (x scale {scale:.3g})"
                )
            elif finest is None:
                verdict, note = "failed", "no pair of steps in the asymptotic range"
            else:
                p = orders[finest]
                ok = abs(p - nominal) <= ORDER_SLACK
                verdict = "passed" if ok else "failed"
                if convention and ok:
                    verdict = "explained"  # the predicted (reduced) order, a finding
                note = (
                    f"observed order {p:.3f} (nominal {nominal}) at dt={dts[finest]:g}; "
                    f"reference error estimate {ref_err:.1e}"
                )
                if not ok and not convention and integrator in STEPPERS:
                    # is the step still pre-asymptotic? the reference's own equations
                    # stepped by the same integrator show it, or the engine is wrong
                    try:
                        pred = []
                        for h in dts:
                            stepped = refs.discrete(variant, integrator, h)
                            on_grid = stepped[:: round(spec.grid_step / h)]
                            pred.append(float(difference(case, on_grid, ref).max()))
                        p_pred = observed_orders(list(dts), pred)[finest]
                        if abs(p - p_pred) <= ORDER_SLACK:
                            verdict, convention = "explained", PRE_ASYMPTOTIC
                            note += (
                                f"; pre-asymptotic: the same {integrator} on the reference's "
                                f"equations of this model shows order {p_pred:.3f} at this step"
                            )
                    except Exception as exc:  # no discrete prediction: the row stays failed
                        note += f"; no discrete prediction ({type(exc).__name__}: {exc})"
                if variant != book_variant(case):
                    note += f"; against the reference of the same model {describe(variant)}"
            scale_q = float(np.abs(ref).max())
            for dt, err, p, a, w in zip(dts, errors, orders, asym, worst, strict=True):
                points.append(
                    ConvergencePoint(case.name, name, integrator, dt, err, p, nominal, ref_err, a)
                )
                rows.append(
                    Discrepancy(
                        case=case.name,
                        quantity="trajectory",
                        impl_a="reference",
                        impl_b=name,
                        integrator=integrator,
                        dt=dt,
                        max_abs_err=err,
                        max_rel_err=err / scale_q,
                        tolerance=float("nan"),
                        tolerance_basis="exact for a polynomial q(t): accumulated round-off"
                        if exact
                        else "below the precision's round-off: accumulated round-off"
                        if limited
                        else f"order study: observed order within {nominal} ± {ORDER_SLACK}",
                        verdict=verdict,
                        convention=""
                        if exact or limited
                        else (convention or f"{TRUNCATION} (order {nominal})"),
                        note=note,
                        worst_state=w,
                    )
                )
        if getattr(getattr(impl, "adapter", None), "adaptive", False):
            try:
                rows.append(_adaptive(case, impl, variant, refs))
            except Exception as exc:  # unsupported (quaternion state) or crashed: a row
                rows.append(_unavailable(case, name, exc, "dop853"))
        if hasattr(getattr(impl, "adapter", None), "simulate_controlled"):
            try:
                rows += _controlled(case, impl, variant, refs)
            except Exception as exc:  # crashed or diverged: a row, not a crash
                rows.append(_unavailable(case, name, exc, CONTROLLED))
    rows += _engine_pairs(case, engines, runs, variants, refs, impls)
    return points, rows, figures


def _drift_row(
    case: Case,
    impl: Implementation,
    variant: Variant | None,
    refs: References,
    integrator: str,
    dt: float,
) -> Discrepancy:
    """The cords' violation C q̄(t) along the engine's run at ``dt`` against the same
    model's discrete motion (the reference stepped by the same integrator): zero to
    round-off for an exact constraint, the soft model's stretch for a soft one."""
    C = case.multibody().coupling_matrix(positions=True)
    observed = impl.engine_positions(dt, integrator) @ C.T  # type: ignore[attr-defined]
    steps = observed.shape[0] - 1
    tol = accumulated(steps, soft_factor(variant), impl.eps)
    base: dict[str, Any] = dict(
        case=case.name,
        quantity="constraint_drift",
        impl_a="reference",
        impl_b=impl.name,
        integrator=integrator,
        dt=dt,
        tolerance=tol.rtol,
        tolerance_basis=tol.basis + " (relative to the coordinates' scale)",
    )
    if variant is None:
        return Discrepancy(
            **base,
            max_abs_err=float("nan"),
            max_rel_err=float("nan"),
            verdict="failed",
            convention="",
            note="model differs from the book in an unpredicted way",
            worst_state=-1,
        )
    how = f"the same model stepped by {integrator}"
    if integrator in STEPPERS:
        _, qe = refs.discrete_engine(variant, integrator, dt)
        predicted = qe @ C.T
    elif not variant.softness:
        # an engine's own Runge–Kutta scheme on an exact cord: every Runge–Kutta method keeps
        # a linear invariant C q exactly (Hairer, Lubich & Wanner, GNI, Thm. IV.1.5)
        qe = impl.engine_positions(dt, integrator)  # type: ignore[attr-defined]
        predicted = np.broadcast_to(qe[0] @ C.T, observed.shape)
        how = f"{integrator}, a Runge–Kutta method, keeps the linear invariant C q"
    else:
        raise ValueError(f"no discrete model of {integrator} for a soft constraint")
    diff = np.abs(observed - predicted).max(axis=1)
    scale = float(np.abs(qe).max())
    err = float(diff.max())
    return Discrepancy(
        **base,
        max_abs_err=err,
        max_rel_err=err / scale,
        verdict="passed" if err / scale <= tol.rtol else "failed",
        convention=SOFT_CONSTRAINT if variant.softness else "",
        note=f"max abs violation observed {np.abs(observed).max():.3g} m, predicted "
        f"{np.abs(predicted).max():.3g} m ({how})",
        worst_state=first_near_max(diff, tol.rtol * scale),
    )


ADAPTIVE_RTOL = 1e-13


def attainable_rtol(impl: Implementation) -> float:
    """The error-controlled run's tolerance: :data:`ADAPTIVE_RTOL`, or ε κ(M) at the initial
    state where that is larger — below it the local error estimate is round-off of the
    accelerations (relative ε κ(M)), and the step size collapses chasing noise. It binds only
    for the spherical pendulum's quaternion state, whose spin about the rod carries the
    inertia floor alone (κ(M) ≈ 1e8); every other case keeps 1e-13."""
    qe0, _ = impl._engine_start()  # type: ignore[attr-defined]
    mass = impl.adapter.mass_matrix(qe0[None])[0]  # type: ignore[attr-defined]
    return max(ADAPTIVE_RTOL, float(np.finfo(float).eps * np.linalg.cond(mass)))


def _adaptive(
    case: Case, impl: Implementation, variant: Variant | None, refs: References
) -> Discrepancy:
    """The engine's forward dynamics under the reference's own integrator and tolerance (on
    the rotation group in re-centred exponential coordinates): each solution's error is
    estimated alike, e = |x(rtol) − x(rtol/4)|, and |q − q_ref| ≤ e_ref + e_engine if the
    estimates hold; allowed twice that, since an estimate is not a bound."""
    ref, ref_err = refs(variant or book_variant(case))
    rtol = attainable_rtol(impl)
    q = impl.solve(refs.t, rtol)  # type: ignore[attr-defined]
    own_err = float(difference(case, q, impl.solve(refs.t, rtol / 4)).max())  # type: ignore[attr-defined]
    diff = difference(case, q, ref).max(axis=1)
    scale_q = float(np.abs(ref).max())
    err = float(diff.max())
    allowed = 2 * (ref_err + own_err)
    verdict = "passed" if variant is not None and err <= allowed else "failed"
    return Discrepancy(
        case=case.name,
        quantity="trajectory",
        impl_a="reference",
        impl_b=impl.name,
        integrator="dop853",
        dt=float("nan"),
        max_abs_err=err,
        max_rel_err=err / scale_q,
        tolerance=allowed / scale_q,
        tolerance_basis=f"2 x (reference error estimate {ref_err:.1e} + own estimate "
        f"{own_err:.1e}) (DOP853 at rtol {rtol:.2g} against rtol/4)",
        verdict=verdict,
        convention="",
        note="scipy solve_ivp on the engine's forward dynamics, same model"
        + (
            "; quaternions in re-centred exponential coordinates"
            if any(j.type in ROTATING for j in case.multibody().joints)
            else ""
        ),
        worst_state=first_near_max(diff, ref_err + own_err),
    )


CONTROLLED = "rk3-controlled"
CONTROLLED_ACCURACIES = (1e-7, 1e-8, 1e-9, 1e-10)
"""Target accuracies ε of an engine's error-controlled integrator, a decade apart."""


def _controlled(
    case: Case, impl: Implementation, variant: Variant | None, refs: References
) -> list[Discrepancy]:
    """Tolerance proportionality of an engine's error-controlled integrator (Drake's
    ``runge_kutta3``). Its controller sizes each step so that the embedded 2nd-order estimate
    of the local error (∝ h³) meets ε, while it propagates the 3rd-order solution (local error
    ∝ h⁴): h ∝ ε^(1/3), global error ∝ h³ ∝ ε. The observed slope
    ln(E₁/E₂)/ln(ε₁/ε₂) at the finest pair above the reference's error must be 1 ± ORDER_SLACK;
    a polynomial q(t) (the cords) is integrated exactly, to accumulated round-off."""
    ref, ref_err = refs(variant or book_variant(case))
    scale = float(np.abs(ref).max())
    errors, steps, worst = [], [], []
    for eps in CONTROLLED_ACCURACIES:
        q, n = impl.simulate_controlled(eps)  # type: ignore[attr-defined]
        diff = difference(case, q, ref).max(axis=1)
        errors.append(float(diff.max()))
        steps.append(n)
        worst.append(first_near_max(diff, accumulated(n).rtol * scale))
    slopes = observed_orders(list(CONTROLLED_ACCURACIES), errors)
    asym = [e > REFERENCE_MARGIN * ref_err for e in errors]
    finest = finest_pair(asym)
    degree = None
    if variant is not None:
        degree = getattr(general_method(case, variant), "polynomial_degree", None)
    if variant is None:
        verdict, basis = "failed", "model differs from the book in an unpredicted way"
        note = basis
    elif degree is not None and degree <= 3:
        tol = accumulated(max(steps))
        verdict = "passed" if max(errors) <= tol.rtol * scale else "failed"
        basis = "exact for a polynomial q(t): accumulated round-off"
        note = (
            f"q(t) is a polynomial of degree {degree}, which RK3 integrates exactly: max error "
            f"{max(errors):.2g} within {tol.basis} (x scale {scale:.3g})"
        )
    elif finest is None:
        verdict, basis = "failed", "tolerance proportionality"
        note = "no pair of accuracies in the asymptotic range"
    else:
        p = slopes[finest]
        verdict = "passed" if abs(p - 1) <= ORDER_SLACK else "failed"
        basis = f"tolerance proportionality: global error ∝ ε, slope within 1 ± {ORDER_SLACK}"
        note = (
            f"observed slope {p:.3f} (nominal 1) between ε = "
            f"{CONTROLLED_ACCURACIES[finest - 1]:g} and {CONTROLLED_ACCURACIES[finest]:g}"
            f"; reference error estimate {ref_err:.1e}"
        )
    return [
        Discrepancy(
            case=case.name,
            quantity="trajectory",
            impl_a="reference",
            impl_b=impl.name,
            integrator=f"{CONTROLLED} eps={eps:g}",
            dt=float("nan"),
            max_abs_err=err,
            max_rel_err=err / scale,
            tolerance=float("nan"),
            tolerance_basis=basis,
            verdict=verdict,
            convention="",
            note=f"{n} steps; {note}",
            worst_state=w,
        )
        for eps, err, n, w in zip(CONTROLLED_ACCURACIES, errors, steps, worst, strict=True)
    ]


def _no_numbers(
    case: Case, a: str, b: str, integrator: str, dt: float, verdict: str, convention: str, note: str
) -> Discrepancy:
    """A trajectory row with no error to show (skipped, or failed before any number)."""
    nan = float("nan")
    return Discrepancy(
        case.name,
        "trajectory",
        a,
        b,
        integrator,
        dt,
        nan,
        nan,
        nan,
        "",
        verdict,
        convention,
        note,
        -1,
    )


def _unavailable(
    case: Case, name: str, exc: Exception, integrator: str = "", dt: float = float("nan")
) -> Discrepancy:
    """A skipped (engine not installed, model unsupported) or failed (raised, diverged)
    trajectory row against the reference."""
    if isinstance(exc, EngineNotInstalled | Unsupported):
        return _no_numbers(case, "reference", name, integrator, dt, "skipped", "", str(exc))
    return _no_numbers(
        case, "reference", name, integrator, dt, "failed", "", f"{type(exc).__name__}: {exc}"
    )


def _maps_differ(
    case: Case, a: str, b: str, integrator: str, impls: dict[str, Implementation | Exception]
) -> str | None:
    """Why two engines' fixed-step runs are different maps of the same dynamics, or None:
    Drake and sympy-mechanics step a rotating body in their own chart (roll-pitch-yaw or
    Example 9's angles, a free joint's quaternion components) where the others apply the
    exponential map; MuJoCo's ``implicitfast`` adds a free body's gyroscopic derivative (MuJoCo
    ≥ 3.12, changelog f0fa3d82), which semi-implicit Euler does not."""
    types = {j.type for j in case.multibody().joints}
    if not types & set(ROTATING):
        return None
    if any(is_chart(e) for e in (a, b)) and a != b:
        return CHARTS_DIFFER
    if integrator.startswith("rk4") and len({_group_order(impls[e]) for e in (a, b)}) == 2:
        return NAIVE_GROUP_RK4
    if integrator == "implicitfast" and "free" in types:
        facts = {
            getattr(getattr(impls[e], "adapter", None), "gyroscopic_implicit", False)
            for e in (a, b)
        }
        if len(facts) == 2:
            return GYROSCOPIC_IMPLICIT
    return None


def _group_order(impl: Implementation | Exception) -> int:
    """RK4's order on the rotation group as the engine defines it (4 unless it says less)."""
    return int(getattr(getattr(impl, "adapter", None), "rk4_group_order", NOMINAL_ORDER["rk4"]))


def _frame_pair(
    case: Case,
    a: str,
    b: str,
    integrator: str,
    dts: tuple[float, ...],
    runs: dict[tuple[str, str, float], np.ndarray],
    convention: str,
    nominal: int | None = None,
    eps: float = EPS,
) -> Discrepancy:
    """Two different fixed-step maps of the same dynamics (:func:`_maps_differ`): both
    converge at the integrator's order p, so their difference must shrink at least at order p
    (faster where the maps agree to higher order). Predicted: the difference's observed order
    between the two coarsest steps. ``nominal``: the lower of the two maps' orders (default:
    the integrator's)."""
    nominal = nominal or NOMINAL_ORDER[integrator]
    if len(dts) < 2 or any((e, integrator, dt) not in runs for e in (a, b) for dt in dts[:2]):
        why = "the two maps differ in definition and fewer than two steps ran"
        return _no_numbers(case, a, b, integrator, dts[0], "failed", convention, why)
    d = []
    for dt in dts[:2]:
        qa, qb = runs[a, integrator, dt], runs[b, integrator, dt]
        d.append(float(difference(case, qb, qa).max()))
    scale_q = float(np.abs(runs[a, integrator, dts[0]]).max())
    if eps > EPS:
        steps = round(case.trajectory.duration / dts[1])
        if d[1] <= ROUNDOFF_MARGIN * roundoff_floor(eps, steps) * scale_q:
            # the finer difference is round-off: no order to measure in this precision; the
            # difference must then lie within the pair's accumulated round-off
            tol = accumulated(round(case.trajectory.duration / dts[0]), eps=eps)
            return Discrepancy(
                case=case.name,
                quantity="trajectory",
                impl_a=a,
                impl_b=b,
                integrator=integrator,
                dt=dts[0],
                max_abs_err=d[0],
                max_rel_err=d[0] / scale_q,
                tolerance=tol.rtol,
                tolerance_basis=tol.basis,
                verdict="passed" if d[0] / scale_q <= tol.rtol else "failed",
                convention="",
                note=f"{a} and {b} are different maps ({convention}); at dt={dts[1]:g} their "
                f"difference is within the round-off of eps = {eps:.3g}, so its order cannot "
                f"be measured; at dt={dts[0]:g} it lies within the accumulated round-off",
                worst_state=-1,
            )
    p = float(np.log(d[0] / d[1]) / np.log(dts[0] / dts[1]))
    ok = p >= nominal - ORDER_SLACK  # two order-p maps differ by O(hᵖ) or less
    return Discrepancy(
        case.name,
        "trajectory",
        a,
        b,
        integrator,
        dts[0],
        d[0],
        d[0] / scale_q,
        float("nan"),
        f"difference of two order-{nominal} maps: shrinks at order >= {nominal} - {ORDER_SLACK}",
        "explained" if ok else "failed",
        convention,
        f"{a} and {b} are different maps ({convention}); their difference shrinks at order "
        f"{p:.3f} from dt={dts[0]:g} to {dts[1]:g} "
        f"(predicted {nominal})",
        -1,
    )


def _eps(impl: Implementation | Exception) -> float:
    return impl.eps if isinstance(impl, Implementation) else EPS


def _engine_pairs(
    case: Case,
    engines: list[str],
    runs: dict[tuple[str, str, float], np.ndarray],
    variants: dict[str, Variant | None],
    refs: References,
    impls_: dict[str, Implementation | Exception],
) -> list[Discrepancy]:
    """Same integrator, same (coarsest) step, two engines: equal to accumulated round-off, or
    differing by the predicted effect of their model variants on the trajectory."""
    rows = []
    spec = case.trajectory
    for a, b in ((a, b) for a, b in combinations(engines, 2) if compared(a, b)):
        for integrator, dts in spec.steps.items():
            for dt in dts[:1]:  # the coarsest step: agreement there needs no finer repeat
                if (a, integrator, dt) not in runs or (b, integrator, dt) not in runs:
                    continue
                differ = _maps_differ(case, a, b, integrator, impls_)
                if differ is not None:
                    order = min(_group_order(impls_[a]), _group_order(impls_[b]))
                    nominal = order if differ == NAIVE_GROUP_RK4 else None
                    eps = max(_eps(impls_[a]), _eps(impls_[b]))
                    rows.append(
                        _frame_pair(case, a, b, integrator, dts, runs, differ, nominal, eps)
                    )
                    continue
                qa, qb = runs[a, integrator, dt], runs[b, integrator, dt]
                steps = qa.shape[0] - 1
                soft = max(soft_factor(variants[a]), soft_factor(variants[b]))
                tol = accumulated(steps, soft, max(_eps(impls_[a]), _eps(impls_[b])))
                scale_q = float(np.abs(qa).max())
                diff = difference(case, qb, qa).max(axis=1)
                # ties at float64 round-off go to the first state (machine-independent)
                worst = first_near_max(diff, accumulated(steps, soft).rtol * scale_q)
                err = float(diff[worst])
                row: dict[str, Any] = dict(
                    case=case.name,
                    quantity="trajectory",
                    impl_a=a,
                    impl_b=b,
                    integrator=integrator,
                    dt=dt,
                    max_abs_err=err,
                    max_rel_err=err / scale_q,
                    tolerance=tol.rtol,
                    tolerance_basis=tol.basis,
                    worst_state=worst,
                )
                va, vb = variants[a], variants[b]
                if err / scale_q <= tol.rtol:
                    rows.append(Discrepancy(**row, verdict="passed", convention="", note=""))
                elif va is not None and vb is not None and va != vb:
                    try:
                        predicted = refs.discrete(vb, integrator, dt) - refs.discrete(
                            va, integrator, dt
                        )
                    except Exception as exc:  # no discrete prediction here: a failed row
                        rows.append(
                            Discrepancy(
                                **row,
                                verdict="failed",
                                convention="; ".join(va.conventions(vb)),
                                note=f"no prediction: {type(exc).__name__}: {exc}",
                            )
                        )
                        continue
                    res_rel = float(difference(case, qb - qa, predicted).max()) / scale_q
                    note = (
                        f"predicted by the reference equations of both models, stepped by "
                        f"{integrator}: max {np.abs(predicted).max():.3g} rad; residual "
                        f"{res_rel:.3g}"
                    )
                    verdict = "explained" if res_rel <= tol.rtol else "failed"
                    rows.append(
                        Discrepancy(
                            **row,
                            verdict=verdict,
                            convention="; ".join(va.conventions(vb)),
                            note=note,
                        )
                    )
                else:
                    rows.append(
                        Discrepancy(
                            **row,
                            verdict="failed",
                            convention="",
                            note="unexplained: no convention predicts this",
                        )
                    )
    return rows
