"""Tolerances as named records, each with its basis; checked to cover every quantity.

Instantaneous quantities are compared normwise: max |actual − desired| over all states and
components, divided by the quantity's scale, max |desired| over the states. Each engine or
formula evaluates an entry in O(10) floating-point operations on values of that scale, so
round-off is a few ε; 64 ε (1.4e-14) leaves room for the coordinate map (a few more products)
without admitting any modelling difference (the smallest one dyncheck explains is ~1e-9).
Forward dynamics solves M v̇ = τ − h, whose relative error is amplified by κ(M) (the
2-norm condition number, the largest over the sampled states).

A pair with a float32 implementation (MJX, MuJoCo Warp) is held to the same bounds with
ε₃₂ = 1.2e-7 in place of ε₆₄: the port rounds the state itself to float32 (a relative
perturbation ε₃₂ of q, v, τ, whose effect on M, h and τ is a few ε₃₂ at these states' scales)
and evaluates in float32; c = 64 covers both, as it covers the float64 evaluations. Forward
dynamics keeps its factor κ(M) (the solve amplifies the relative error of M and of τ − h).

Every instantaneous bound adds the quantity's conditioning, c ε Σⱼ |∂f/∂xⱼ||xⱼ| relative to
its scale (:func:`conditioned`): where the terms of a quantity cancel, round-off is relative
to the terms, not to the result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.precision import EPS, ROUNDOFF_FACTOR, eps_name
from dyncheck.vocabulary import INSTANTANEOUS, Quantity


@dataclass(frozen=True)
class Tolerance:
    """A relative tolerance and the reason for its size."""

    rtol: float
    basis: str


def soft_condition(impedance: float) -> float:
    """The amplification of round-off by a soft constraint of impedance d: MuJoCo's primal
    solver minimizes with Hessian M + Cᵀ R⁻¹ C, R = (1 − d)/d · C M⁻¹ Cᵀ, whose condition
    number exceeds κ(M) by up to 1 + d/(1 − d) (1e4 at d = 0.9999; measured: the solver's
    answer departs from the exact minimizer by ~1e-12 relative there, ~1e-16 at d = 0.9)."""
    return 1.0 + impedance / (1.0 - impedance)


def instantaneous(
    quantity: str, condition: float, soft: float = 1.0, eps: float = EPS
) -> Tolerance:
    """The tolerance for ``quantity``; ``condition`` = max κ(M) over the states, ``soft``
    the :func:`soft_condition` of a soft-constraint solve in the pair (1 if none), ``eps``
    the unit round-off of the pair's less precise implementation."""
    if quantity not in INSTANTANEOUS:
        raise KeyError(quantity)
    unit = eps_name(eps)
    if quantity in (Quantity.FORWARD_DYNAMICS, Quantity.CONSTRAINT_FORCE):
        basis = f"round-off: {ROUNDOFF_FACTOR} {unit} x cond(M) = {condition:.3g}"
        if soft > 1.0:
            basis += f" x soft-constraint Hessian 1 + d/(1-d) = {soft:.3g}"
        return Tolerance(ROUNDOFF_FACTOR * eps * condition * soft, basis)
    return Tolerance(ROUNDOFF_FACTOR * eps, f"round-off: {ROUNDOFF_FACTOR} {unit}")


def conditioned(tol: Tolerance, relative: float, eps: float) -> Tolerance:
    """``tol`` widened by the quantity's conditioning: c ε Σⱼ |∂f/∂xⱼ||xⱼ| over the state's
    components, relative to the quantity's scale (``relative``). An evaluation that is
    backward stable — exact for inputs perturbed by a few ε relative, as sums and products
    are — errs by up to that much (forward error ≤ condition × backward error; Higham,
    *Accuracy and Stability of Numerical Algorithms*, 2002, §1.6), and an engine that rounds
    the state it is given (float32) moves f by it to first order. Where a quantity cancels
    (g sin θ at θ ≈ π; the Atwood machine's potential with nearly equal masses), its terms
    are far larger than the result, and a bound relative to the result alone would fail an
    exact computation."""
    return Tolerance(tol.rtol + ROUNDOFF_FACTOR * eps * relative,
                     f"{tol.basis} + conditioning: {ROUNDOFF_FACTOR} {eps_name(eps)} x "
                     f"sum|df/dx||x| / max|f| = {relative:.3g}")


def accumulated(steps: int, soft: float = 1.0, eps: float = EPS) -> Tolerance:
    """Two runs of the same integrator on the same model: round-off accumulates at most
    linearly over the steps (no exponential growth on these regular orbits); ``soft`` as in
    :func:`instantaneous`, for runs through a soft-constraint solve; ``eps`` the unit
    round-off of the less precise run."""
    basis = f"accumulated round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x {steps} steps"
    if soft > 1.0:
        basis += f" x soft-constraint Hessian {soft:.3g}"
    return Tolerance(ROUNDOFF_FACTOR * eps * steps * soft, basis)


