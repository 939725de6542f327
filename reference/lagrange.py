"""The general method: Lagrange's equations (2.2.23)–(2.2.26) from T and V, derived exactly.

Given T(x, ẋ) and V(x) as sympy expressions, the Euler–Lagrange equations (2.2.26) with
L = T − V (2.2.25) are written in the standard form

    M(x) ẍ + h(x, ẋ) = τ,

where M_rs = ∂²T/∂ẋʳ∂ẋˢ (the metric of (2.2.21) times the mass, from (2.2.22)),
h_r = (∂²T/∂ẋʳ∂xⁿ) ẋⁿ − ∂T/∂xʳ + ∂V/∂xʳ (velocity terms of (2.2.22) and the conservative
force of (2.2.20) moved to the left), and τ_r the remaining (non-potential) generalized force
Q_r of (2.2.23), a covariant vector. Everything is evaluated on batches: q, v of shape (n, N).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from dyncheck.reference.derivations import derived, lambdified


def particle_energies(
    masses: Sequence[sp.Expr],
    positions: Sequence[Sequence[sp.Expr]],
    q: Sequence[sp.Symbol],
    qd: Sequence[sp.Symbol],
    g: sp.Expr,
) -> tuple[sp.Expr, sp.Expr]:
    """T = Σ ½ m_k |ṙ_k|² (2.2.21)/(2.2.27) and V = Σ m_k g y_k (gravity along −y, V = −W
    of (2.2.20)) for particles at Cartesian positions r_k(q) = (x_k, y_k)."""
    T = sp.Integer(0)
    V = sp.Integer(0)
    for m, r in zip(masses, positions, strict=True):
        rdot = [sum(sp.diff(c, qi) * qdi for qi, qdi in zip(q, qd, strict=True)) for c in r]
        T += sp.Rational(1, 2) * m * sum(c**2 for c in rdot)
        V += m * g * r[1]
    return T, V


def _vectorize(expr: sp.Expr, args: Sequence[sp.Symbol]) -> Callable[..., np.ndarray]:
    """A numpy function of batched arguments; constants broadcast to the batch shape."""
    f = lambdified(args, expr, "numpy")

    def evaluate(*values: np.ndarray) -> np.ndarray:
        out = np.asarray(f(*values), dtype=float)
        return np.broadcast_to(out, np.broadcast(*values).shape).copy()

    return evaluate


def _fused(exprs: Sequence[sp.Expr], args: Sequence[sp.Symbol]) -> Callable[..., np.ndarray]:
    """Many expressions in one numpy function (shared subexpressions computed once); each
    result broadcast to the batch shape, stacked on the last axis. A batch of one state (a
    time step's stage) is evaluated by the same expressions in Python's ``math``, where
    numpy's per-call overhead would cost ten times the arithmetic; an argument outside
    ``math``'s domain falls back to numpy (its NaN or infinity, as for a batch)."""
    f = lambdified(args, list(exprs), "numpy")
    scalar: list[Callable[..., list[float]]] = []  # lambdified on first use

    def evaluate(*values: np.ndarray) -> np.ndarray:
        shape = np.broadcast(*values).shape
        if shape == (1,):
            if not scalar:
                scalar.append(lambdified(args, list(exprs), "math"))
            try:
                one = [float(x[0]) if isinstance(x, np.ndarray) else float(x) for x in values]
                return np.array([scalar[0](*one)], dtype=float)
            except (ArithmeticError, ValueError):  # outside math's domain
                pass
        return np.stack(
            [np.broadcast_to(np.asarray(x, dtype=float), shape) for x in f(*values)], -1
        )

    return evaluate


@dataclass(frozen=True)
class SymbolicSystem:
    """T(x, ẋ) and V(x) with parameter symbols; :meth:`numeric` binds parameter values.

    ``field`` is the potential of a force applied from outside the model (e.g. a central
    attraction an engine receives through its external-force input): its generalized force
    Q_r = −∂V_f/∂xʳ (2.2.20) is applied in forward and inverse dynamics but kept out of h and
    V, as an engine keeps it out of its bias forces and energies.
    """

    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    params: tuple[sp.Symbol, ...]
    T: sp.Expr
    V: sp.Expr
    field: sp.Expr | int = 0
    simplify: bool = True
    """Simplify M and h symbolically (exact either way; off where sympy's simplify is slow)."""

    def equations(self) -> tuple[sp.Matrix, sp.Matrix]:
        """(M, h) of the standard form, from (2.2.22)–(2.2.26) (cached on disk:
        :mod:`.derivations`)."""
        inputs = (self.q, self.qd, self.T, self.V, self.simplify)
        return derived("lagrange_equations", inputs, self._equations)

    def _equations(self) -> tuple[sp.Matrix, sp.Matrix]:
        n = len(self.q)
        p = [sp.diff(self.T, qdi) for qdi in self.qd]  # ∂T/∂ẋʳ
        tidy = sp.simplify if self.simplify else sp.expand
        M = sp.Matrix(n, n, lambda r, s: tidy(sp.diff(p[r], self.qd[s])))
        h = sp.Matrix(
            n,
            1,
            lambda r, _: tidy(
                sum(sp.diff(p[r], qn) * qdn for qn, qdn in zip(self.q, self.qd, strict=True))
                - sp.diff(self.T, self.q[r])
                + sp.diff(self.V, self.q[r])
            ),
        )
        return M, h

    @cached_property
    def compiled(self) -> tuple:
        """(M entries, h entries, T, V) as numpy functions of (x, ẋ, parameters), derived and
        compiled once per system and shared by every set of parameter values."""
        M, h = self.equations()
        args = (*self.q, *self.qd, *self.params)
        n = len(self.q)
        return (
            tuple(tuple(_vectorize(M[r, c], args) for c in range(n)) for r in range(n)),
            tuple(_vectorize(h[r, 0], args) for r in range(n)),
            _vectorize(self.T, args),
            _vectorize(self.V, args),
            tuple(_vectorize(-sp.diff(self.field, qi), args) for qi in self.q),
            _vectorize(self.field, args),
            _fused([*M, *h, *(-sp.diff(self.field, qi) for qi in self.q)], args),
        )

    def numeric(self, values: dict[str, float]) -> LagrangianDynamics:
        missing = {s.name for s in self.params} - set(values)
        if missing:
            raise KeyError(f"missing parameter values: {sorted(missing)}")
        M_entries, h_entries, T_fn, V_fn, F_entries, Vf_fn, fused = self.compiled
        return LagrangianDynamics(
            fused=fused,
            F_entries=F_entries,
            Vf_fn=Vf_fn,
            ndof=len(self.q),
            param_values=tuple(float(values[s.name]) for s in self.params),
            M_entries=M_entries,
            h_entries=h_entries,
            T_fn=T_fn,
            V_fn=V_fn,
        )


@dataclass(frozen=True)
class LagrangianDynamics:
    """Numeric M(q), h(q, v), forward and inverse dynamics, T, V on batches (n, N)."""

    ndof: int
    param_values: tuple[float, ...]
    M_entries: tuple[tuple[Callable[..., np.ndarray], ...], ...]
    h_entries: tuple[Callable[..., np.ndarray], ...]
    T_fn: Callable[..., np.ndarray]
    V_fn: Callable[..., np.ndarray]
    F_entries: tuple[Callable[..., np.ndarray], ...] = ()
    Vf_fn: Callable[..., np.ndarray] | None = None
    fused: Callable[..., np.ndarray] | None = None
    """M, h and the field's force in one call (the hot path of forward dynamics)."""

    def field_force(self, q: np.ndarray) -> np.ndarray:
        """Q_r = −∂V_f/∂xʳ of the external field, shape (n, N) (zero without a field)."""
        q = np.atleast_2d(q)
        if not self.F_entries:
            return np.zeros_like(q, dtype=float)
        args = self._args(q)
        return np.stack([f(*args) for f in self.F_entries], -1)

    def field_potential(self, q: np.ndarray) -> np.ndarray:
        """V_f of the external field, shape (n,)."""
        q = np.atleast_2d(q)
        return np.zeros(len(q)) if self.Vf_fn is None else self.Vf_fn(*self._args(q))

    def _args(self, q: np.ndarray, v: np.ndarray | None = None) -> list[np.ndarray]:
        q = np.atleast_2d(q)
        v = np.zeros_like(q) if v is None else np.atleast_2d(v)
        return [*q.T, *v.T, *self.param_values]

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q), shape (n, N, N)."""
        args = self._args(q)
        return np.stack([np.stack([f(*args) for f in row], -1) for row in self.M_entries], -2)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """h(q, v) = velocity terms + gravity, shape (n, N)."""
        args = self._args(q, v)
        return np.stack([f(*args) for f in self.h_entries], -1)

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """ẍ = M⁻¹(τ + Q_field − h), shape (n, N)."""
        if self.fused is not None:
            n = self.ndof
            out = self.fused(*self._args(q, v))
            M = out[..., : n * n].reshape(-1, n, n)
            h, Q = out[..., n * n : n * n + n], out[..., n * n + n :]
            rhs = np.atleast_2d(tau) + Q - h
            return np.linalg.solve(M, rhs[..., None])[..., 0]
        rhs = np.atleast_2d(tau) + self.field_force(q) - self.bias(q, v)
        return np.linalg.solve(self.mass_matrix(q), rhs[..., None])[..., 0]

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """τ = M ẍ + h − Q_field, shape (n, N)."""
        return (
            np.einsum("nij,nj->ni", self.mass_matrix(q), np.atleast_2d(a))
            + self.bias(q, v)
            - self.field_force(q)
        )

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """T, shape (n,)."""
        return self.T_fn(*self._args(q, v))

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        """V, shape (n,)."""
        return self.V_fn(*self._args(q))
