"""Every implementation at the same sampled states, every pair on every quantity.

A pair's verdict: ``passed`` when the normwise relative error is within the round-off
tolerance; ``explained`` when the two models differ by a named convention whose effect the
reference predicts — the general method evaluated on each implementation's model variant —
and the observed difference equals the predicted one within the same tolerance; otherwise
``failed``. An explanation is never a free pass: it predicts the difference itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from dyncheck.cases import Case, StateSample
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    QUANTITIES,
    Implementation,
    ReferenceImplementation,
    Variant,
    general_method,
)
from dyncheck.results import Discrepancy
from dyncheck.tolerances import Tolerance, instantaneous

POINT_INERTIA = "point-mass inertia floor"


@dataclass(frozen=True)
class Evaluation:
    """One implementation's values (book coordinates) at the sample, or why it has none."""

    name: str
    values: dict[str, np.ndarray] | None
    variant: Variant | None
    error: str = ""
    skipped: bool = False


def scale(desired: np.ndarray) -> float:
    """A quantity's scale: max |desired| over all states (1 where it is identically zero)."""
    return float(np.abs(desired).max()) or 1.0


def _error(actual: np.ndarray, desired: np.ndarray) -> tuple[float, float, int]:
    """(max abs error, max abs error / scale(desired), index of the worst state)."""
    diff = np.abs(actual - desired).reshape(len(desired), -1).max(axis=1)
    worst = int(np.argmax(diff))
    return float(diff[worst]), float(diff[worst]) / scale(desired), worst


class VariantPredictor:
    """The general method evaluated on model variants, cached per variant."""

    def __init__(self, case: Case, sample: StateSample) -> None:
        self.case, self.sample = case, sample
        self._cache: dict[Variant, dict[str, np.ndarray]] = {}

    def __call__(self, variant: Variant) -> dict[str, np.ndarray]:
        if variant not in self._cache:
            impl = ReferenceImplementation(self.case)
            impl.dyn = general_method(self.case, variant.hinge_inertia)
            self._cache[variant] = impl.evaluate(self.sample)
        return self._cache[variant]


def judge(
    case: Case,
    quantity: str,
    a: Evaluation,
    b: Evaluation,
    tol: Tolerance,
    predict: VariantPredictor,
) -> Discrepancy:
    """Compare b (actual) with a (desired) on one quantity."""
    row = dict(
        case=case.name,
        quantity=quantity,
        impl_a=a.name,
        impl_b=b.name,
        integrator="",
        dt=float("nan"),
        tolerance=tol.rtol,
        tolerance_basis=tol.basis,
    )
    if a.values is None or b.values is None:
        bad = a if a.values is None else b
        return Discrepancy(
            **row,
            max_abs_err=float("nan"),
            max_rel_err=float("nan"),
            verdict="skipped" if bad.skipped else "failed",
            convention="",
            note=f"{bad.name}: {bad.error}",
            worst_state=-1,
        )
    desired, actual = a.values[quantity], b.values[quantity]
    abs_err, rel_err, worst = _error(actual, desired)
    if rel_err <= tol.rtol:
        return Discrepancy(
            **row,
            max_abs_err=abs_err,
            max_rel_err=rel_err,
            verdict="passed",
            convention="",
            note="",
            worst_state=worst,
        )
    if a.variant is not None and b.variant is not None and a.variant != b.variant:
        pa, pb = predict(a.variant), predict(b.variant)
        _, predicted, _ = _error(pb[quantity], pa[quantity])
        residual = (actual - desired) - (pb[quantity] - pa[quantity])
        res_rel = float(np.abs(residual).max()) / scale(desired)
        note = (
            f"hinge inertia {b.name} {list(b.variant.hinge_inertia)} vs {a.name} "
            f"{list(a.variant.hinge_inertia)} kg m^2: predicted rel. difference "
            f"{predicted:.3g}, residual after prediction {res_rel:.3g}"
        )
        verdict = "explained" if res_rel <= tol.rtol else "failed"
        return Discrepancy(
            **row,
            max_abs_err=abs_err,
            max_rel_err=rel_err,
            verdict=verdict,
            convention=POINT_INERTIA,
            note=note,
            worst_state=worst,
        )
    note = "unexplained: no convention predicts this difference"
    return Discrepancy(
        **row,
        max_abs_err=abs_err,
        max_rel_err=rel_err,
        verdict="failed",
        convention="",
        note=note,
        worst_state=worst,
    )


def evaluate(impl: Implementation | Exception, name: str, sample: StateSample) -> Evaluation:
    """Run one implementation; an exception becomes a failed (or skipped) evaluation."""
    from dyncheck.errors import EngineNotInstalled

    if isinstance(impl, Exception):
        return Evaluation(name, None, None, str(impl), isinstance(impl, EngineNotInstalled))
    try:
        return Evaluation(name, impl.evaluate(sample), impl.variant())
    except Exception as exc:  # a report run survives one implementation crashing
        return Evaluation(name, None, None, f"{type(exc).__name__}: {exc}")


def compare_instantaneous(
    case: Case, impls: dict[str, Implementation | Exception], sample: StateSample
) -> list[Discrepancy]:
    """Rows for every pair (trusted first, in IMPLEMENTATIONS order) and quantity."""
    names = [n for n in IMPLEMENTATIONS if n in impls]
    evals = {n: evaluate(impls[n], n, sample) for n in names}
    predict = VariantPredictor(case, sample)
    condition = float(np.linalg.cond(predict(Variant((0.0,) * case.ndof))["mass_matrix"]).max())
    rows = []
    for quantity in QUANTITIES:
        tol = instantaneous(quantity, condition)
        for a, b in combinations(names, 2):
            rows.append(judge(case, quantity, evals[a], evals[b], tol, predict))
    return rows