def first_near_max(errors: np.ndarray, band: float) -> int:
    """The first index whose error is within ``band`` (round-off) of the largest: where
    several errors tie at round-off, the same index on every machine."""
    return int(np.argmax(errors >= errors.max() - band))


ORDER_SLACK = 0.1
"""Observed order must lie within nominal ± this, in the asymptotic range."""

ROUNDOFF_MARGIN = 100.0
"""A run's error counts in the order study only if it exceeds this many times the run's own
round-off estimate :func:`roundoff_floor`. Measured (float32 against float64 runs of the same
MJX code): from 0.01 ε √N (a pendulum) up to 3.4 ε √N (a free body falling 15 m: the rounding
of its height is biased); a margin of 100 keeps round-off under 1/30 of a counted error, which
moves an observed order by less than the 0.1 slack."""


def roundoff_floor(eps: float, steps: int) -> float:
    """The round-off a fixed-step run accumulates, relative to the state's scale: ε per step,
    adding up as a random walk, ε √N (Henrici's statistical theory of round-off in
    discrete-variable methods, 1962)."""
    return eps * float(np.sqrt(steps))


REFERENCE_MARGIN = 100.0
"""A step's error counts in the order study only if it exceeds this many times the reference
trajectory's own error estimate."""


def check_coverage() -> None:
    """Every quantity has a tolerance (fails loudly when a quantity is added without one)."""
    for q in INSTANTANEOUS:
        instantaneous(q, 1.0)


check_coverage()


@dataclass(frozen=True, kw_only=True)
class BasisTerm:
    """One kind of tolerance basis (the start of a row's ``tolerance_basis``) and what it
    means, for the report's glossary."""

    starts: str
    meaning: str


BASES = (
    BasisTerm(starts="round-off", meaning="an instantaneous quantity computed two ways in "
              "floating point: c ε (c = 64; ε of float64, or of float32 for a port) relative "
              "to the quantity's largest entry, times κ(M) where a solve with M amplifies it, "
              "times the tree depth for derivatives accumulated along a chain, times a soft "
              "constraint's Hessian condition 1 + d/(1 − d); '+' terms add the quantity's "
              "conditioning c ε Σ|∂f/∂x||x| / max|f| (what a backward-stable evaluation, or "
              "rounding the state to float32, moves it by: large where its terms cancel), a "
              "finite difference's predicted truncation and round-off error and the referee's "
              "own error estimate"),
    BasisTerm(starts="accumulated round-off", meaning="two runs of the same integrator on "
              "the same model: c ε per step times the number of steps (round-off accumulates "
              "at most linearly)"),
    BasisTerm(starts="below the precision's round-off", meaning="a run whose truncation "
              "error is below what its precision resolves: judged by its accumulated "
              "round-off, not by an order"),
    BasisTerm(starts="exact for a polynomial q(t)", meaning="a case whose exact motion is a "
              "polynomial the integrator reproduces exactly (the pulleys' constant "
              "acceleration): accumulated round-off"),
    BasisTerm(starts="order study", meaning="a run against the reference at a sequence of "
              "steps: the observed order log(e(2h)/e(h))/log 2 at the finest pair in the "
              "asymptotic range within the integrator's nominal order ± 0.1"),
    BasisTerm(starts="difference of two order-", meaning="two different order-p maps (two "
              "engines' integrators that differ at O(h^p)): their difference must shrink at "
              "order p − 0.1 or faster"),
    BasisTerm(starts="tolerance proportionality", meaning="an error-controlled integrator at "
              "a decade sequence of accuracies ε: its global error must shrink ∝ ε (slope 1 "
              "± 0.1)"),
    BasisTerm(starts="2 x (reference error estimate", meaning="scipy's DOP853 on an "
              "engine's dynamics against the reference's DOP853: twice the sum of the two "
              "runs' own error estimates"),
    BasisTerm(starts="4 x DOP853 error estimate", meaning="the reference's run against the "
              "book's closed form (Kepler): four times DOP853's error estimate plus the closed "
              "form's own round-off"),
)
"""The glossary of tolerance bases; every row's basis starts with one of these (a test)."""


def basis_term(basis: str) -> BasisTerm | None:
    """The glossary term a row's ``tolerance_basis`` belongs to (the longest match)."""
    found = [t for t in BASES if basis.startswith(t.starts)]
    return max(found, key=lambda t: len(t.starts)) if found else None
