"""Pinocchio stepped: it has no time integrator of its own, so :mod:`.integrators` supplies
MuJoCo's definitions, run in MuJoCo's state layout (a quaternion (w, x, y, z); a free
joint's linear velocity in world axes, v_w = R v_b, whose rate is R (v̇_b + ω × v_b)) on
Pinocchio's own forward dynamics, so that the maps compare like for like; and scipy's
error-controlled DOP853 integrates it on the rotation group in re-centred exponential
coordinates (:func:`.integrators.solve_on_group`).

Pinocchio's forward dynamics: ``aba``; with couplings its constrained
``forwardDynamics(q, v, τ, C, γ = 0)`` (an exact KKT solve with the constant constraint
Jacobian C, the multipliers in ``data.lambda_c``: M v̇ + h = τ + Cᵀ λ). A field of forces
on bodies enters as Pinocchio's external forces: per joint, in the joint's local frame.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from dyncheck.adapters.base import Field
from dyncheck.adapters.integrators import Addresses, integrate, solve_on_group
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.cases.quaternions import cross

Held = tuple[str, int, np.ndarray]
"""A body a field pushes: its name, the joint that carries it, its centre of mass in that
joint's frame."""


class Stepping:
    """A Pinocchio model's forward dynamics in MuJoCo's state layout, and its runs there."""

    def __init__(self, model: pin.Model, data: pin.Data, joint_types: Sequence[str], *,
                 held: Sequence[Held], rows: np.ndarray | None) -> None:
        self.model, self.data, self.rows = model, data, rows
        self.layout = Addresses.of(joint_types)
        self._held = list(held)
        # MuJoCo's positions → Pinocchio's: each quaternion (w, x, y, z) → (x, y, z, w), as
        # one permutation of q (and its inverse); the free joints, whose linear velocity
        # changes frame
        self._to_pin = np.arange(model.nq)
        self._free: list[tuple[int, int]] = []
        for jt, qa, va in self.layout.joints:
            if jt in ("ball", "free"):
                k = qa + (3 if jt == "free" else 0)
                self._to_pin[k : k + 4] = [k + 1, k + 2, k + 3, k]
            if jt == "free":
                self._free.append((qa, va))
        self._to_mj = np.argsort(self._to_pin)
        self._zero = np.zeros(model.nv)  # τ = 0 at every stage (read-only to ABA)
        self._no_forces = pin.StdVec_Force()
        self._no_forces.extend([pin.Force.Zero() for _ in range(model.njoints)])

    def external(self, q: np.ndarray, field: Field | None) -> pin.StdVec_Force | None:
        """``field`` as Pinocchio's external forces at q (its layout): per joint, in the
        joint's local frame, the force at each held body's centre of mass (None without a
        field)."""
        if field is None:
            return None
        d = self.data
        pin.forwardKinematics(self.model, d, q)
        where = {name: d.oMi[j].act(lever) for name, j, lever in self._held}
        forces = field(where)
        fext = pin.StdVec_Force(self._no_forces)  # a copy
        for name, j, _ in self._held:
            if name in forces:
                c, f = where[name], np.asarray(forces[name], float)
                fext[j] = fext[j] + d.oMi[j].actInv(pin.Force(f, cross(c, f)))
        return fext

    def accelerate(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                   fext: pin.StdVec_Force | None = None) -> np.ndarray:
        """v̇ at τ (its layout): ABA, or with couplings the KKT solve (its multipliers left in
        ``data.lambda_c``; a field is refused with couplings before any run)."""
        m, d = self.model, self.data
        if self.rows is not None:
            gamma = np.zeros(self.rows.shape[0])  # C is constant: no drift term
            return pin.forwardDynamics(m, d, q, v, tau, self.rows, gamma).copy()
        if fext is None:
            return pin.aba(m, d, q, v, tau)
        return pin.aba(m, d, q, v, tau, fext)

    def to_mujoco(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio's state → MuJoCo's layout: quaternions (x, y, z, w) → (w, x, y, z), a
        free joint's body-frame linear velocity v_b → v_w = R v_b."""
        q, v = np.asarray(q, float)[self._to_mj], np.array(v, float)
        for qa, va in self._free:
            v[va : va + 3] = quat_to_matrix(q[None, qa + 3 : qa + 7])[0] @ v[va : va + 3]
        return q, v

    def from_mujoco(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The inverse of :meth:`to_mujoco`."""
        if not self.layout.rotating:  # the same layout: each stage's state as it is
            return np.asarray(q, float), np.asarray(v, float)
        q = np.asarray(q, float)
        if self._free:
            v = np.array(v, float)
            for qa, va in self._free:
                v[va : va + 3] = quat_to_matrix(q[None, qa + 3 : qa + 7])[0].T @ v[va : va + 3]
        return q[self._to_pin], np.asarray(v, float)

    def _states_from_mujoco(self, qs: np.ndarray, vs: np.ndarray) -> tuple:
        """:meth:`from_mujoco` of every state of a run: at once where no free joint turns a
        velocity (moving values only), state by state otherwise."""
        if not self._free:
            return qs[:, self._to_pin], vs
        pairs = [self.from_mujoco(q, v) for q, v in zip(qs, vs, strict=True)]
        return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])

    def acceleration(self, field: Field | None) -> Callable[..., np.ndarray]:
        """v̇(q, v[, held]) in MuJoCo's layout at τ = 0 (:data:`.integrators.Acceleration`):
        a free joint's v̇_b turned into R (v̇_b + ω × v_b), the rate of v_w = R v_b; ``held``
        the external forces frozen at a step's start, else the field's now. Where the layouts
        agree and there is neither a cord nor a field, the very call it comes down to (ABA at
        τ = 0), bound once: a stage's cost on a small model is Python's calls around the
        dynamics, not the dynamics."""
        if not self.layout.rotating and self.rows is None and field is None:
            aba, m, d, zero = pin.aba, self.model, self.data, self._zero

            def bare(q: np.ndarray, v: np.ndarray, held: object = None) -> np.ndarray:
                return aba(m, d, q, v, zero)

            return bare

        def acc(q: np.ndarray, v: np.ndarray, held: pin.StdVec_Force | None = None) -> np.ndarray:
            qp, vp = self.from_mujoco(q, v)
            fext = self.external(qp, field) if held is None else held
            a = self.accelerate(qp, vp, self._zero, fext)
            for qa, va in self._free:
                R = quat_to_matrix(q[None, qa + 3 : qa + 7])[0]
                lin, ang = slice(va, va + 3), slice(va + 3, va + 6)
                a[lin] = R @ (a[lin] + cross(vp[ang], vp[lin]))
            return a

        return acc

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's definition of ``integrator`` (:func:`.integrators.integrate`), in MuJoCo's
        layout; its states in Pinocchio's."""
        qs, vs = integrate(
            self.acceleration(field), *self.to_mujoco(q0, v0), dt, steps, integrator,
            freeze=lambda q, v: self.external(self.from_mujoco(q, v)[0], field),
            layout=self.layout)
        return self._states_from_mujoco(qs, vs)

    def solve(self, q0: np.ndarray, v0: np.ndarray, t_eval: np.ndarray, *, rtol: float,
              field: Field | None, label: str) -> tuple[np.ndarray, np.ndarray]:
        """scipy's DOP853 at rtol = atol = ``rtol`` (:func:`.integrators.solve_on_group`)."""
        qs, vs = solve_on_group(self.acceleration(field), *self.to_mujoco(q0, v0), t_eval,
                                rtol, layout=self.layout, label=label)
        return self._states_from_mujoco(qs, vs)
