"""Every implementation at the same sampled states, every pair on every quantity.

A pair's verdict: ``passed`` when the normwise relative error is within the round-off
tolerance; ``explained`` when the two models differ by a named convention whose effect the
reference predicts — the general method evaluated on each implementation's model variant —
and the observed difference equals the predicted one within the same tolerance; otherwise
``failed``. An explanation is never a free pass: it predicts the difference itself.

States stream through in chunks: each pair keeps running maxima (error, scale, residual after
prediction, and the state where the error peaked), so memory stays flat however many states.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from itertools import combinations
from typing import Any

import numpy as np

from dyncheck.cases.base import Case, StateSample
from dyncheck.errors import EngineNotInstalled, Unsupported
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    Implementation,
    ReferenceImplementation,
    compared,
    general_method,
    quantities,
)
from dyncheck.precision import EPS, ROUNDOFF_FACTOR
from dyncheck.reference.constraints import MAX_IMPEDANCE
from dyncheck.results import Discrepancy
from dyncheck.tolerances import conditioned, instantaneous, soft_condition
from dyncheck.variants import ENGINE_DEFECT, GRAVITY_DEFAULT, POINT_INERTIA, Variant, book_variant
from dyncheck.vocabulary import Quantity, Verdict

__all__ = ["GRAVITY_DEFAULT", "POINT_INERTIA", "compare_instantaneous", "soft_factor"]


def soft_factor(v: Variant | None) -> float:
    """Round-off amplification of a variant's soft-constraint solve (1 without one): the
    :func:`soft_condition` at its largest impedance, clamped like MuJoCo's."""
    if v is None or not v.softness:
        return 1.0
    return soft_condition(min(max(v.softness[2:4]), MAX_IMPEDANCE))


def describe(v: Variant) -> str:
    """A variant in a few words, for notes."""
    soft = ""
    if v.softness:
        tc, dr, *imp = v.softness
        soft = f", soft constraint solref {[tc, dr]} solimp {imp}"
    how = "it computes with" if v.inertia_computed else "held"
    held = f", inertia {how} {dict(v.inertia)} kg m^2" if v.inertia else ""
    return (f"(point inertia {list(v.point_inertia)} kg m^2, gravity {list(v.gravity)} "
            f"m/s^2{held}{soft})")


def _per_state(x: np.ndarray) -> np.ndarray:
    """max |x| over everything but the state axis, shape (n,); ``x`` is overwritten by |x|
    (a difference made for this call: no second array per pair and quantity). The few values
    of a state are laid along the long axis first: numpy's reduction along a short last axis
    costs ~35 ns a row, 20 times the copy and the reduction across rows (the same maxima —
    a maximum does not round)."""
    rows = np.abs(x, out=x).reshape(len(x), -1)
    if rows.shape[1] == 1:
        return rows[:, 0]
    return np.ascontiguousarray(rows.T).max(axis=0)


def _fmt(x: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in x) + "]"


