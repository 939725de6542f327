"""Engine against engine: the same integrator and step on two engines — equal to accumulated
round-off, differing by the predicted effect of their model variants, or two different maps
of the same dynamics whose difference shrinks at the integrator's order."""

from __future__ import annotations

from collections.abc import Callable
from itertools import combinations
from typing import Any

import numpy as np

from dyncheck.adapters.installed import get_engine
from dyncheck.case_engine import CaseEngine
from dyncheck.cases.base import NOMINAL_ORDER, Case
from dyncheck.comparison import soft_factor
from dyncheck.errors import DyncheckError, EngineNotInstalled, Unsupported
from dyncheck.implementations import Implementation, compared
from dyncheck.labels import CHARTS_DIFFER, GYROSCOPIC_IMPLICIT, NAIVE_GROUP_RK4
from dyncheck.results import Discrepancy, Verdict
from dyncheck.studies.references import References, difference
from dyncheck.tolerances import (
    EPS,
    ORDER_SLACK,
    ROUNDOFF_MARGIN,
    accumulated,
    first_near_max,
    roundoff_floor,
)
from dyncheck.variants import Variant
from dyncheck.vocabulary import ROTATING, Integrator, Quantity, is_rk4


def _charted(name: str) -> bool:
    """Whether an implementation steps a rotating joint in coordinates of its own (a chart:
    angles, a quaternion's components), not along the rotation group."""
    try:
        return get_engine(name).steps_in_a_chart
    except DyncheckError:  # the reference, the book, an engine that is not installed
        return False


def _no_numbers(
    case: Case, a: str, b: str, integrator: str, dt: float, verdict: str, convention: str, note: str
) -> Discrepancy:
    """A trajectory row with no error to show (skipped, or failed before any number)."""
    return Discrepancy.unmeasured(case=case.name, quantity=Quantity.TRAJECTORY, impl_a=a,
                                  impl_b=b, integrator=integrator, dt=dt, verdict=verdict,
                                  convention=convention, note=note)


def unavailable(
    case: Case, name: str, exc: Exception, integrator: str = "", dt: float = float("nan")
) -> Discrepancy:
    """A skipped (engine not installed, model unsupported) or failed (raised, diverged)
    trajectory row against the reference."""
    if isinstance(exc, EngineNotInstalled | Unsupported):
        return _no_numbers(case, "reference", name, integrator, dt, Verdict.SKIPPED, "", str(exc))
    return _no_numbers(
        case, "reference", name, integrator, dt, Verdict.FAILED, "", f"{type(exc).__name__}: {exc}"
    )


def _maps_differ(
    case: Case, a: str, b: str, integrator: str, impls: dict[str, Implementation | Exception]
) -> str | None:
    """Why two engines' fixed-step runs are different maps of the same dynamics, or None:
    Drake and sympy-mechanics step a rotating body in their own chart (roll-pitch-yaw or
    Example 9's angles, a free joint's quaternion components) where the others apply the
    exponential map; MuJoCo's ``implicitfast`` adds a free body's gyroscopic derivative (MuJoCo
    ≥ 3.11.0, changelog f0fa3d82), which semi-implicit Euler does not."""
    types = {j.type for j in case.multibody().joints}
    if not types & set(ROTATING):
        return None
    if any(_charted(e) for e in (a, b)) and a != b:
        return CHARTS_DIFFER
    if is_rk4(integrator) and len({_group_order(impls[e]) for e in (a, b)}) == 2:
        return NAIVE_GROUP_RK4
    if integrator == Integrator.IMPLICITFAST and "free" in types:
        engines = [_adapter(impls[e]) for e in (a, b)]
        facts = {x is not None and x.gyroscopic_implicit for x in engines}
        if len(facts) == 2:
            return GYROSCOPIC_IMPLICIT
    return None


def _adapter(impl: Implementation | Exception) -> CaseEngine | None:
    """The engine behind an implementation (None: the book's side, or one that failed)."""
    return impl.adapter if isinstance(impl, Implementation) else None


