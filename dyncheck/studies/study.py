"""One case's trajectory study: every engine × integrator's order of accuracy against the
reference of its own model, its conserved quantities, and the engine-against-engine rows.

:func:`study` walks the engines and integrators; each step has a name of its own: the order
the run should show (:func:`_expected`), the runs at every step size (:func:`_sweep`), the
data for the figures (:func:`_record`), which steps are in the asymptotic range
(:func:`_asymptotic`), the verdict (:func:`_judge`, with :func:`_pre_asymptotic` for an
order off its nominal one) and the rows (:func:`_rows`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.integrators import STEPPERS
from dyncheck.cases.base import NOMINAL_ORDER, Case
from dyncheck.comparison import describe
from dyncheck.errors import Unsupported
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    EngineImplementation,
    Implementation,
    general_method,
)
from dyncheck.labels import HELD_FORCE, NAIVE_GROUP_RK4, PRE_ASYMPTOTIC, TRUNCATION
from dyncheck.results import ConvergencePoint, Discrepancy, Verdict
from dyncheck.studies.controlled import adaptive, controlled
from dyncheck.studies.drift import drift_row, energy_drift, momentum_drift
from dyncheck.studies.order import CONTROLLED, TrajectoryFigures, finest_pair, observed_orders
from dyncheck.studies.pairs import engine_pairs, unavailable
from dyncheck.studies.references import References, difference
from dyncheck.tolerances import (
    ORDER_SLACK,
    REFERENCE_MARGIN,
    ROUNDOFF_MARGIN,
    accumulated,
    first_near_max,
    roundoff_floor,
)
from dyncheck.variants import Variant, book_variant
from dyncheck.vocabulary import ROTATING, Integrator, Quantity, is_rk4


@dataclass(frozen=True, kw_only=True)
class Sweep:
    """One engine × integrator run at every step size of the study: the max configuration
    error against the reference at each, where along the run it peaked, and the finest run
    (its configuration on the grid and its error in time, for the figures)."""

    errors: list[float]
    worst: list[int]
    q: np.ndarray
    diff: np.ndarray
    dt: float


@dataclass(frozen=True, kw_only=True)
class Judgement:
    """A run's verdict and what its rows say: the convention that explains it, the note,
    the tolerance basis, and whether q(t) was exact or below the precision's round-off."""

    verdict: Verdict
    convention: str
    note: str
    exact: bool
    limited: bool


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
            rows.append(unavailable(case, name, impl))
            continue
        variant = variants[name] = impl.computed_variant()
        for integrator, dts in spec.steps.items():
            if integrator not in impl.integrators:
                continue
            nominal, convention = _expected(impl, integrator, rotating)
            ref, ref_err = refs(variant or book_variant(case))
            engine = impl.adapter
            limit = engine.max_steps if engine is not None else None
            longest = round(spec.duration / min(dts))
            if engine is not None and limit is not None and longest > limit:  # refused first
                why = Unsupported(
                    f"{name}: the study's longest run has {longest} steps, more than the "
                    f"{limit} this engine makes here ({engine.device})"
                )
                rows.append(unavailable(case, name, why, integrator, dts[0]))
                continue
            try:
                sweep = _sweep(case, impl, name, integrator, dts, ref, runs)
            except _RunFailed as failed:  # a diverging or crashing run is a row, not a crash
                rows.append(unavailable(case, name, failed.error, integrator, failed.dt))
                continue
            if case.multibody().couplings:
                rows.append(drift_row(case, impl, variant, refs, integrator, dts[0]))
            _record(figures, case, impl, variant, name, integrator, sweep)
            orders = observed_orders(list(dts), sweep.errors)
            asym, limited = _asymptotic(case, impl, dts, sweep.errors, ref, ref_err)
            judged = _judge(case, impl, variant, refs, integrator, dts, sweep.errors, orders,
                            asym, limited, nominal, convention, ref, ref_err)
            points_, rows_ = _rows(case, name, integrator, dts, sweep, orders, asym, nominal,
                                   ref, ref_err, judged)
            points += points_
            rows += rows_
        if impl.adapter is not None and impl.adapter.adaptive:
            try:
                rows.append(adaptive(case, impl, variant, refs))
            except Exception as exc:  # unsupported (quaternion state) or crashed: a row
                rows.append(unavailable(case, name, exc, "dop853"))
        if impl.adapter is not None and impl.adapter.error_controlled:
            try:
                rows += controlled(case, impl, variant, refs)
            except Exception as exc:  # crashed or diverged: a row, not a crash
                rows.append(unavailable(case, name, exc, CONTROLLED))
    rows += engine_pairs(case, engines, runs, variants, refs, impls)
    return points, rows, figures