@dataclass
class PairStats:
    """Running maxima for one quantity of one pair (a = desired, b = actual), whatever the
    chunks: two stats of consecutive slices of states :meth:`merge` into the stats of both.

    The worst state is the first whose error lies within round-off (``ROUNDOFF_FACTOR`` ε of
    the largest desired value) of the largest error, so that ties at round-off go to the same
    state on every machine and for every cut of the states into chunks or workers. Only the
    errors' prefix maxima (each larger than all before it; a few dozen for random states) can
    be that state: they are kept, with the state's values."""

    scale: float = 0.0
    residual: float = 0.0
    predicted: float = 0.0
    sensitivity: float = 0.0
    """Max over states and entries of Σⱼ |∂f/∂xⱼ| |xⱼ| (:meth:`VariantPredictor.sensitivity`)."""
    effects: bool = False
    """Whether an engine's declared defect entered the prediction."""
    own_scale: float = 0.0
    """max |values| of a side whose declared defect makes it compute another model than the
    book's: the scale of its own round-off, which the residual after prediction carries."""
    records: list[tuple[int, float, str]] = field(default_factory=list)
    """(state index, error, state values) of each prefix maximum of the error, in order."""

    @property
    def max_abs(self) -> float:
        return self.records[-1][1] if self.records else 0.0

    def update(
        self,
        offset: int,
        s: StateSample,
        actual: np.ndarray,
        desired: np.ndarray,
        predicted: np.ndarray | None,
        *,
        scale: float,
    ) -> None:
        """Take in a chunk of states; ``scale`` is max |desired| (one per implementation and
        quantity, shared by the pairs that trust it)."""
        d = actual - desired
        if predicted is not None:
            self.predicted = max(self.predicted, float(np.abs(predicted).max()))
            self.residual = max(self.residual, float(np.abs(d - predicted).max()))
        diff = _per_state(d)
        self.scale = max(self.scale, scale)
        start = self.max_abs if self.records else -np.inf  # the first state is a record
        before = np.maximum.accumulate(np.concatenate([[start], diff]))[:-1]
        for k in np.flatnonzero(diff > before):
            self._add(offset + int(k), float(diff[k]), s, int(k))

    def _add(self, index: int, error: float, s: StateSample, k: int) -> None:
        values = f"q={_fmt(s.q[k])} v={_fmt(s.v[k])} tau={_fmt(s.tau[k])} a={_fmt(s.a[k])}"
        self.records.append((index, error, values))

    def merge(self, later: PairStats) -> PairStats:
        """The stats of this slice of states followed by ``later``'s."""
        top = self.max_abs
        return PairStats(
            scale=max(self.scale, later.scale),
            residual=max(self.residual, later.residual),
            predicted=max(self.predicted, later.predicted),
            sensitivity=max(self.sensitivity, later.sensitivity),
            effects=self.effects or later.effects,
            own_scale=max(self.own_scale, later.own_scale),
            records=[*self.records, *(r for r in later.records if r[1] > top or not self.records)],
        )

    @property
    def worst(self) -> tuple[int, str]:
        """(index, values) of the first state within round-off of the largest error."""
        if not self.records:
            return -1, ""
        band = ROUNDOFF_FACTOR * EPS * self.scale
        index, _error, values = next(r for r in self.records if r[1] >= self.max_abs - band)
        return index, values


@dataclass
class Evaluator:
    """One implementation across the chunks; the first exception ends it (a failed row)."""

    name: str
    impl: Implementation | Exception
    variant: Variant | None = None
    error: str = ""
    skipped: bool = False
    values: dict[str, np.ndarray] | None = field(default=None, repr=False)

    @property
    def eps(self) -> float:
        """Unit round-off of the implementation's arithmetic (float64's when it failed)."""
        return EPS if isinstance(self.impl, Exception) else self.impl.eps

    effects: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    """What its declared defects add to ``values`` (the chunk's states)."""
    unavailable: dict[str, str] = field(default_factory=dict, repr=False)
    """Quantity → why its engine does not compute it on this model (its limit, in its
    words)."""

    @property
    def defects(self) -> tuple[str, ...]:
        """An engine's declared defects on this model (none for the book's side)."""
        return self.impl.defects() if isinstance(self.impl, Implementation) else ()

    def __post_init__(self) -> None:
        if isinstance(self.impl, Exception):
            self.error = str(self.impl)
            self.skipped = isinstance(self.impl, EngineNotInstalled | Unsupported)
        else:
            try:
                self.variant = self.impl.variant()
            except Exception as exc:
                self.error = f"{type(exc).__name__}: {exc}"

    @property
    def ok(self) -> bool:
        return not self.error

    def step(self, s: StateSample) -> None:
        self.values = None
        if not self.ok:
            return
        try:
            values = self.impl.evaluate(s)  # type: ignore[union-attr]
            unavailable = self.impl.unavailable_quantities() \
                if isinstance(self.impl, Implementation) else {}
            self.unavailable.update(unavailable)
            for q, x in values.items():
                if q not in unavailable and not np.all(np.isfinite(x)):
                    raise FloatingPointError(f"non-finite {q}")
            self.values = values
            if isinstance(self.impl, Implementation):
                self.effects = self.impl.effects(s)
        except Exception as exc:  # a report run survives one implementation crashing
            self.error = f"{type(exc).__name__}: {exc}"


