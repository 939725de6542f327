"""sympy.physics.mechanics as a symbolic peer engine: the case's engine-neutral model written
as frames, points and particles, Lagrange's equations by ``LagrangesMethod``, numbers by
``lambdify``. It shares no code with :mod:`dyncheck.reference` (adapters never import it), so
its agreement is independent evidence.

Construction, per body: the parent's frame and point; each joint in order either rotates the
frame (hinge: ``orientnew('Axis')``; ball: ``orientnew('Body', (φ, θ, ψ), 'ZXZ')``, Example
9's angles as coordinates) or moves the point (slide: along the frame's axis; free: along
the parent's axes, then a ball); the centre of mass is located in the final frame. Point
masses are ``Particle``s, bodies with inertia ``RigidBody``s. Gravity enters as loads;
the Lagrangian is T alone, so ``LagrangesMethod`` gives M q̈ = F with F = τ_loads −
(velocity terms). The canonical h is −F without the field's loads; the field's generalized
force is F(field) − F(no field).
Energies: ``kinetic_energy`` and V = −Σ m g·r. Couplings (cords) are ``hol_coneqs`` of
``LagrangesMethod``: its full mass matrix and forcing give q̈ and the multipliers λ together
(M q̈ = F + τ + Φᵀ λ, the adapters' sign of f).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import sympy as sp
import sympy.physics.mechanics as me

from dyncheck.adapters.base import Field, ModelEngine
from dyncheck.adapters.integrators import integrate
from dyncheck.adapters.linalg import solve
from dyncheck.adapters.model_tree import Dynamics, ModelTree
from dyncheck.adapters.offers import Offer
from dyncheck.adapters.symbolic import AFRESH, Symbolic
from dyncheck.adapters.sympy_mechanics.tree import Chart, case_tree
from dyncheck.cases.multibody import Coupling, Multibody
from dyncheck.errors import Unsupported
from dyncheck.vocabulary import ROTATING, Integrator


def _vec(frame: me.ReferenceFrame, xyz) -> me.Vector:
    return sum(
        (sp.Rational(float(c)) * e for c, e in zip(xyz, (frame.x, frame.y, frame.z), strict=True)),
        me.Vector(0),
    )


def _batched(
    exprs: list[sp.Expr], args: list[sp.Symbol], lambdify: Callable[..., Callable[..., Any]]
) -> Callable[..., np.ndarray]:
    """One function for all of ``exprs`` (common subexpressions shared): numpy over a batch
    of states, Python's ``math`` on scalars for one state (a time step: numpy's per-call
    overhead would dominate). Constant entries are filled in, not evaluated. Returns
    (n, len(exprs)) for n states."""
    symbols = set(args)
    varying = [i for i, e in enumerate(exprs) if e.free_symbols & symbols]
    const = [i for i, e in enumerate(exprs) if not e.free_symbols & symbols]
    values_const = np.array([float(exprs[i]) for i in const])
    terms = [exprs[i] for i in varying]
    batch = lambdify(args, terms, "numpy")
    scalar = lambdify(args, terms, "math")

    def evaluate(*values: np.ndarray) -> np.ndarray:
        n = np.broadcast(*values).shape[0]
        out = np.empty((n, len(exprs)))
        out[:, const] = values_const
        if varying and n == 1:
            out[0, varying] = scalar(*(float(x[0]) for x in values))
        elif varying:
            out[:, varying] = np.stack(batch(*values), -1)
        return out

    return evaluate


_SOURCE = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]
"""This module's source, part of the key of its cached derivations (an edit derives afresh)."""


@dataclass(frozen=True, kw_only=True)
class Equations:
    """What LagrangesMethod derives for a model, in plain symbols x0.., v0.. (positions,
    velocities): M and h = −F of the standard form, the field's generalized force, the
    cords' KKT matrix and right-hand side (with ``ncons`` multipliers), T and V."""

    M: tuple[sp.Expr, ...]
    h: tuple[sp.Expr, ...]
    field: tuple[sp.Expr, ...]
    K: tuple[sp.Expr, ...]
    rhs: tuple[sp.Expr, ...]
    ncons: int
    T: sp.Expr
    V: sp.Expr