def _expected(impl: Implementation, integrator: str, rotating: bool) -> tuple[int, str]:
    """The order the run should show and the convention that sets it where it is not the
    integrator's nominal one: a force held over RK4's stages (order 1), RK4's stages summed
    across tangent spaces on a rotating joint (the engine's declared order)."""
    nominal = NOMINAL_ORDER[integrator]
    convention = HELD_FORCE if integrator == Integrator.RK4_HELD_FORCE else ""
    group_order = impl.adapter.rk4_group_order if impl.adapter is not None else nominal
    if is_rk4(integrator) and rotating and group_order < nominal:
        nominal, convention = group_order, NAIVE_GROUP_RK4
    return nominal, convention


class _RunFailed(Exception):
    """A run of the sweep raised (diverged or crashed) at step ``dt``."""

    def __init__(self, error: Exception, dt: float) -> None:
        super().__init__(str(error))
        self.error, self.dt = error, dt


def _sweep(case: Case, impl: Implementation, name: str, integrator: str,
           dts: tuple[float, ...], ref: np.ndarray,
           runs: dict[tuple[str, str, float], np.ndarray]) -> Sweep:
    """Every step size's run against the reference (each run also kept in ``runs`` for the
    engine-against-engine rows)."""
    spec = case.trajectory
    errors: list[float] = []
    worst: list[int] = []
    dt = dts[0]
    try:
        if isinstance(impl, EngineImplementation):
            impl.simulate_all(dts, integrator)  # at once where the engine batches them
        for dt in dts:
            _, q = impl.simulate(dt, integrator)
            runs[name, integrator, dt] = q
            diff = difference(case, q[:: round(spec.grid_step / dt)], ref).max(axis=1)
            errors.append(float(diff.max()))
            band = accumulated(round(spec.duration / dt)).rtol * float(np.abs(ref).max())
            worst.append(first_near_max(diff, band))
    except Exception as exc:
        raise _RunFailed(exc, dt) from None
    return Sweep(errors=errors, worst=worst, q=q, diff=diff, dt=dt)


def _record(figures: TrajectoryFigures, case: Case, impl: Implementation,
            variant: Variant | None, name: str, integrator: str, sweep: Sweep) -> None:
    """The finest run's configuration, error, energy and momentum drift for the figures."""
    key = (name, integrator)
    figures.runs[key] = sweep.q[:: round(case.trajectory.grid_step / sweep.dt)]
    figures.errors[key] = sweep.diff
    figures.steps[key] = sweep.dt
    drift = energy_drift(case, impl, variant, sweep.dt, integrator, sweep.q)
    if drift is not None:
        figures.energy[key] = drift
    h_drift = momentum_drift(case, impl, sweep.dt, integrator, sweep.q)
    if h_drift is not None:
        figures.momentum[key] = h_drift


def _asymptotic(case: Case, impl: Implementation, dts: tuple[float, ...],
                errors: list[float], ref: np.ndarray,
                ref_err: float) -> tuple[list[bool], bool]:
    """Which steps are in the asymptotic range — their error stands clear of the
    reference's error and of the run's own round-off (:func:`roundoff_floor`: float32 ports
    reach it) — and whether no pair is because of the run's own precision."""
    duration = case.trajectory.duration
    scale = float(np.abs(ref).max())
    floors = [ROUNDOFF_MARGIN * roundoff_floor(impl.eps, round(duration / h)) * scale
              for h in dts]
    asym = [e > REFERENCE_MARGIN * ref_err and e > f
            for e, f in zip(errors, floors, strict=True)]
    limited = finest_pair(asym) is None and any(
        e <= f for e, f in zip(errors, floors, strict=True))
    return asym, limited