RELATIVE_STEP = 1e-6
"""The relative step of :meth:`VariantPredictor.sensitivity`'s central differences."""


class VariantPredictor:
    """The general method evaluated on model variants for the current chunk."""

    def __init__(self, case: Case) -> None:
        self.case = case
        self._impls: dict[Variant, ReferenceImplementation] = {}
        self._values: dict[Variant, dict[str, np.ndarray]] = {}

    def new_chunk(self, s: StateSample) -> None:
        self.sample, self._values = s, {}

    def __call__(self, variant: Variant) -> dict[str, np.ndarray]:
        if variant not in self._values:
            if variant not in self._impls:
                impl = ReferenceImplementation(self.case)
                impl.dyn = general_method(self.case, variant)
                self._impls[variant] = impl
            self._values[variant] = self._impls[variant].evaluate(self.sample)
        return self._values[variant]

    def sensitivity(self, variant: Variant) -> dict[str, float]:
        """Each quantity's first-order response to relative perturbations of its inputs: max
        over the chunk's states and the quantity's entries of Σⱼ |∂f/∂xⱼ| |xⱼ| over the
        components xⱼ of q, v, τ and v̇ — the componentwise condition number times |f|
        (:func:`~dyncheck.tolerances.conditioned`). Each term by a central difference at
        relative step :data:`RELATIVE_STEP` (truncation ~1e-12 of the term, round-off
        ε₆₄/1e-6 of |f|: both far below the bound's factor c)."""
        self(variant)
        impl = self._impls[variant]
        total: dict[str, np.ndarray] = {}
        for name in ("q", "v", "tau", "a"):
            x = getattr(self.sample, name)
            for j in range(x.shape[1]):
                step = np.zeros_like(x)
                step[:, j] = RELATIVE_STEP * x[:, j]
                if not step.any():
                    continue  # rounding an exact zero changes nothing
                up = impl.evaluate(replace(self.sample, **{name: x + step}))
                down = impl.evaluate(replace(self.sample, **{name: x - step}))
                for q, value in up.items():
                    term = np.abs(value - down[q]) / (2 * RELATIVE_STEP)
                    total[q] = total.get(q, 0.0) + term
        return {q: float(t.max()) for q, t in total.items()}


@dataclass(frozen=True, kw_only=True)
class Status:
    """What a row needs to know of one implementation after a sweep."""

    name: str
    variant: Variant | None
    eps: float
    error: str
    skipped: bool
    defects: tuple[str, ...] = ()
    """What the implementation's engine is known to do wrong on this model (measured, named
    by its adapter): the evidence a failed row cites."""
    unavailable: tuple[tuple[str, str], ...] = ()
    """(quantity, why) where its engine does not compute a quantity on this model."""

    @property
    def ok(self) -> bool:
        return not self.error


@dataclass(frozen=True, kw_only=True)
class Sweep:
    """What a slice of states leaves: each (quantity, a, b)'s stats, the largest condition
    number of the book's mass matrix, and each implementation's status (its first error).
    Slices computed apart — on other workers — :meth:`merge` in order into the sweep of all."""

    case: str
    stats: dict[tuple[str, str, str], PairStats]
    condition: float
    status: dict[str, Status]

    def merge(self, later: Sweep) -> Sweep:
        return Sweep(
            case=self.case,
            stats={k: st.merge(later.stats[k]) for k, st in self.stats.items()},
            condition=max(self.condition, later.condition),
            status={n: st if st.error else replace(later.status[n], unavailable=tuple(dict(
                st.unavailable + later.status[n].unavailable).items()))
                for n, st in self.status.items()},
        )


