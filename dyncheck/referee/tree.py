"""The referee, ``reference``, on the neutral tree one engine read from the file (the report
names which): the book's general method (:mod:`dyncheck.reference.tree`, Lagrange
(2.2.23)–(2.2.24)) — the root of trust — and the recursive Newton–Euler algorithm
(:mod:`dyncheck.reference.recursive`, (2.2.48)–(2.2.49) body by body), which serves the
states and the derivatives once it is tied to the general method on this very tree.

The tie: at the first :data:`TIE_STATES` sampled states both methods give M and h, compared
to round-off: 64 ε × the tree's depth × max(1, X/ℓ) of M's scale, and of the larger of |h| and
|M v̇| for h — X/ℓ how far from the world origin the model stands in its own lengths
(:meth:`~dyncheck.reference.recursive.RecursiveDynamics.reach`): the general method sums
momenta about the origin, whose lever arms lose ε X / ℓ; the recursive one works about each
subtree's root point and does not. Where they agree the recursive algorithm serves every
state; where they do not, the general method serves every state and the tie is a failed row
naming the referee itself."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.model_tree import Dynamics, ModelTree
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, standing
from dyncheck.referee.computed import bodies, in_layout
from dyncheck.reference.recursive import RecursiveDynamics
from dyncheck.reference.tree import TreeDynamics
from dyncheck.vocabulary import REFEREE

ENGINE = REFEREE
TIE_STATES = 10
"""States at which the recursive algorithm is tied to the general method on every tree."""
GENERAL = "reference (general method)"
RECURSIVE = "reference (recursive)"


@dataclass(frozen=True, kw_only=True)
class Tie:
    """The recursive algorithm's M and h against the general method's at ``states`` states:
    the larger relative error of the two, and the round-off tolerance."""

    states: int
    mass_error: float
    bias_error: float
    tolerance: float
    standing: float  # max(1, X / ℓ): how far from the origin the model stands

    @property
    def agrees(self) -> bool:
        return max(self.mass_error, self.bias_error) <= self.tolerance


def tie(general: TreeDynamics, recursive: RecursiveDynamics, depth: int, q: np.ndarray,
        v: np.ndarray, a: np.ndarray,
        found: tuple[np.ndarray, np.ndarray] | None = None) -> Tie:
    """Both methods at the states (q, v) — M against M's scale, h against the larger of
    |h| and |M a| (h vanishes without gravity and velocity); ``found``: the general
    method's M and h there, where the caller has them."""
    with np.errstate(all="ignore"):
        mass_g, bias_g = found if found is not None else general.at_states(q, v)[:2]
        mass_r, bias_r, _, _ = recursive.at_states(q, v)
        m_scale = max(float(np.abs(mass_g).max(initial=0.0)), 1e-300)
        h_scale = max(float(np.abs(bias_g).max(initial=0.0)),
                      float(np.abs(np.einsum("sij,sj->si", mass_g, a)).max(initial=0.0)),
                      1e-300)
        mass_error = float(np.abs(mass_r - mass_g).max(initial=0.0)) / m_scale
        bias_error = float(np.abs(bias_r - bias_g).max(initial=0.0)) / h_scale
    factor = standing(*recursive.reach(q))
    return Tie(states=len(q), mass_error=float(np.nan_to_num(mass_error, nan=np.inf)),
               bias_error=float(np.nan_to_num(bias_error, nan=np.inf)),
               tolerance=ROUNDOFF_FACTOR * EPS * max(depth, 1) * factor, standing=factor)


def standing_of(tree: ModelTree, q: np.ndarray) -> float:
    """max(1, X/ℓ) of ``tree`` at the states ``q`` (:func:`dyncheck.precision.standing`)."""
    return standing(*in_layout(RecursiveDynamics(bodies(tree), tree.gravity), tree).reach(q))


class ReferenceModel:
    """The referee, in the canonical layout of ``tree`` (whose order it keeps): ``solver``
    the general method, ``recursive`` the recursive algorithm; :attr:`tie` set by
    :meth:`dynamics`."""

    engine = ENGINE

    def __init__(self, tree: ModelTree) -> None:
        from dyncheck.referee.computed import depth

        self.tree = tree
        self.solver = in_layout(TreeDynamics(bodies(tree), tree.gravity), tree)
        self.recursive = in_layout(RecursiveDynamics(bodies(tree), tree.gravity), tree)
        self.depth = depth(tree)
        self.tie: Tie | None = None

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        """Every state at once: the two methods tied at the first :data:`TIE_STATES`
        states, then the one that may serve (the module's docstring); forward dynamics by
        one batched solve, a singular M (a joint moving no mass, a NaN) giving NaN for its
        state: a failed row (non-finite), never a crash."""
        first = slice(0, TIE_STATES)
        self.tie = tie(self.solver, self.recursive, self.depth, q[first], v[first], a[first])
        serving = self.recursive if self.tie.agrees else self.solver
        with np.errstate(all="ignore"):  # an overflow shows as a non-finite result: a row
            mass, bias, kinetic, potential = serving.at_states(q, v)
            forward = np.full_like(bias, np.nan)
            try:
                forward = np.linalg.solve(mass, -bias[..., None])[..., 0]
            except np.linalg.LinAlgError:  # one singular M fails the batch: state by state
                for i in range(len(q)):
                    try:
                        forward[i] = np.linalg.solve(mass[i], -bias[i])
                    except np.linalg.LinAlgError:
                        pass
            inverse = np.einsum("sij,sj->si", mass, a) + bias
        return Dynamics(
            mass_matrix=mass, bias=bias, forward=forward, inverse=inverse,
            kinetic=kinetic, potential=potential,
        )