def _judge(case: Case, impl: Implementation, variant: Variant | None, refs: References,
           integrator: str, dts: tuple[float, ...], errors: list[float], orders: list[float],
           asym: list[bool], limited: bool, nominal: int, convention: str, ref: np.ndarray,
           ref_err: float) -> Judgement:
    """The run's verdict: exact where q(t) is a polynomial the integrator reproduces, within
    accumulated round-off where the precision hides the order, else the observed order at
    the finest asymptotic pair against the nominal (or the convention's) order."""
    spec = case.trajectory
    scale = float(np.abs(ref).max())
    finest = finest_pair(asym)
    degree = getattr(general_method(case, variant), "polynomial_degree", None)
    exact = variant is not None and degree is not None and nominal >= degree > 1
    # the bound where no order can be judged: the finest run's accumulated round-off
    tol = accumulated(round(spec.duration / dts[-1]), eps=impl.eps)
    within = Verdict.PASSED if max(errors) <= tol.rtol * scale else Verdict.FAILED
    if exact:
        # q(t) is a polynomial the integrator reproduces: only round-off remains
        note = (
            f"q(t) is a polynomial of degree {degree} in t, which {integrator} "
            f"(order {nominal}) integrates exactly: max error {max(errors):.2g} within "
            f"{tol.basis} (x scale {scale:.3g})"
        )
        return Judgement(verdict=within, convention="", note=note, exact=True, limited=limited)
    if variant is None:
        return Judgement(verdict=Verdict.FAILED, convention=convention,
                         note="model differs from the book in an unpredicted way",
                         exact=False, limited=limited)
    if limited:
        # truncation below the precision's round-off: no order to observe; the runs must
        # still agree with the reference within accumulated round-off
        note = (
            f"errors {min(errors):.2g} to {max(errors):.2g}: fewer than two steps stand "
            f"clear of {ROUNDOFF_MARGIN:g} x the run's round-off eps sqrt(N) x scale "
            f"(eps = {impl.eps:.3g}): {integrator}'s order cannot be observed in this "
            f"precision; max error within {tol.basis} (x scale {scale:.3g})"
        )
        return Judgement(verdict=within, convention=convention, note=note, exact=False,
                         limited=True)
    if finest is None:
        return Judgement(verdict=Verdict.FAILED, convention=convention,
                         note="no pair of steps in the asymptotic range", exact=False,
                         limited=False)
    p = orders[finest]
    ok = abs(p - nominal) <= ORDER_SLACK
    verdict = Verdict.PASSED if ok else Verdict.FAILED
    if convention and ok:
        verdict = Verdict.EXPLAINED  # the predicted (reduced) order, a finding
    note = (f"observed order {p:.3f} (nominal {nominal}) at dt={dts[finest]:g}; "
            f"reference error estimate {ref_err:.1e}")
    if not ok and not convention and integrator in STEPPERS:
        verdict, convention, note = _pre_asymptotic(case, variant, refs, integrator, dts, ref,
                                                    finest, p, verdict, note)
    if variant != book_variant(case):
        note += f"; against the reference of the same model {describe(variant)}"
    return Judgement(verdict=verdict, convention=convention, note=note, exact=False,
                     limited=False)


def _pre_asymptotic(case: Case, variant: Variant, refs: References, integrator: str,
                    dts: tuple[float, ...], ref: np.ndarray, finest: int, p: float,
                    verdict: Verdict, note: str) -> tuple[Verdict, str, str]:
    """An order off its nominal one: is the step still pre-asymptotic? The reference's own
    equations stepped by the same integrator show it (explained), or the engine is wrong
    (the row stays failed)."""
    spec = case.trajectory
    convention = ""
    try:
        pred = []
        for h in dts:
            stepped = refs.discrete(variant, integrator, h)
            on_grid = stepped[:: round(spec.grid_step / h)]
            pred.append(float(difference(case, on_grid, ref).max()))
        p_pred = observed_orders(list(dts), pred)[finest]
        if abs(p - p_pred) <= ORDER_SLACK:
            verdict, convention = Verdict.EXPLAINED, PRE_ASYMPTOTIC
            note += (
                f"; pre-asymptotic: the same {integrator} on the reference's "
                f"equations of this model shows order {p_pred:.3f} at this step"
            )
    except Exception as exc:  # no discrete prediction: the row stays failed
        note += f"; no discrete prediction ({type(exc).__name__}: {exc})"
    return verdict, convention, note


def _rows(case: Case, name: str, integrator: str, dts: tuple[float, ...], sweep: Sweep,
          orders: list[float], asym: list[bool], nominal: int, ref: np.ndarray,
          ref_err: float, judged: Judgement) -> tuple[list[ConvergencePoint], list[Discrepancy]]:
    """One convergence point and one trajectory row per step size."""
    scale_q = float(np.abs(ref).max())
    if judged.exact:
        basis, convention = "exact for a polynomial q(t): accumulated round-off", ""
    elif judged.limited:
        basis, convention = "below the precision's round-off: accumulated round-off", ""
    else:
        basis = f"order study: observed order within {nominal} ± {ORDER_SLACK}"
        convention = judged.convention or f"{TRUNCATION} (order {nominal})"
    points, rows = [], []
    for dt, err, p, a, w in zip(dts, sweep.errors, orders, asym, sweep.worst, strict=True):
        points.append(ConvergencePoint(
            case=case.name, impl=name, integrator=integrator, dt=dt, error=err,
            observed_order=p, nominal_order=nominal, reference_error=ref_err, asymptotic=a))
        rows.append(Discrepancy.measured(
            case=case.name, quantity=Quantity.TRAJECTORY, impl_a="reference", impl_b=name,
            integrator=integrator, dt=dt, error=err, scale=scale_q, tolerance=float("nan"),
            basis=basis, verdict=judged.verdict, convention=convention, note=judged.note,
            worst_state=w))
    return points, rows
