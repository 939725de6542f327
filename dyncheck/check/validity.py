"""Step 4 of a model check: whether each body an engine holds (or the file states) is
physically possible — §2.2: the inertia tensor (2.2.39) of real matter is positive
semi-definite and its principal moments obey the triangle inequality, Iₐ + I_b ≥ I_c,
because each is a sum of m (r² − rᵢ²) ≥ 0 terms. Tolerance: 64 ε × trace(I)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from dyncheck.adapters.model_tree import ModelTree
from dyncheck.check.joint_fields import shown_value
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, eps_name
from dyncheck.vocabulary import Verdict

FIXES = {
    "mass": "fix: give the body a positive mass, or merge a massless link into its parent",
    "finite": "fix: write finite numbers for the mass and the inertia",
    "inertia": "fix: a physical inertia tensor has non-negative principal moments (check the "
    "signs of the products of inertia: URDF's ixy is +∫xy dm, some exporters write −)",
    "triangle": "fix: raise the smaller principal moments until I1 + I2 >= I3 (MuJoCo's "
    "<compiler balanceinertia=\"true\"/> does this), or recompute the tensor from the "
    "link's geometry",
}
"""A fix hint for each violated condition of :func:`validity` (the page shows it first)."""


def _violation(mass: float, inertia: np.ndarray, eps: float = EPS,
               held: float = 0.0) -> tuple[str, object, float, float, str] | None:
    """(field, value, error, tolerance, note) of the first violated condition, or None; the
    tolerance is round-off of the tensor's size (its trace), or of ``held``, the size of what
    an engine's tensor was derived from where that is larger (:func:`tree_bodies`)."""
    if not mass > 0.0:
        return "mass", mass, abs(mass), 0.0, f"mass {mass:g} (must be > 0)"
    if not np.isfinite(mass) or not np.all(np.isfinite(inertia)):
        return ("finite", mass, float("inf"), 0.0,
                f"mass {mass:g} or inertia {shown_value(np.asarray(inertia).ravel())} not finite")
    scale = float(np.abs(inertia).max()) or 1.0  # eigenvalues of I/scale: no overflow at 1e308
    unit = np.asarray(inertia, float) / scale
    moments = np.linalg.eigvalsh(0.5 * (unit + unit.T)) * scale
    if not np.all(np.isfinite(moments)):
        return ("finite", mass, float("inf"), 0.0,
                f"principal moments of inertia {shown_value(np.asarray(inertia).ravel())} overflow")
    tol = ROUNDOFF_FACTOR * eps * max(float(np.abs(moments).sum()), held, 1e-300)
    if moments[0] < -tol:
        return ("inertia", moments, -float(moments[0]), tol,
                f"principal moments {shown_value(moments)}: not positive semi-definite (2.2.39)")
    if moments[0] + moments[1] < moments[2] - tol:
        return ("triangle", moments, float(moments[2] - moments[0] - moments[1]), tol,
                f"principal moments {shown_value(moments)} break I1 + I2 >= I3 (2.2.39)")
    return None


class Held(NamedTuple):
    """A body as it is checked: its name, mass and inertia about its centre of mass, and the
    size (kg m²) of what that tensor was derived from (0: the tensor itself, a file's)."""

    name: str
    mass: float
    inertia: np.ndarray
    derived_from: float = 0.0


def validity(
    model: str, holder: str, bodies: Sequence[tuple[str, float, np.ndarray] | Held], *,
    eps: float = EPS,
) -> list[CheckRow]:
    """Positive mass, positive semi-definite inertia, triangle inequality for each
    ``(name, mass, inertia)`` an engine holds (its rigid groups, :func:`tree_bodies`) or the
    file states (a URDF's links): a failed row per violation, else one passed row. Massless,
    inertia-less links (frames) are not bodies and are skipped."""
    rows: list[CheckRow] = []
    checked = 0
    for body in bodies:
        name, mass, inertia, held = Held(*body)
        if mass == 0.0 and not np.any(inertia):
            continue
        checked += 1
        found = _violation(mass, inertia, eps, held)
        if found is not None:
            field, value, err, tol, note = found
            note = f"{note}; {FIXES[field]}"
            rows.append(
                CheckRow(
                    model=model, section=Section.VALIDITY, subject=name, field=field,
                    impl_a=holder, impl_b="", value_a=shown_value(value), value_b="", error=err,
                    tolerance=tol,
                    basis=(f"round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x "
                           + ("trace(I about the origin)"
                              if held > abs(float(np.trace(inertia))) else "trace(I)"))
                    if tol else "",
                    verdict=Verdict.FAILED, note=note,
                )
            )
    if not rows:
        rows.append(
            CheckRow(
                model=model, section=Section.VALIDITY, subject="model",
                field="mass, inertia, triangle", impl_a=holder, impl_b="",
                value_a=f"{checked} bodies", value_b="", error=0.0, tolerance=0.0, basis="",
                verdict=Verdict.PASSED, note="positive mass, positive semi-definite inertia, "
                "triangle inequality",
            )
        )
    return rows


def tree_bodies(tree: ModelTree) -> list[Held]:
    """Each joint's body as the engine holds it, with the size of what its tensor was derived
    from (:attr:`~dyncheck.adapters.model_tree.TreeJoint.inertia_derived_from`): Drake holds
    the inertia about the body's origin, and the one about the centre of mass is their
    difference by the parallel-axis theorem — a link of 1e-20 kg m² 2 cm off its origin
    (example-robot-data's iCub ankle) is then round-off of a 2e-4 kg m² tensor, not an
    invalid one."""
    return [Held(j.body, j.mass, j.inertia, j.inertia_derived_from) for j in tree.joints]
