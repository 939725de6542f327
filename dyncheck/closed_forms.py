"""Closed-form solutions against the reference's integrated trajectories.

``torque_free``: the book says torque-free motion of an asymmetric body is solved by Jacobi
elliptic functions; :class:`dyncheck.reference.rigid.TorqueFree` is that solution for ω̄(t).
The reference's general method (Lagrange's equations in Example 9's angles) integrated by
DOP853, mapped to ω̄ by exercise 23, must reproduce it: two derivations that share nothing but
the inertia. Tolerance: 4 × the integration's error estimate (rtol 1e-13 against 2.5e-14)
plus the closed form's own round-off, 64 ε (1 + |u̇| T) (the phase u = u₀ + u̇ t carries a
relative error ε per unit of |u|).
"""

from __future__ import annotations

import numpy as np

from dyncheck.cases.base import Case
from dyncheck.implementations import general_method
from dyncheck.precision import EPS
from dyncheck.reference import rigid
from dyncheck.reference.trajectory import solve
from dyncheck.results import Discrepancy, Verdict
from dyncheck.tolerances import first_near_max
from dyncheck.vocabulary import Quantity


def closed_form_rows(case: Case) -> list[Discrepancy]:
    """Rows ``closed_form`` (book's solution vs reference) for cases that have one."""
    if case.name != "torque_free":
        return []
    spec = case.trajectory
    t = spec.grid()
    dyn = general_method(case)
    q0, v0 = np.asarray(spec.q0, float), np.asarray(spec.v0, float)
    runs = [solve(dyn, q0, v0, t, rtol=r, atol=r) for r in (1e-13, 2.5e-14)]
    w, w_tight = (rigid.body_angular_velocity(q, v) for q, v in runs)
    w0 = rigid.body_angular_velocity(q0, v0)[0]
    tf = rigid.TorqueFree((case.I11, case.I22, case.I33), tuple(float(x) for x in w0))
    exact = tf.omega(t)
    scale = float(np.abs(exact).max())
    err = np.abs(w - exact).max(axis=1)
    estimate = float(np.abs(w - w_tight).max())
    rate = abs(tf.rate)
    allowed = 4 * estimate + 64 * EPS * (1 + rate * spec.duration) * scale
    return [
        Discrepancy.measured(
            case=case.name,
            quantity=Quantity.CLOSED_FORM,
            impl_a="book",
            impl_b="reference",
            integrator="dop853",
            error=float(err.max()),
            scale=scale,
            tolerance=allowed / scale,
            basis=f"4 x DOP853 error estimate {estimate:.1e} + closed form round-off "
            "64 eps (1 + abs(du/dt) T)",
            verdict=Verdict.PASSED if err.max() <= allowed else Verdict.FAILED,
            note=f"body angular velocity: Jacobi elliptic closed form (m = {tf.parameter:.4f}) "
            "against Lagrange's equations in Euler angles integrated by DOP853",
            worst_state=first_near_max(err, 64 * EPS * (1 + rate * spec.duration) * scale),
        )
    ]