def _derive(model: Multibody) -> Equations:
    """The model as frames, points and particles, and Lagrange's equations (the module's
    docstring says how)."""
    n = model.nv
    q = me.dynamicsymbols(f"q0:{n}")
    qd = [qi.diff() for qi in q]
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    particles, gravity_loads, field_loads, V = _bodies(model, q, N, O)
    T = me.kinetic_energy(N, *particles)
    qs, vs = sp.symbols(f"x0:{n}"), sp.symbols(f"v0:{n}")
    plain = dict(zip(qd, vs, strict=True)) | dict(zip(q, qs, strict=True))

    def forcing(loads: list) -> sp.Matrix:
        lm = me.LagrangesMethod(T, q, forcelist=loads or None, frame=N)
        lm.form_lagranges_equations()
        return lm.mass_matrix, lm.forcing

    M, F_free = forcing(gravity_loads)
    K_exprs: list[sp.Expr] = []
    rhs_exprs: list[sp.Expr] = []
    if model.couplings:
        K_exprs, rhs_exprs = _constrained(model, T=T, q=q, loads=gravity_loads, N=N,
                                          plain=plain)
    M_exprs = [e.subs(plain) for e in M]
    h_exprs = [(-e).subs(plain) for e in F_free]
    field_exprs: list[sp.Expr] = []
    if field_loads:
        _, F_field = forcing(gravity_loads + field_loads)
        field_exprs = [(a - b).subs(plain) for a, b in zip(F_field, F_free, strict=True)]
    return Equations(
        M=tuple(M_exprs), h=tuple(h_exprs), field=tuple(field_exprs), K=tuple(K_exprs),
        rhs=tuple(rhs_exprs), ncons=len(model.couplings), T=T.subs(plain), V=V.subs(plain))


def _bodies(model: Multibody, q: list, N: me.ReferenceFrame,
            O: me.Point) -> tuple[list, list, list, sp.Expr]:
    """Every body as a particle or a rigid body at its centre of mass, placed through its
    joints (a free joint's position in its parent's axes, then Example 9's angles; a hinge
    about its axis; a slide along it), with its gravity load, the central field's where
    the model has one, and the potential energy: (bodies, gravity loads, field loads, V)."""
    frames = {None: N}
    points = {None: O}
    particles, gravity_loads, field_loads, V = [], [], [], sp.Integer(0)
    g = _vec(N, model.gravity)
    k = 0
    for body in model.bodies:
        frame = frames[body.parent]
        point = points[body.parent].locatenew(f"{body.name}_j", _vec(frame, body.joint_pos))
        for joint in body.joints:
            if joint.type == "free":  # position in the parent's axes, then a ball
                offset = q[k] * frame.x + q[k + 1] * frame.y + q[k + 2] * frame.z
                point = point.locatenew(f"{joint.name}_P", offset)
                k += 3
            if joint.type in ROTATING:  # Example 9's angles: body Z, X, Z
                frame = frame.orientnew(
                    f"{joint.name}_F", "Body", (q[k], q[k + 1], q[k + 2]), "ZXZ"
                )
                k += 3
            elif joint.type == "hinge":
                frame = frame.orientnew(
                    f"{joint.name}_F", "Axis", (q[k], _vec(frame, joint.axis))
                )
                k += 1
            else:
                point = point.locatenew(f"{joint.name}_P", q[k] * _vec(frame, joint.axis))
                k += 1
        com = point.locatenew(f"{body.name}_c", _vec(frame, body.com))
        r = com.pos_from(O)
        com.set_vel(N, r.dt(N))
        frame.set_ang_vel(N, frame.ang_vel_in(N))
        m = sp.Rational(float(body.mass))
        particles.append(_body(model, body, com=com, frame=frame, mass=m))
        gravity_loads.append((com, m * g))
        V -= m * g.dot(r)
        if model.central_mu:
            dist = sp.sqrt(r.dot(r))
            field_loads.append((com, -sp.Rational(float(model.central_mu)) * m * r / dist**3))
        frames[body.name], points[body.name] = frame, point
    return particles, gravity_loads, field_loads, V


def _body(model: Multibody, body: Any, *, com: me.Point, frame: me.ReferenceFrame,
          mass: sp.Expr) -> Any:
    """A particle where the body has no inertia about its centre of mass, else a rigid
    body with its inertia dyadic in its own frame."""
    I = model.body_inertia(body)  # a point mass on a ball joint carries the floor
    if not I.any():
        return me.Particle(body.name, com, mass)
    dyad = me.inertia(
        frame,
        *(
            sp.Rational(float(x))
            for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[0, 2])
        ),
    )
    return me.RigidBody(body.name, com, frame, mass, (dyad, com))


