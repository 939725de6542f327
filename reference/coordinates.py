"""Coordinate systems as maps into Cartesian space, and the tensors they induce.

A coordinate system is the map x(q) from generalized coordinates qⁱ to Cartesian position.
From it: the metric g_ij = (∂x_k/∂qⁱ)(∂x_k/∂qʲ) of ds² = g_ij dqⁱ dqʲ ((2.2.6), (2.2.21)),
its inverse g^ij, the Christoffel symbols of the first kind
[mn, i] = ½ (∂g_im/∂qⁿ + ∂g_in/∂qᵐ − ∂g_mn/∂qⁱ) and of the second kind {i; m n} = g^ij [mn, j]
that enter the generalized acceleration (2.2.5). Derived exactly (sympy) for any user map;
the named systems also carry their textbook closed forms, which must agree with the derivation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache, cached_property

import numpy as np
import sympy as sp

from dyncheck.reference.derivations import derived, lambdified


@dataclass(frozen=True)
class CoordinateSystem:
    """x(q): Cartesian position (sympy expressions) as functions of coordinates ``q``.

    ``closed_form`` optionally holds the textbook metric and non-zero Christoffel symbols of
    the second kind as {(i, m, n): expr} (symmetric in m, n; give m ≤ n).
    """

    name: str
    q: tuple[sp.Symbol, ...]
    x: tuple[sp.Expr, ...]
    closed_metric: tuple[sp.Expr, ...] | None = None
    closed_christoffel: tuple[tuple[tuple[int, int, int], sp.Expr], ...] | None = None

    @property
    def dim(self) -> int:
        return len(self.q)

    @cached_property
    def jacobian(self) -> sp.Matrix:
        """∂x_k/∂qⁱ, shape (3, N)."""
        return sp.Matrix(self.x).jacobian(sp.Matrix(self.q))

    @cached_property
    def metric(self) -> sp.Matrix:
        """g_ij, derived from the map (cached on disk: :mod:`.derivations`)."""
        J = self.jacobian
        return derived("metric", (self.q, self.x),
                       lambda: (J.T * J).applyfunc(lambda e: sp.simplify(sp.trigsimp(e))))

    @cached_property
    def inverse_metric(self) -> sp.Matrix:
        """g^ij."""
        return derived("inverse_metric", (self.q, self.x),
                       lambda: self.metric.inv().applyfunc(sp.simplify))

    @cached_property
    def christoffel_first(self) -> list[list[list[sp.Expr]]]:
        """[mn, i] indexed [i][m][n]."""
        return derived("christoffel_first", (self.q, self.x), self._christoffel_first)

    def _christoffel_first(self) -> list[list[list[sp.Expr]]]:
        g, q, n = self.metric, self.q, self.dim
        return [
            [
                [
                    sp.simplify(
                        (sp.diff(g[i, m], q[k]) + sp.diff(g[i, k], q[m]) - sp.diff(g[m, k], q[i]))
                        / 2
                    )
                    for k in range(n)
                ]
                for m in range(n)
            ]
            for i in range(n)
        ]

    @cached_property
    def christoffel(self) -> list[list[list[sp.Expr]]]:
        """{i; m n} indexed [i][m][n], derived: g^ij [mn, j]."""
        return derived("christoffel", (self.q, self.x), self._christoffel)

    def _christoffel(self) -> list[list[list[sp.Expr]]]:
        gi, c1, n = self.inverse_metric, self.christoffel_first, self.dim
        return [
            [
                [sp.simplify(sum(gi[i, j] * c1[j][m][k] for j in range(n))) for k in range(n)]
                for m in range(n)
            ]
            for i in range(n)
        ]

    def closed_form_christoffel(self) -> list[list[list[sp.Expr]]]:
        """The textbook's {i; m n} (zeros elsewhere); raises if this system has none."""
        if self.closed_christoffel is None:
            raise ValueError(f"coordinate system {self.name!r} has no closed form")
        n = self.dim
        out = [[[sp.Integer(0)] * n for _ in range(n)] for _ in range(n)]
        for (i, m, k), expr in self.closed_christoffel:
            out[i][m][k] = out[i][k][m] = expr
        return out

    @cached_property
    def numeric(self) -> NumericCoordinates:
        """Batched numpy evaluation of the map, Jacobian, metric and Christoffel symbols."""
        q = self.q
        n = self.dim
        return NumericCoordinates(
            position=_batched(list(self.x), q, (3,)),
            jacobian=_batched(list(self.jacobian), q, (3, n)),
            metric=_batched(list(self.metric), q, (n, n)),
            christoffel=_batched([e for a in self.christoffel for b in a for e in b], q, (n, n, n)),
        )