def _own_roundoff(st: PairStats, eps: float) -> float:
    """The absolute round-off of a defective side's own values that the residual after
    prediction carries (the prediction, float64 on both models, adds none of that size):
    c ε max|values| — where its own model makes its values far larger than the book's (a
    point mass on a hinge's axis: v̇ ~ 1e9), the book's scale would bound the residual by
    round-off of numbers that are not computed. Zero where no defect entered."""
    return ROUNDOFF_FACTOR * eps * st.own_scale if st.effects else 0.0


def _row(
    case: str, quantity: str, a: Status, b: Status, st: PairStats, condition: float
) -> Discrepancy:
    soft = max(soft_factor(a.variant), soft_factor(b.variant))
    tol = instantaneous(quantity, condition, soft, max(a.eps, b.eps))
    if st.sensitivity and st.scale:
        tol = conditioned(tol, st.sensitivity / st.scale, max(a.eps, b.eps))
    base: dict[str, Any] = dict(case=case, quantity=quantity, impl_a=a.name, impl_b=b.name,
                                tolerance=tol.rtol, basis=tol.basis)
    unavailable = [(x.name, why) for x in (a, b) for q, why in x.unavailable if q == quantity]
    if unavailable and a.ok and b.ok:  # an engine's limit on this model, in its words
        return Discrepancy.unmeasured(**base, verdict=Verdict.SKIPPED, note="; ".join(
            f"{name} does not compute it here: {why}" for name, why in unavailable))
    if not (a.ok and b.ok):
        bad = a if not a.ok else b
        return Discrepancy.unmeasured(
            **base,
            verdict=Verdict.SKIPPED if bad.skipped else Verdict.FAILED,
            # the engine named once: its own message may already start with its name
            note=bad.error if bad.error.startswith(f"{bad.name}: ") else f"{bad.name}: {bad.error}",
        )
    scale = st.scale or 1.0
    rel = st.max_abs / scale
    verdict, convention, note = Verdict.PASSED, "", ""
    if rel > tol.rtol:
        va, vb = a.variant, b.variant
        named = [f"{x.name}: {d}" for x in (a, b) for d in x.defects] if st.effects else []
        conventions: list[str] = []
        said: list[str] = []
        if va is not None and vb is not None and va != vb:
            conventions = va.conventions(vb)
            said = [f"{b.name} {describe(vb)} vs {a.name} {describe(va)}"]
        if said or named:
            convention = "; ".join(conventions + [ENGINE_DEFECT] * bool(named))
            note = (
                f"{convention}: {'; '.join(said + named)}; predicted rel. difference "
                f"{st.predicted / scale:.3g}, residual after prediction "
                f"{st.residual / scale:.3g}"
            )
            bound = tol.rtol + _own_roundoff(st, max(a.eps, b.eps)) / scale
            verdict = Verdict.EXPLAINED if st.residual / scale <= bound else Verdict.FAILED
            if st.residual / scale > tol.rtol:  # (the own round-off decides the verdict)
                note += (f" (bound {bound:.3g}: with the round-off of the defective side's own "
                         f"values, {ROUNDOFF_FACTOR} eps x max|values| {st.own_scale:.3g})")
        else:
            verdict, note = Verdict.FAILED, "unexplained: no convention predicts this difference"
    return Discrepancy.measured(
        **base, error=st.max_abs, scale=scale, verdict=verdict, convention=convention,
        note=note, worst_state=st.worst[0], worst_state_values=st.worst[1],
    )


