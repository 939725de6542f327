"""Error-controlled integration: the engine's forward dynamics under the reference's own
DOP853, and the tolerance proportionality of an engine's own error-controlled integrator."""

from __future__ import annotations

import numpy as np

from dyncheck.cases.base import Case
from dyncheck.implementations import EngineImplementation, Implementation, general_method
from dyncheck.results import Discrepancy, Verdict
from dyncheck.studies.order import (
    CONTROLLED,
    CONTROLLED_ACCURACIES,
    finest_pair,
    observed_orders,
)
from dyncheck.studies.references import References, difference
from dyncheck.tolerances import ORDER_SLACK, REFERENCE_MARGIN, accumulated, first_near_max
from dyncheck.variants import Variant, book_variant
from dyncheck.vocabulary import ROTATING, Quantity

ADAPTIVE_RTOL = 1e-13


def attainable_rtol(impl: Implementation) -> float:
    """The error-controlled run's tolerance: :data:`ADAPTIVE_RTOL`, or ε κ(M) at the initial
    state where that is larger — below it the local error estimate is round-off of the
    accelerations (relative ε κ(M)), and the step size collapses chasing noise. It binds only
    for the spherical pendulum's quaternion state, whose spin about the rod carries the
    inertia floor alone (κ(M) ≈ 1e8); every other case keeps 1e-13."""
    assert isinstance(impl, EngineImplementation), impl.name  # an engine's error control
    qe0, _ = impl.engine_start()
    mass = impl.adapter.mass_matrix(qe0[None])[0]
    return max(ADAPTIVE_RTOL, float(np.finfo(float).eps * np.linalg.cond(mass)))


def adaptive(
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
    verdict = Verdict.PASSED if variant is not None and err <= allowed else Verdict.FAILED
    return Discrepancy.measured(
        case=case.name,
        quantity=Quantity.TRAJECTORY,
        impl_a="reference",
        impl_b=impl.name,
        integrator="dop853",
        error=err,
        scale=scale_q,
        tolerance=allowed / scale_q,
        basis=f"2 x (reference error estimate {ref_err:.1e} + own estimate "
        f"{own_err:.1e}) (DOP853 at rtol {rtol:.2g} against rtol/4)",
        verdict=verdict,
        note="scipy solve_ivp on the engine's forward dynamics, same model"
        + (
            "; quaternions in re-centred exponential coordinates"
            if any(j.type in ROTATING for j in case.multibody().joints)
            else ""
        ),
        worst_state=first_near_max(diff, ref_err + own_err),
    )




def controlled(
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
        verdict, basis = Verdict.FAILED, "model differs from the book in an unpredicted way"
        note = basis
    elif degree is not None and degree <= 3:
        tol = accumulated(max(steps))
        verdict = Verdict.PASSED if max(errors) <= tol.rtol * scale else Verdict.FAILED
        basis = "exact for a polynomial q(t): accumulated round-off"
        note = (
            f"q(t) is a polynomial of degree {degree}, which RK3 integrates exactly: max error "
            f"{max(errors):.2g} within {tol.basis} (x scale {scale:.3g})"
        )
    elif finest is None:
        verdict, basis = Verdict.FAILED, "tolerance proportionality"
        note = "no pair of accuracies in the asymptotic range"
    else:
        p = slopes[finest]
        verdict = Verdict.PASSED if abs(p - 1) <= ORDER_SLACK else Verdict.FAILED
        basis = f"tolerance proportionality: global error ∝ ε, slope within 1 ± {ORDER_SLACK}"
        note = (
            f"observed slope {p:.3f} (nominal 1) between ε = "
            f"{CONTROLLED_ACCURACIES[finest - 1]:g} and {CONTROLLED_ACCURACIES[finest]:g}"
            f"; reference error estimate {ref_err:.1e}"
        )
    return [
        Discrepancy.measured(
            case=case.name,
            quantity=Quantity.TRAJECTORY,
            impl_a="reference",
            impl_b=impl.name,
            integrator=f"{CONTROLLED} eps={eps:g}",
            error=err,
            scale=scale,
            tolerance=float("nan"),
            basis=basis,
            verdict=verdict,
            note=f"{n} steps; {note}",
            worst_state=w,
        )
        for eps, err, n, w in zip(CONTROLLED_ACCURACIES, errors, steps, worst, strict=True)
    ]