def _group_order(impl: Implementation | Exception) -> int:
    """RK4's order on the rotation group as the engine defines it (4 unless it says less)."""
    adapter = _adapter(impl)
    return adapter.rk4_group_order if adapter is not None else NOMINAL_ORDER[Integrator.RK4]


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
    model: Callable[[float], np.ndarray] | None = None,
) -> Discrepancy:
    """Two different fixed-step maps of the same dynamics (:func:`_maps_differ`): both
    converge at the integrator's order p, so their difference must shrink at least at order p
    (faster where the maps agree to higher order). Predicted: the difference's observed order
    between the two coarsest steps. ``nominal``: the lower of the two maps' orders (default:
    the integrator's). ``model``: where the two models differ too (their variants), the
    reference's prediction of that at a step size, taken off first. With a float32 side the
    order is a measurement only where the finer difference stands clear of the round-off
    that side can accumulate (ε N of the state's scale: a float32 engine's drift is
    systematic, not a random walk); else the difference must lie within it."""
    nominal = nominal or NOMINAL_ORDER[integrator]
    if len(dts) < 2 or any((e, integrator, dt) not in runs for e in (a, b) for dt in dts[:2]):
        why = "the two maps differ in definition and fewer than two steps ran"
        return _no_numbers(case, a, b, integrator, dts[0], Verdict.FAILED, convention, why)
    try:
        shifts = [None if model is None else model(dt) for dt in dts[:2]]
    except ValueError:  # no discrete prediction in the book's chart here: the maps alone
        shifts, model = [None, None], None
    d = []
    for dt, shift in zip(dts[:2], shifts, strict=True):
        qa, qb = runs[a, integrator, dt], runs[b, integrator, dt]
        d.append(float((difference(case, qb, qa) if shift is None else
                        difference(case, qb - qa, shift)).max()))
    scale_q = float(np.abs(runs[a, integrator, dts[0]]).max())
    if eps > EPS:
        steps = round(case.trajectory.duration / dts[1])
        drift = max(ROUNDOFF_MARGIN * roundoff_floor(eps, steps),
                    accumulated(steps, eps=eps).rtol)
        if d[1] <= drift * scale_q:
            # the finer difference is round-off: no order to measure in this precision; the
            # difference must then lie within the pair's accumulated round-off
            tol = accumulated(round(case.trajectory.duration / dts[0]), eps=eps)
            return Discrepancy.measured(
                case=case.name, quantity=Quantity.TRAJECTORY, impl_a=a, impl_b=b,
                integrator=integrator, dt=dts[0], error=d[0], scale=scale_q,
                tolerance=tol.rtol, basis=tol.basis,
                verdict=Verdict.PASSED if d[0] / scale_q <= tol.rtol else Verdict.FAILED,
                note=f"{a} and {b} are different maps ({convention}); at dt={dts[1]:g} their "
                f"difference is within the round-off of eps = {eps:.3g}, so its order cannot "
                f"be measured; at dt={dts[0]:g} it lies within the accumulated round-off",
            )
    p = float(np.log(d[0] / d[1]) / np.log(dts[0] / dts[1]))
    ok = p >= nominal - ORDER_SLACK  # two order-p maps differ by O(hᵖ) or less
    return Discrepancy.measured(
        case=case.name, quantity=Quantity.TRAJECTORY, impl_a=a, impl_b=b,
        integrator=integrator, dt=dts[0], error=d[0], scale=scale_q, tolerance=float("nan"),
        basis=f"difference of two order-{nominal} maps: shrinks at order >= "
        f"{nominal} - {ORDER_SLACK}",
        verdict=Verdict.EXPLAINED if ok else Verdict.FAILED,
        convention=convention,
        note=f"{a} and {b} are different maps ({convention}); their difference"
        + (" less the reference's prediction of their models' difference" if model else "")
        + f" shrinks at order {p:.3f} from dt={dts[0]:g} to {dts[1]:g} (predicted {nominal})",
    )


def _eps(impl: Implementation | Exception) -> float:
    return impl.eps if isinstance(impl, Implementation) else EPS


def engine_pairs(
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
                    va, vb = variants[a], variants[b]
                    model = None if va is None or vb is None or va == vb else (
                        lambda h, va=va, vb=vb, i=integrator:
                        refs.discrete(vb, i, h) - refs.discrete(va, i, h))
                    rows.append(
                        _frame_pair(case, a, b, integrator, dts, runs, differ, nominal, eps,
                                    model=model)
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
                    case=case.name, quantity=Quantity.TRAJECTORY, impl_a=a, impl_b=b,
                    integrator=integrator, dt=dt, error=err, scale=scale_q,
                    tolerance=tol.rtol, basis=tol.basis, worst_state=worst,
                )
                va, vb = variants[a], variants[b]
                if err / scale_q <= tol.rtol:
                    rows.append(Discrepancy.measured(**row, verdict=Verdict.PASSED))
                elif va is not None and vb is not None and va != vb:
                    try:
                        predicted = refs.discrete(vb, integrator, dt) - refs.discrete(
                            va, integrator, dt
                        )
                    except Exception as exc:  # no discrete prediction here: a failed row
                        rows.append(Discrepancy.measured(
                            **row, verdict=Verdict.FAILED,
                            convention="; ".join(va.conventions(vb)),
                            note=f"no prediction: {type(exc).__name__}: {exc}"))
                        continue
                    res_rel = float(difference(case, qb - qa, predicted).max()) / scale_q
                    note = (
                        f"predicted by the reference equations of both models, stepped by "
                        f"{integrator}: max {np.abs(predicted).max():.3g} rad; residual "
                        f"{res_rel:.3g}"
                    )
                    verdict = Verdict.EXPLAINED if res_rel <= tol.rtol else Verdict.FAILED
                    rows.append(Discrepancy.measured(
                        **row, verdict=verdict, convention="; ".join(va.conventions(vb)),
                        note=note))
                else:
                    rows.append(Discrepancy.measured(
                        **row, verdict=Verdict.FAILED,
                        note="unexplained: no convention predicts this"))
    return rows
