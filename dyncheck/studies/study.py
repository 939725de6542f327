"""One case's trajectory study: every engine × integrator's order of accuracy against the
reference of its own model, its conserved quantities, and the engine-against-engine rows."""

from __future__ import annotations

import numpy as np

from dyncheck.adapters.integrators import STEPPERS
from dyncheck.cases import NOMINAL_ORDER, Case
from dyncheck.cases.multibody import ROTATING
from dyncheck.comparison import describe
from dyncheck.errors import Unsupported
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    EngineImplementation,
    Implementation,
    Variant,
    book_variant,
    general_method,
)
from dyncheck.results import ConvergencePoint, Discrepancy, Verdict
from dyncheck.studies.controlled import CONTROLLED, adaptive, controlled
from dyncheck.studies.drift import drift_row, energy_drift, momentum_drift
from dyncheck.studies.labels import HELD_FORCE, NAIVE_GROUP_RK4, PRE_ASYMPTOTIC, TRUNCATION
from dyncheck.studies.order import TrajectoryFigures, finest_pair, observed_orders
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
                rows.append(unavailable(case, name, why, integrator, dts[0]))
                continue
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
            except Exception as exc:  # a diverging or crashing run is a row, not a crash
                rows.append(unavailable(case, name, exc, integrator, dt))
                continue
            if case.multibody().couplings:
                rows.append(drift_row(case, impl, variant, refs, integrator, dts[0]))
            figures.runs[name, integrator] = q[:: round(spec.grid_step / dt)]
            figures.errors[name, integrator] = diff
            figures.steps[name, integrator] = dt
            drift = energy_drift(case, impl, variant, dt, integrator, q)
            if drift is not None:
                figures.energy[name, integrator] = drift
            h_drift = momentum_drift(case, impl, dt, integrator, q)
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
                verdict = Verdict.PASSED if max(errors) <= tol.rtol * scale else Verdict.FAILED
                convention = ""
                note = (
                    f"q(t) is a polynomial of degree {degree} in t, which {integrator} "
                    f"(order {nominal}) integrates exactly: max error {max(errors):.2g} within "
                    f"{tol.basis} (x scale {scale:.3g})"
                )
            elif variant is None:
                verdict, note = Verdict.FAILED, "model differs from the book in an unpredicted way"
            elif limited:
                # truncation below the precision's round-off: no order to observe; the runs
                # must still agree with the reference within accumulated round-off
                tol = accumulated(round(spec.duration / dts[-1]), eps=impl.eps)
                verdict = Verdict.PASSED if max(errors) <= tol.rtol * scale else Verdict.FAILED
                note = (
                    f"errors {min(errors):.2g} to {max(errors):.2g}: fewer than two steps stand "
                    f"clear of {ROUNDOFF_MARGIN:g} x the run's round-off eps sqrt(N) x scale "
                    f"(eps = {impl.eps:.3g}): {integrator}'s order cannot be observed in this "
                    f"precision; max error within {tol.basis} (x scale {scale:.3g})"
                )
            elif finest is None:
                verdict, note = Verdict.FAILED, "no pair of steps in the asymptotic range"
            else:
                p = orders[finest]
                ok = abs(p - nominal) <= ORDER_SLACK
                verdict = Verdict.PASSED if ok else Verdict.FAILED
                if convention and ok:
                    verdict = Verdict.EXPLAINED  # the predicted (reduced) order, a finding
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
                            verdict, convention = Verdict.EXPLAINED, PRE_ASYMPTOTIC
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
                    ConvergencePoint(
                        case=case.name,
                        impl=name,
                        integrator=integrator,
                        dt=dt,
                        error=err,
                        observed_order=p,
                        nominal_order=nominal,
                        reference_error=ref_err,
                        asymptotic=a,
                    )
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
                rows.append(adaptive(case, impl, variant, refs))
            except Exception as exc:  # unsupported (quaternion state) or crashed: a row
                rows.append(unavailable(case, name, exc, "dop853"))
        if hasattr(getattr(impl, "adapter", None), "simulate_controlled"):
            try:
                rows += controlled(case, impl, variant, refs)
            except Exception as exc:  # crashed or diverged: a row, not a crash
                rows.append(unavailable(case, name, exc, CONTROLLED))
    rows += engine_pairs(case, engines, runs, variants, refs, impls)
    return points, rows, figures