def compare_instantaneous(
    case: Case,
    impls: Mapping[str, Implementation | Exception],
    chunks: StateSample | Iterable[StateSample],
) -> list[Discrepancy]:
    """Rows for every pair (trusted first, in IMPLEMENTATIONS order) and quantity, over all
    states of ``chunks`` (one sample or an iterable of chunks)."""
    return rows(sweep(case, impls, chunks))


def sweep(
    case: Case,
    impls: Mapping[str, Implementation | Exception],
    chunks: StateSample | Iterable[StateSample],
    *,
    offset: int = 0,
) -> Sweep:
    """Every pair on every quantity over the states of ``chunks``, the first of which has
    index ``offset`` in the whole sweep."""
    if isinstance(chunks, StateSample):
        chunks = [chunks]
    names = [n for n in IMPLEMENTATIONS if n in impls]
    evals = {n: Evaluator(n, impls[n]) for n in names}
    pairs = [(a, b) for a, b in combinations(names, 2) if compared(a, b)]
    qs = quantities(case)

    def provides(name: str, q: str) -> bool:
        impl = impls[name]
        return impl.provides(q) if isinstance(impl, Implementation) else True

    keys = [(q, a, b) for q in qs for a, b in pairs if provides(a, q) and provides(b, q)]
    stats = {key: PairStats() for key in keys}
    predict = VariantPredictor(case)
    book = book_variant(case)
    condition = 1.0
    for s in chunks:
        predict.new_chunk(s)
        condition = max(condition, float(np.linalg.cond(predict(book)[Quantity.MASS_MATRIX]).max()))
        sensitivity = predict.sensitivity(book)
        for ev in evals.values():
            ev.step(s)
        scales: dict[tuple[str, str], float] = {}  # (a, quantity) → max |a's values|
        for a, b in pairs:
            ea, eb = evals[a], evals[b]
            if ea.values is None or eb.values is None:
                continue
            va, vb = ea.variant, eb.variant
            pa = pb = None
            if va is not None and vb is not None and va != vb:
                pa, pb = predict(va), predict(vb)
            for q in qs:
                if (q, a, b) in stats and q not in ea.unavailable and q not in eb.unavailable:
                    desired = ea.values[q]
                    if (a, q) not in scales:
                        scales[a, q] = float(np.abs(desired).max())
                    predicted = pb[q] - pa[q] if pa is not None and pb is not None else None
                    if q in eb.effects or q in ea.effects:  # declared defects, predicted
                        predicted = (0.0 if predicted is None else predicted) \
                            + eb.effects.get(q, 0.0) - ea.effects.get(q, 0.0)
                    stats[q, a, b].update(offset, s, eb.values[q], desired, predicted,
                                          scale=scales[a, q])
                    stats[q, a, b].sensitivity = max(stats[q, a, b].sensitivity,
                                                     sensitivity.get(q, 0.0))
                    stats[q, a, b].effects |= q in eb.effects or q in ea.effects
                    _own(stats[q, a, b], [e for e in (ea, eb) if q in e.effects], q)
        offset += len(s)
    status = {
        n: Status(name=n, variant=e.variant, eps=e.eps, error=e.error, skipped=e.skipped,
                  defects=e.defects, unavailable=tuple(e.unavailable.items()))
        for n, e in evals.items()
    }
    return Sweep(case=case.name, stats=stats, condition=condition, status=status)


def _own(st: PairStats, sides: list[Evaluator], quantity: str) -> None:
    """Record the scale of the values of each side whose declared defect entered the
    prediction (its own model's round-off, not the book's)."""
    for side in sides:
        assert side.values is not None
        st.own_scale = max(st.own_scale, float(np.abs(side.values[quantity]).max()))


def rows(result: Sweep) -> list[Discrepancy]:
    """The rows of a (merged) sweep, in the order of its keys."""
    st = result.status
    return [
        _row(result.case, q, st[a], st[b], stats, result.condition)
        for (q, a, b), stats in result.stats.items()
    ]
