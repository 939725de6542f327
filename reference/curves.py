"""Curves in generalized coordinates: Frenet–Serret (2.2.6)–(2.2.15), the velocity and
acceleration split (2.2.16)–(2.2.17), the Darboux vector (exercise 29), and the small
geometric exercises 1–5 (lines, planes, tangents, intersections).

A curve is xⁱ = xⁱ(t) (2.2.1), sympy expressions in a parameter ``t`` in a coordinate system
``cs``. Intrinsic derivatives along the curve are δAⁱ/δs = (dAⁱ/dt + {i; m n} Aᵐ ẋⁿ)/(ds/dt).
Everything is exact up to the final numeric evaluation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from dyncheck.reference.coordinates import CoordinateSystem, cartesian


class DegenerateCurve(ValueError):
    """The Frenet frame is undefined: zero speed, or zero curvature (a straight piece)."""


@dataclass(frozen=True)
class FrenetFrame:
    """Contravariant T, N, B (shape (N,)), curvature κ ≥ 0 and signed torsion τ at one t."""

    T: np.ndarray
    N: np.ndarray
    B: np.ndarray
    kappa: float
    tau: float


@dataclass(frozen=True)
class Curve:
    """xⁱ(t) in ``cs`` (default Cartesian)."""

    t: sp.Symbol
    x: tuple[sp.Expr, ...]
    cs: CoordinateSystem = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.cs is None:
            object.__setattr__(self, "cs", cartesian())
        if len(self.x) != self.cs.dim:
            raise ValueError(
                f"curve has {len(self.x)} components, {self.cs.name} needs {self.cs.dim}"
            )

    @cached_property
    def _subs(self) -> dict[sp.Symbol, sp.Expr]:
        return dict(zip(self.cs.q, self.x, strict=True))

    def _on(self, expr: sp.Expr) -> sp.Expr:
        return expr.subs(self._subs)

    @cached_property
    def metric(self) -> sp.Matrix:
        return self.cs.metric.applyfunc(self._on)

    @cached_property
    def velocity(self) -> sp.Matrix:
        """vⁱ = dxⁱ/dt (2.2.3)."""
        return sp.Matrix([sp.diff(e, self.t) for e in self.x])

    @cached_property
    def speed(self) -> sp.Expr:
        """ds/dt = √(g_ij vⁱ vʲ)."""
        return sp.sqrt((self.velocity.T * self.metric * self.velocity)[0, 0])

    def intrinsic_ds(self, A: sp.Matrix) -> sp.Matrix:
        """δAⁱ/δs along the curve."""
        n = self.cs.dim
        G = [
            [[self._on(self.cs.christoffel[i][m][k]) for k in range(n)] for m in range(n)]
            for i in range(n)
        ]
        v = self.velocity
        return sp.Matrix(
            [
                (
                    sp.diff(A[i], self.t)
                    + sum(G[i][m][k] * A[m] * v[k] for m in range(n) for k in range(n))
                )
                / self.speed
                for i in range(n)
            ]
        )

    def _dot(self, A: sp.Matrix, B: sp.Matrix) -> sp.Expr:
        return (A.T * self.metric * B)[0, 0]

    def _cross(self, A: sp.Matrix, B: sp.Matrix) -> sp.Matrix:
        """Cⁱ = εⁱʲᵏ A_j B_k with εⁱʲᵏ = eᵢⱼₖ/√g (the covariant components lowered by g)."""
        a, b = self.metric * A, self.metric * B
        c = sp.Matrix(
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        )
        return c / sp.sqrt(self.metric.det())

    @cached_property
    def _frame_exprs(self) -> tuple:
        T = self.velocity / self.speed  # (2.2.6)
        dT = self.intrinsic_ds(T)  # = κ N (2.2.8)
        kappa = sp.sqrt(self._dot(dT, dT))
        N = dT / kappa
        B = self._cross(T, N)  # Bⁱ = εⁱʲᵏ T_j N_k
        dN = self.intrinsic_ds(N)  # = τ B − κ T (2.2.15)
        tau = self._dot(dN, B)
        dB = self.intrinsic_ds(B)  # = −τ N (2.2.14)
        return T, dT, kappa, N, B, dN, tau, dB

    def evaluate(self, expr, t0: float) -> np.ndarray:
        """``expr`` at t = t0, its repeated subexpressions computed once (``cse``: the frame's
        derivatives repeat the curve's, and printing them whole cost seconds a frame)."""
        f = sp.lambdify(self.t, expr, "numpy", cse=True)
        return np.asarray(f(t0), dtype=float).reshape(
            np.shape(expr) if hasattr(expr, "shape") else ()
        )

    def tangent(self, t0: float) -> np.ndarray:
        """The unit tangent Tⁱ = dxⁱ/ds (2.2.6) at t0."""
        if float(self.evaluate(self.speed, t0)) == 0.0:
            raise DegenerateCurve(f"speed is zero at t={t0}: no tangent")
        return self.evaluate(self.velocity / self.speed, t0).ravel()

    def frame(self, t0: float, *, tol: float = 1e-12) -> FrenetFrame:
        """T, N, B, κ, τ at t0; raises :class:`DegenerateCurve` where κ ≤ tol·(scale)."""
        T, dT, _, N, B, _, tau, _ = self._frame_exprs
        speed = float(self.evaluate(self.speed, t0))
        if speed == 0.0:
            raise DegenerateCurve(f"speed is zero at t={t0}: no Frenet frame")
        k = float(np.sqrt(max(float(self.evaluate(self._dot(dT, dT), t0)), 0.0)))
        if k <= tol:
            raise DegenerateCurve(
                f"curvature is zero at t={t0} (a straight line): the normal "
                "N and binormal B are undefined"
            )
        return FrenetFrame(
            self.evaluate(T, t0).ravel(),
            self.evaluate(N, t0).ravel(),
            self.evaluate(B, t0).ravel(),
            k,
            float(self.evaluate(tau, t0)),
        )

    def frenet_residuals(self, t0: float) -> dict[str, float]:
        """Max |·| of δT/δs − κN, δN/δs − (τB − κT), δB/δs + τN (2.2.15) at t0."""
        T, dT, kappa, N, B, dN, tau, dB = self._frame_exprs
        e = {"dT": dT - kappa * N, "dN": dN - (tau * B - kappa * T), "dB": dB + tau * N}
        return {k: float(np.abs(self.evaluate(v, t0)).max()) for k, v in e.items()}

    def darboux(self, t0: float) -> np.ndarray:
        """D = τ T + κ B (exercise 29): δA/δs = D × A for A = T, N, B."""
        fr = self.frame(t0)
        return fr.tau * fr.T + fr.kappa * fr.B

    def acceleration_split(self, t0: float) -> tuple[float, float, np.ndarray]:
        """(dv/dt, κ v², fⁱ) with fⁱ of (2.2.5): (2.2.17) says f = (dv/dt) T + κ v² N."""
        kappa = self._frame_exprs[2]
        v = self.velocity
        n = self.cs.dim
        G = [
            [[self._on(self.cs.christoffel[i][m][k]) for k in range(n)] for m in range(n)]
            for i in range(n)
        ]
        f = sp.Matrix(
            [
                sp.diff(v[i], self.t)
                + sum(G[i][m][k] * v[m] * v[k] for m in range(n) for k in range(n))
                for i in range(n)
            ]
        )
        return (
            float(self.evaluate(sp.diff(self.speed, self.t), t0)),
            float(self.evaluate(kappa * self.speed**2, t0)),
            self.evaluate(f, t0).ravel(),
        )

    def position(self, t0: float) -> np.ndarray:
        return self.evaluate(sp.Matrix(self.x), t0).ravel()


def line_through(p1: np.ndarray, p2: np.ndarray, t: sp.Symbol) -> Curve:
    """xⁱ = p1ⁱ + t (p2ⁱ − p1ⁱ) (exercise 1)."""
    return Curve(
        t, tuple(sp.nsimplify(a) + t * sp.nsimplify(b - a) for a, b in zip(p1, p2, strict=True))
    )


def plane_through(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray) -> tuple[sp.Matrix, sp.Matrix]:
    """x(s₁, s₂) = p1 + s₁ (p2 − p1) + s₂ (p3 − p1) and its unit normal (exercise 4)."""
    s1, s2 = sp.symbols("s1 s2")
    P = [sp.Matrix([sp.nsimplify(c) for c in p]) for p in (p1, p2, p3)]
    x = P[0] + s1 * (P[1] - P[0]) + s2 * (P[2] - P[0])
    n = sp.diff(x, s1).cross(sp.diff(x, s2))
    return x, n / sp.sqrt(n.dot(n))


def intersect_plane(curve: Curve, normal: tuple[float, ...], d: float) -> list[sp.Expr]:
    """Parameter values where a Cartesian curve meets the plane n·x = d (exercise 3)."""
    eq = sum(sp.nsimplify(n) * e for n, e in zip(normal, curve.x, strict=True)) - sp.nsimplify(d)
    return sorted(sp.solve(sp.Eq(eq, 0), curve.t), key=lambda r: complex(r).real)