def _batched(
    exprs: Sequence[sp.Expr], q: Sequence[sp.Symbol], shape: tuple[int, ...]
) -> Callable[[np.ndarray], np.ndarray]:
    fns = [lambdified(q, e, "numpy", cse=False) for e in exprs]

    def evaluate(qv: np.ndarray) -> np.ndarray:
        qv = np.atleast_2d(qv)
        cols = [np.broadcast_to(np.asarray(f(*qv.T), float), qv.shape[:1]) for f in fns]
        return np.stack(cols, -1).reshape(qv.shape[0], *shape)

    return evaluate


@dataclass(frozen=True)
class NumericCoordinates:
    """Shapes: position (n, 3), jacobian (n, 3, N), metric (n, N, N), christoffel
    (n, N, N, N) indexed [i, m, k] = {i; m k}."""

    position: Callable[[np.ndarray], np.ndarray]
    jacobian: Callable[[np.ndarray], np.ndarray]
    metric: Callable[[np.ndarray], np.ndarray]
    christoffel: Callable[[np.ndarray], np.ndarray]


@cache
def cartesian() -> CoordinateSystem:
    x, y, z = sp.symbols("x y z", real=True)
    return CoordinateSystem("cartesian", (x, y, z), (x, y, z), (1, 1, 1), ())


@cache
def cylindrical() -> CoordinateSystem:
    """(r, θ, z): x = r cos θ, y = r sin θ, z = z; ds² = dr² + r² dθ² + dz²;
    {r; θ θ} = −r, {θ; r θ} = 1/r."""
    r, th, z = sp.symbols("r theta z", real=True)
    return CoordinateSystem(
        "cylindrical",
        (r, th, z),
        (r * sp.cos(th), r * sp.sin(th), z),
        (1, r**2, 1),
        (((0, 1, 1), -r), ((1, 0, 1), 1 / r)),
    )


@cache
def spherical() -> CoordinateSystem:
    """The book's (ρ, θ, φ) of Example 5: x = ρ sin θ cos φ, y = ρ sin θ sin φ, z = ρ cos θ;
    ds² = dρ² + ρ² dθ² + ρ² sin²θ dφ²; {ρ; θθ} = −ρ, {ρ; φφ} = −ρ sin²θ, {θ; ρθ} = 1/ρ,
    {θ; φφ} = −sin θ cos θ, {φ; ρφ} = 1/ρ, {φ; θφ} = cot θ."""
    rho, th, ph = sp.symbols("rho theta phi", real=True)
    return CoordinateSystem(
        "spherical",
        (rho, th, ph),
        (rho * sp.sin(th) * sp.cos(ph), rho * sp.sin(th) * sp.sin(ph), rho * sp.cos(th)),
        (1, rho**2, rho**2 * sp.sin(th) ** 2),
        (
            ((0, 1, 1), -rho),
            ((0, 2, 2), -rho * sp.sin(th) ** 2),
            ((1, 0, 1), 1 / rho),
            ((1, 2, 2), -sp.sin(th) * sp.cos(th)),
            ((2, 0, 2), 1 / rho),
            ((2, 1, 2), sp.cos(th) / sp.sin(th)),
        ),
    )


def custom(name: str, q: Sequence[sp.Symbol], x: Sequence[sp.Expr]) -> CoordinateSystem:
    """A user-given map x(q); everything is derived exactly."""
    if len(x) != 3:
        raise ValueError(f"x must have 3 Cartesian components, got {len(x)}")
    return CoordinateSystem(name, tuple(q), tuple(sp.sympify(e) for e in x))


NAMED = {"cartesian": cartesian, "cylindrical": cylindrical, "spherical": spherical}
