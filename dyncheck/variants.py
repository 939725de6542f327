"""How an implementation's model departs from the book's, as far as the reference can
predict it (:class:`Variant`), and the names of those conventions."""

from __future__ import annotations

from dataclasses import dataclass

from dyncheck.cases.base import Case
from dyncheck.labels import SOFT_CONSTRAINT

__all__ = ["ENGINE_DEFECT", "GRAVITY_DEFAULT", "INERTIA_STORED", "POINT_INERTIA",
           "SOFT_CONSTRAINT", "TENSOR", "Variant", "book_variant"]


@dataclass(frozen=True)
class Variant:
    """How an implementation's model departs from the book's, as far as the reference can
    predict it: the isotropic rotational inertia (kg·m², about the centre of mass) each body
    carries where the book has a point mass (book: zero), and the gravity vector (m/s²) the
    implementation actually uses (book: the case's)."""

    point_inertia: tuple[float, ...]
    gravity: tuple[float, float, float]
    softness: tuple[float, ...] | None = None
    """None: couplings held exactly; else a soft constraint's (solref, solimp)."""
    inertia: tuple[tuple[str, float], ...] = ()
    """A rigid body's inertia tensor as the implementation holds it, where its loader stored
    it rounded beyond a read-back's round-off (PyBullet: principal moments from a Jacobi
    diagonalization): the case's parameters ``I11`` … ``I23`` it replaces (book: none)."""
    inertia_computed: bool = False
    """:attr:`inertia` is the tensor the engine computes with, not the one it holds (a
    declared defect: :attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia`)."""

    def conventions(self, other: Variant) -> list[str]:
        """Names of the conventions in which two variants differ."""
        out = []
        if self.point_inertia != other.point_inertia:
            out.append(POINT_INERTIA)
        if self.inertia != other.inertia:
            out.append(ENGINE_DEFECT if self.inertia_computed or other.inertia_computed
                       else INERTIA_STORED)
        if self.gravity != other.gravity:
            out.append(GRAVITY_DEFAULT)
        if self.softness != other.softness:
            out.append(SOFT_CONSTRAINT)
        return out


POINT_INERTIA = "point-mass inertia floor"
INERTIA_STORED = "inertia tensor stored rounded by the loader"
ENGINE_DEFECT = "engine defect declared by its adapter"
TENSOR = (("I11", 0, 0), ("I22", 1, 1), ("I33", 2, 2), ("I12", 0, 1), ("I13", 0, 2),
          ("I23", 1, 2))
"""A rigid body case's parameters naming its inertia tensor's entries."""
GRAVITY_DEFAULT = "MJCF gravity option not read"


def book_variant(case: Case) -> Variant:
    """The book's model: point masses, the case's gravity."""
    mb = case.multibody()
    gx, gy, gz = (float(x) for x in mb.gravity)
    return Variant((0.0,) * len(mb.bodies), (gx, gy, gz))
