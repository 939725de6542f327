"""What a run should conserve: energy ((2.2.36)), angular momentum ((2.2.49) with M = 0) and
the cords' constraint (its drift against the same model's discrete motion)."""

from __future__ import annotations

from typing import Any

import numpy as np

from dyncheck.adapters.integrators import STEPPERS
from dyncheck.cases.base import Case
from dyncheck.cases.coordinate_maps import EulerAngleMap
from dyncheck.comparison import soft_factor
from dyncheck.implementations import Implementation, general_method
from dyncheck.reference import rigid
from dyncheck.results import Discrepancy, Verdict
from dyncheck.studies.references import References
from dyncheck.tolerances import accumulated, first_near_max
from dyncheck.variants import SOFT_CONSTRAINT, Variant
from dyncheck.vocabulary import Quantity


def energy_drift(
    case: Case,
    impl: Implementation,
    variant: Variant | None,
    dt: float,
    integrator: str,
    q: np.ndarray,
) -> np.ndarray | None:
    """Relative energy error along a run (conservation, (2.2.36)'s T + V = h), evaluated with
    the reference's energy of the implementation's own model."""
    v = impl.velocities(dt, integrator)
    if v is None or variant is None:
        return None
    dyn = general_method(case, variant)
    energy = dyn.kinetic_energy(q, v) + dyn.potential_energy(q)
    if hasattr(dyn, "field_potential"):
        energy = energy + dyn.field_potential(q)
    return np.abs(energy - energy[0]) / max(float(np.abs(energy).max()), 1e-300)


def momentum_drift(
    case: Case, impl: Implementation, dt: float, integrator: str, q: np.ndarray
) -> np.ndarray | None:
    """|H(t) − H(0)| / |H(0)| along a run of a rigid case (its last three coordinates are
    Example 9's angles): H = ℓ Ī ω̄ in space axes, conserved by (2.2.49) with M = 0."""
    v = impl.velocities(dt, integrator)
    if v is None or not hasattr(case, "inertia"):
        return None
    angles, rates = q[:, -3:], v[:, -3:]
    euler = EulerAngleMap()
    w = np.einsum("nij,nj->ni", euler.jacobian(angles), rates)
    H = np.einsum("nij,nj->ni", euler.rotation(angles), rigid.angular_momentum(case.inertia(), w))
    return np.linalg.norm(H - H[0], axis=1) / np.linalg.norm(H[0])


def drift_row(
    case: Case,
    impl: Implementation,
    variant: Variant | None,
    refs: References,
    integrator: str,
    dt: float,
) -> Discrepancy:
    """The cords' violation C q̄(t) along the engine's run at ``dt`` against the same
    model's discrete motion (the reference stepped by the same integrator): zero to
    round-off for an exact constraint, the soft model's stretch for a soft one."""
    C = case.multibody().coupling_matrix(positions=True)
    observed = impl.engine_positions(dt, integrator) @ C.T  # type: ignore[attr-defined]
    steps = observed.shape[0] - 1
    tol = accumulated(steps, soft_factor(variant), impl.eps)
    base: dict[str, Any] = dict(
        case=case.name,
        quantity=Quantity.CONSTRAINT_DRIFT,
        impl_a="reference",
        impl_b=impl.name,
        integrator=integrator,
        dt=dt,
        tolerance=tol.rtol,
        basis=tol.basis + " (relative to the coordinates' scale)",
    )
    if variant is None:
        return Discrepancy.unmeasured(**base, verdict=Verdict.FAILED,
                                      note="model differs from the book in an unpredicted way")
    how = f"the same model stepped by {integrator}"
    if integrator in STEPPERS:
        _, qe = refs.discrete_engine(variant, integrator, dt)
        predicted = qe @ C.T
    elif not variant.softness:
        # an engine's own Runge–Kutta scheme on an exact cord: every Runge–Kutta method keeps
        # a linear invariant C q exactly (Hairer, Lubich & Wanner, GNI, Thm. IV.1.5)
        qe = impl.engine_positions(dt, integrator)  # type: ignore[attr-defined]
        predicted = np.broadcast_to(qe[0] @ C.T, observed.shape)
        how = f"{integrator}, a Runge–Kutta method, keeps the linear invariant C q"
    else:
        raise ValueError(f"no discrete model of {integrator} for a soft constraint")
    diff = np.abs(observed - predicted).max(axis=1)
    scale = float(np.abs(qe).max())
    err = float(diff.max())
    return Discrepancy.measured(
        **base,
        error=err,
        scale=scale,
        verdict=Verdict.PASSED if err / scale <= tol.rtol else Verdict.FAILED,
        convention=SOFT_CONSTRAINT if variant.softness else "",
        note=f"max abs violation observed {np.abs(observed).max():.3g} m, predicted "
        f"{np.abs(predicted).max():.3g} m ({how})",
        worst_state=first_near_max(diff, tol.rtol * scale),
    )