def _constrained(model: Multibody, *, T: sp.Expr, q: list, loads: list,
                 N: me.ReferenceFrame, plain: dict) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """The cords as holonomic constraints: LagrangesMethod adds multipliers λ with
    M q̈ − Φᵀ λ = F and the constraints' second derivative Φ q̈ = −Φ̇ q̇ — the lower block of
    its full mass matrix and forcing, in plain symbols."""
    n = model.nv
    index = {j.name: i for i, j in enumerate(model.joints)}
    cons = [
        sum(sp.Rational(float(c)) * q[index[j]] for j, c in cp.coefs)
        for cp in model.couplings
    ]
    lm = me.LagrangesMethod(T, q, hol_coneqs=cons, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    K = lm.mass_matrix_full[n:, n:]
    rhs = lm.forcing_full[n:, :]
    return [e.subs(plain) for e in K], [e.subs(plain) for e in rhs]


class SympyMechanics(ModelEngine):
    """The case's Lagrange equations (see the module) as an engine: built from the case (its
    registration's ``run`` is :attr:`~.registration.Format.CASE`), not read from a file. Its
    tree holds the case's joints in the canonical layout; it computes in Example 9's angles
    and their rates (:class:`~.tree.Chart`) and maps each batch there and back."""

    engine = "sympy-mechanics"
    offers = frozenset({Offer.FORWARD, Offer.STEPPING, Offer.COUPLINGS, Offer.BODY_FORCES})
    steps_in_a_chart = True
    """A rotating body's state is stepped in its angles (q₊ = q + h q̇)."""
    per_state_calls = False
    """Its dynamics are dyncheck's own lambdified equations: no engine call to time."""
    definitions: ClassVar[Mapping[str, str]] = {Integrator.IMPLICITFAST: Integrator.EULER}
    """dyncheck's ``implicitfast`` has D = 0 here (no damping, no actuators): ``euler``."""

    def __init__(self, model: Multibody, *, symbolic: Symbolic = AFRESH) -> None:
        n = model.nv
        self.model = model
        self.tree: ModelTree = case_tree(model, engine=self.engine)
        self._chart = Chart(model)
        self._symbolic = symbolic
        eq = symbolic.derive("sympy_mechanics", (repr(model), _SOURCE), lambda: _derive(model))
        args = [*sp.symbols(f"x0:{n}"), *sp.symbols(f"v0:{n}")]

        def batched(exprs: list[sp.Expr]) -> Callable[..., np.ndarray]:
            return _batched(exprs, args, symbolic.lambdify)

        self._kkt = None
        if model.couplings:
            self._kkt = (batched(list(eq.K)), batched(list(eq.rhs)), eq.ncons)
        self._M = batched(list(eq.M))
        self._h = batched(list(eq.h))
        self._field = batched(list(eq.field)) if eq.field else None
        self._stepping = (args, [*eq.K, *eq.rhs] if model.couplings else
                          [*eq.M, *eq.h, *eq.field])
        self._step_fn: Callable[..., list[float]] | None = None
        self._T = batched([eq.T])
        self._V = batched([eq.V])
        self._n = n

    @classmethod
    def version(cls, package: str) -> str:
        return sp.__version__

    def _args(self, x: np.ndarray, xd: np.ndarray | None = None) -> list[np.ndarray]:
        """The lambdified functions' arguments: angles and rates, column by column."""
        xd = np.zeros_like(x) if xd is None else xd
        return [*np.atleast_2d(x).T, *np.atleast_2d(xd).T]

    def _field_force(self, x: np.ndarray) -> np.ndarray:
        return np.zeros_like(x) if self._field is None else self._field(*self._args(x))

    def _mass(self, x: np.ndarray) -> np.ndarray:
        return self._M(*self._args(x)).reshape(-1, self._n, self._n)

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        """M, h, τ at v̇ = a (without the field: the run adds its force), T and V, computed in
        the angles and mapped to the tree's layout by the chart's T: M = Tᵀ M_x T, forces by
        Tᵀ, h = Tᵀ (h_x + M_x Ṫ v)."""
        s = self._chart.to_angles(q, v, a)
        mass, bias = self._mass(s.x), self._h(*self._args(s.x, s.xd))
        t_t = np.swapaxes(s.t, 1, 2)
        mass_c = t_t @ mass @ s.t
        bias_c = self._chart.force(s.t, bias + np.einsum("nij,nj->ni", mass, s.tdot_v))
        return Dynamics(
            mass_matrix=mass_c, bias=bias_c,
            forward=-np.linalg.solve(mass_c, bias_c[..., None])[..., 0],
            inverse=self._chart.force(s.t, np.einsum("nij,nj->ni", mass, s.xdd) + bias),
            kinetic=self._T(*self._args(s.x, s.xd))[:, 0],
            potential=self._V(*self._args(s.x))[:, 0])

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        """The case's central field's generalized force, derived with its equations (the
        ``field`` a run hands is that same field: this engine is built from the case)."""
        s = self._chart.to_angles(q, v, np.zeros_like(v))
        return self._chart.force(s.t, self._field_force(s.x))

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """v̇ at τ (every applied force: a run adds the field's, :meth:`body_forces`):
        M⁻¹ (τ − h) in the angles, or with cords the first rows of LagrangesMethod's KKT
        system (:meth:`constrained`)."""
        if self._kkt is not None:
            return self.constrained(q, v, tau)[0]
        s = self._chart.to_angles(q, v, np.zeros_like(v))
        rhs = self._chart.generalized(s.t, tau) - self._h(*self._args(s.x, s.xd))
        return self._chart.acceleration(s, np.linalg.solve(self._mass(s.x), rhs[..., None])[
            ..., 0])

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """Its equations hold the case's couplings from the start: only those are accepted."""
        if tuple(couplings) != self.model.couplings:
            raise Unsupported(f"{self.engine} holds its case's couplings only")

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self.constrained(q, v, tau)[1]

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(v̇, λ) of LagrangesMethod's equations with the cords (M q̈ = F + τ + Φᵀ λ)."""
        s = self._chart.to_angles(q, v, np.zeros_like(v))
        out = self._kkt_solve(s.x, s.xd, self._chart.generalized(s.t, tau))
        return self._chart.acceleration(s, out[:, : self._n]), out[:, self._n :]

    def _kkt_solve(self, x: np.ndarray, xd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """(ẍ, λ) of the KKT system with τ (in the angles) added to its forcing."""
        if self._kkt is None:
            raise Unsupported(f"{self.engine}: its case has no couplings")
        K_fn, rhs_fn, m = self._kkt
        n = self._n
        K = K_fn(*self._args(x, xd)).reshape(-1, n + m, n + m)
        rhs = rhs_fn(*self._args(x, xd))
        rhs[:, :n] += tau
        return np.linalg.solve(K, rhs[..., None])[..., 0]

    def _step_acceleration(self, x: np.ndarray, xd: np.ndarray) -> np.ndarray:
        """ẍ at one state in the angles with no applied force (a time step's stage): M⁻¹(f −
        h), or with cords the first n rows of the KKT system's solution — from one scalar
        function of the state (common subexpressions shared, Python's ``math``): the per-call
        cost of the batched path's numpy calls dominated a trajectory."""
        n = self._n
        if self._step_fn is None:  # lambdified on first use: only trajectories need it
            args, exprs = self._stepping
            self._step_fn = self._symbolic.lambdify(args, exprs, "math")
        values = np.array(self._step_fn(*x.tolist(), *xd.tolist()), float)
        if self._kkt is not None:
            size = n + self._kkt[2]
            K, rhs = values[: size * size].reshape(size, size), values[size * size :]
            return solve(K, rhs)[:n]
        M, h, f = values[: n * n].reshape(n, n), values[n * n : n * n + n], values[n * n + n :]
        rhs = (f - h) if len(f) else -h
        return rhs / M[0, 0] if n == 1 else solve(M, rhs)

    def _held_acceleration(self, x: np.ndarray, xd: np.ndarray,
                           held: np.ndarray) -> np.ndarray:
        """ẍ at one state in the angles under a generalized force ``held`` in place of the
        field's (RK4's held-force stages: the field at the step's start)."""
        if self._kkt is not None:  # (its forcing holds no field: the held force less it)
            tau = held - self._field_force(x[None])[0]
            return self._kkt_solve(x[None], xd[None], tau[None])[0, : self._n]
        rhs = held - self._h(*self._args(x[None], xd[None]))[0]
        return solve(self._mass(x[None])[0], rhs)

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's definitions (:mod:`.integrators`) stepped in the angles and their rates
        (Python-level evaluations of the lambdified equations), mapped back."""

        def acc(x: np.ndarray, xd: np.ndarray, held=None) -> np.ndarray:
            if held is None:
                return self._step_acceleration(x, xd)
            return self._held_acceleration(x, xd, held)

        start = self._chart.to_angles(q0[None], v0[None], np.zeros_like(v0)[None])
        xs, xds = integrate(acc, start.x[0], start.xd[0], dt, steps, integrator,
                            freeze=lambda x, xd: self._field_force(x[None])[0])
        return self._chart.from_angles(xs, xds)
